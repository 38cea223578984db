//! The referee's verdicts per backend, in one unit: rays.
//!
//! A ray counts once however many queries it was asked (the stability
//! cases ask each ray for its closest hit and for occlusion): it is
//! `wrong` for a backend when any of that backend's answers to it is
//! wrong, `undecided` when none is wrong but the referee left one
//! undecided, `t_off` when none is either but a hit's distance is off. Every
//! subcommand (compare, stability, the checked render, judge) counts
//! through [`Verdicts`].

use super::table::{Cell, Table};
use crate::check::{CheckLog, Judgement, Record, ray_bits};
use crate::geometry::TriangleMesh;
use crate::scene::Scene;
use serde::Serialize;
use std::collections::BTreeMap;
use std::ops::AddAssign;

/// One backend's verdicts over a set of rays.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct BackendTally {
    /// The backend's `--backends` name.
    pub name: String,
    /// Rays on which a decision of this backend (hit or miss, which
    /// triangle, occluded or not) is not admissible.
    pub wrong: u64,
    /// Rays with no wrong decision but an answer the referee could not
    /// decide within its search budget (neither admissible nor wrong).
    pub undecided: u64,
    /// Rays with no wrong or undecided answer but a hit whose distance is
    /// beyond the referee's tolerance.
    pub t_off: u64,
    /// Closest-hit queries answered with a non-finite `t`, or a non-finite
    /// `u`, `v` or normal where the backend gives them.
    pub nan_outputs: u64,
    /// Closest-hit queries answered with a miss.
    pub misses: u64,
    /// Misses on rays that exactly hit the mesh, counted where every ray
    /// had to hit (from inside a closed mesh, towards an interior point):
    /// rays that leaked through it.
    pub leaks: u64,
    /// Meshes the backend could not be built over (it answered none of
    /// their rays; a crate that panics or refuses the vertices).
    pub build_failures: u64,
}

impl BackendTally {
    /// Wrong answers and distances off, in rays.
    pub fn faults(&self) -> u64 {
        self.wrong + self.t_off
    }
}

/// Every backend's verdicts over one set of rays.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Verdicts {
    /// Rays asked.
    pub rays: u64,
    /// Rays the referee judged: every ray on which two backends differ,
    /// and a fixed sample of the others (see `check::AGREEMENT_SAMPLE`).
    pub judged: u64,
    /// Rays on which two backends differ.
    pub disagreements: u64,
    /// Rays on which backends differ and every answer is admissible: an
    /// exact tie, or a ray a one-ulp change would flip.
    pub ambiguous: u64,
    /// One per backend, in the order they were given.
    pub backends: Vec<BackendTally>,
}

impl Verdicts {
    /// Judges every record of `log` against `mesh` and counts per ray;
    /// `rays` is how many rays were asked.
    pub fn judge(log: &CheckLog, mesh: &TriangleMesh, rays: u64) -> Self {
        Self::count(log, &log.judge(mesh), rays)
    }

    /// Counts `judgements` (one list per record of `log`, as
    /// [`CheckLog::judge`] gives them) per ray.
    pub fn count(log: &CheckLog, judgements: &[Vec<Judgement>], rays: u64) -> Self {
        let mut backends: Vec<BackendTally> = log
            .backends
            .iter()
            .map(|b| BackendTally {
                name: b.name.clone(),
                nan_outputs: b.nan_outputs,
                misses: b.misses,
                ..Default::default()
            })
            .collect();
        let mut by_ray: BTreeMap<[u32; 8], Vec<(&Record, &Vec<Judgement>)>> = BTreeMap::new();
        for (record, judged) in log.records.iter().zip(judgements) {
            by_ray
                .entry(ray_bits(&record.ray))
                .or_default()
                .push((record, judged));
        }
        let mut verdicts = Verdicts {
            rays,
            judged: by_ray.len() as u64,
            ..Default::default()
        };
        for queries in by_ray.values() {
            let disagreement = queries.iter().any(|(r, _)| r.disagreement);
            let all_admissible = queries
                .iter()
                .all(|(_, j)| j.iter().all(|j| j.is_admissible()));
            verdicts.disagreements += disagreement as u64;
            verdicts.ambiguous += (disagreement && all_admissible) as u64;
            for (index, tally) in backends.iter_mut().enumerate() {
                let of_backend = || queries.iter().map(|(_, j)| j[index]);
                if of_backend().any(|j| j == Judgement::Wrong) {
                    tally.wrong += 1;
                } else if of_backend().any(|j| j == Judgement::Undecided) {
                    tally.undecided += 1;
                } else if of_backend().any(|j| j == Judgement::DistanceOff) {
                    tally.t_off += 1;
                }
            }
        }
        verdicts.backends = backends;
        verdicts
    }

    /// The verdicts on a checked render: each layer's log judged against
    /// its own mesh, summed; every query counts as a ray.
    pub fn judge_layers(scene: &Scene, logs: &[CheckLog]) -> Self {
        let mut total = Verdicts::default();
        for (log, mesh) in logs.iter().zip(scene.meshes()) {
            total += &Self::judge(log, mesh, log.intersect_queries + log.occluded_queries);
        }
        total
    }

    /// These verdicts over every backend of `names`, in that order: a
    /// backend these verdicts lack (it could not be built over the mesh)
    /// gets one build failure and nothing else.
    pub fn over(mut self, names: &[String]) -> Self {
        let mut tallies = std::mem::take(&mut self.backends);
        self.backends = names
            .iter()
            .map(|name| match tallies.iter().position(|b| &b.name == name) {
                Some(index) => tallies.swap_remove(index),
                None => BackendTally {
                    name: name.clone(),
                    build_failures: 1,
                    ..Default::default()
                },
            })
            .collect();
        self
    }

    /// The tally of the backend named `name`.
    /// The first backend's (the checked one's) wrong answers, distances
    /// off and non-finite outputs: what makes a command exit 1.
    pub fn faults_of_first(&self) -> u64 {
        self.backends
            .first()
            .map_or(0, |b| b.faults() + b.nan_outputs)
    }

    pub fn backend(&self, name: &str) -> Option<&BackendTally> {
        self.backends.iter().find(|b| b.name == name)
    }
}

impl AddAssign<&Verdicts> for Verdicts {
    /// Adds the verdicts on other rays, asked of the same backends.
    ///
    /// # Panics
    /// If both hold backends and they are not the same ones in the same
    /// order.
    fn add_assign(&mut self, other: &Verdicts) {
        if self.backends.is_empty() {
            self.backends = other
                .backends
                .iter()
                .map(|b| BackendTally {
                    name: b.name.clone(),
                    ..Default::default()
                })
                .collect();
        }
        let names = |v: &Verdicts| {
            v.backends
                .iter()
                .map(|b| b.name.clone())
                .collect::<Vec<_>>()
        };
        assert!(
            other.backends.is_empty() || names(self) == names(other),
            "adding verdicts of {:?} to {:?}",
            names(other),
            names(self)
        );
        self.rays += other.rays;
        self.judged += other.judged;
        self.disagreements += other.disagreements;
        self.ambiguous += other.ambiguous;
        for (a, b) in self.backends.iter_mut().zip(&other.backends) {
            a.wrong += b.wrong;
            a.undecided += b.undecided;
            a.t_off += b.t_off;
            a.nan_outputs += b.nan_outputs;
            a.misses += b.misses;
            a.leaks += b.leaks;
            a.build_failures += b.build_failures;
        }
    }
}

/// `verdicts` as a table, a row per backend.
pub fn table(title: &str, verdicts: &Verdicts, caption: &str) -> Table {
    table_of(title, verdicts, caption, false)
}

/// [`table`] for a catalogue's verdicts (a stability case, a bundle of
/// one), with its two more columns: leaks, and the meshes each backend
/// could not build over.
pub fn catalogue_table(title: &str, verdicts: &Verdicts, caption: &str) -> Table {
    table_of(title, verdicts, caption, true)
}

fn table_of(title: &str, verdicts: &Verdicts, caption: &str, catalogue: bool) -> Table {
    let mut headers = vec![
        "backend",
        "wrong",
        "undecided",
        "t off",
        "NaN outputs",
        "misses",
    ];
    if catalogue {
        headers.extend(["leaks", "meshes it could not build over"]);
    }
    let mut table = Table::new(title, &headers, caption);
    for b in &verdicts.backends {
        let mut row = vec![
            Cell::from(b.name.as_str()),
            Cell::wrong_count(b.wrong),
            Cell::undecided_count(b.undecided),
            Cell::wrong_count(b.t_off),
            Cell::wrong_count(b.nan_outputs),
            b.misses.to_string().into(),
        ];
        if catalogue {
            row.extend([
                Cell::wrong_count(b.leaks),
                Cell::wrong_count(b.build_failures),
            ]);
        }
        table.push(row);
    }
    table
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check::{Answer, BackendLog};
    use crate::geometry::{Hit, Ray};
    use glam::Vec3;

    fn record(x: f32, answers: Vec<Answer>, disagreement: bool) -> Record {
        Record {
            ray: Ray::new(Vec3::new(x, 0.0, 1.0), Vec3::NEG_Z),
            answers,
            disagreement,
        }
    }

    fn hit() -> Answer {
        Answer::Closest(Some(Hit {
            t: 1.0,
            u: 0.0,
            v: 0.0,
            prim: 0,
            ng: Vec3::Z,
        }))
    }

    fn log(records: Vec<Record>) -> CheckLog {
        CheckLog {
            backends: ["a", "b"]
                .map(|name| BackendLog {
                    name: name.into(),
                    ..Default::default()
                })
                .to_vec(),
            records,
            ..Default::default()
        }
    }

    #[test]
    fn a_ray_counts_once_however_many_of_its_queries_are_wrong() {
        use Judgement::*;
        let log = log(vec![
            // Ray 0: b wrong on both its queries.
            record(0.0, vec![hit(), Answer::Closest(None)], true),
            record(
                0.0,
                vec![Answer::Occluded(true), Answer::Occluded(false)],
                true,
            ),
            // Ray 1: b's distance is off.
            record(1.0, vec![hit(), hit()], true),
            // Ray 2: both admissible, different: ambiguous.
            record(2.0, vec![hit(), Answer::Closest(None)], true),
            // Ray 3: a sampled agreement, both wrong.
            record(3.0, vec![hit(), hit()], false),
            // Ray 4: b undecided on one query, off on the other.
            record(4.0, vec![hit(), hit()], true),
            record(
                4.0,
                vec![Answer::Occluded(true), Answer::Occluded(false)],
                true,
            ),
        ]);
        let judgements = vec![
            vec![Right, Wrong],
            vec![Right, Wrong],
            vec![Right, DistanceOff],
            vec![Right, Admissible],
            vec![Wrong, Wrong],
            vec![Right, DistanceOff],
            vec![Right, Undecided],
        ];
        let verdicts = Verdicts::count(&log, &judgements, 100);
        assert_eq!(verdicts.rays, 100);
        assert_eq!(verdicts.judged, 5);
        assert_eq!(verdicts.disagreements, 4);
        assert_eq!(verdicts.ambiguous, 1);
        let a = verdicts.backend("a").unwrap();
        let b = verdicts.backend("b").unwrap();
        assert_eq!((a.wrong, a.undecided, a.t_off), (1, 0, 0));
        assert_eq!((b.wrong, b.undecided, b.t_off), (2, 1, 1));

        let mut sum = Verdicts::default();
        sum += &verdicts;
        sum += &verdicts;
        assert_eq!(sum.rays, 200);
        assert_eq!(sum.backend("b").unwrap().wrong, 4);
        assert_eq!(sum.backend("b").unwrap().undecided, 2);
    }
}
