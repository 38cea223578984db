//! What `raycheck compare` found on one scene: per backend the referee's
//! verdicts, how it differs from the first backend, and replayable rays.

use super::table::{Cell, Table};
use super::tally::Verdicts;
use crate::backends::{Backend, BackendName};
use crate::check::{self, Answer, CheckLog, DifferenceKind, Judgement, RaySet, Record};
use crate::geometry::{Hit, Ray};
use crate::parallel::Workers;
use crate::scene::Scene;
use serde::Serialize;

/// Per backend, at most this many replayable rays on which it is wrong,
/// and as many again on which its distance is off.
pub const SAMPLES_PER_BACKEND: usize = 16;
/// At most this many replayable rays on which backends differ and every
/// answer is admissible.
pub const AMBIGUOUS_SAMPLES: usize = 16;

/// The outcome of one compare run; the JSON of `raycheck compare --json`.
#[derive(Clone, Debug, Serialize)]
pub struct CompareSummary {
    pub scene: String,
    pub triangles: usize,
    pub resolution: u32,
    /// The backends' names; the first one's hits spawn the secondary rays.
    pub backends: Vec<String>,
    /// Queries per ray set.
    pub rays_per_set: Vec<SetCount>,
    /// Per backend, counted in rays.
    pub verdicts: Verdicts,
    /// How each backend after the first differs from the first.
    pub against_first: Vec<Differences>,
    /// Rays on which a backend is wrong or off, or backends differ
    /// admissibly, bit-exact for replay.
    pub samples: Vec<SampleRecord>,
}

/// How many queries one ray set asked.
#[derive(Clone, Debug, Serialize)]
pub struct SetCount {
    pub set: RaySet,
    pub rays: u64,
}

/// How one backend's answers differ from the first backend's.
#[derive(Clone, Debug, Serialize)]
pub struct Differences {
    pub backend: String,
    /// Closest-hit queries where one hit and the other missed.
    pub hit_mismatch: u64,
    /// Closest-hit queries where both hit, but different triangles.
    pub prim_mismatch: u64,
    /// Same triangle, `t` differing beyond the tolerance.
    pub t_mismatch: u64,
    /// Any-hit queries with different answers.
    pub occlusion_mismatch: u64,
    /// Largest relative `t` difference where both hit the same triangle.
    pub max_rel_t_error: f32,
    /// The same, over primary rays only.
    pub max_rel_t_error_primary: f32,
    /// Largest `|Δu|`, `|Δv|` where both hit the same triangle; `None`
    /// when either backend gives no `u`, `v`.
    pub max_uv_error: Option<f32>,
    /// Fraction of all queries whose hit/miss (or occluded) answers agree.
    pub hit_agreement: f64,
    /// Fraction of closest-hit queries that agree on the triangle, counting
    /// referee-certified ties (both answers admissible) as agreement.
    pub prim_agreement: f64,
}

/// One judged query, every float also given as its bit pattern.
#[derive(Clone, Debug, Serialize)]
pub struct SampleRecord {
    pub ray_set: RaySet,
    pub query: &'static str,
    pub ray: RayRecord,
    pub answers: Vec<JudgedAnswer>,
}

/// One backend's answer to a sampled query and the referee's judgement.
#[derive(Clone, Debug, Serialize)]
pub struct JudgedAnswer {
    pub backend: String,
    pub judgement: Judgement,
    pub answer: AnswerRecord,
}

/// A ray as decimals (shortest round-trip) and as hex f32 bits.
#[derive(Clone, Debug, Serialize)]
pub struct RayRecord {
    pub origin: [f32; 3],
    pub dir: [f32; 3],
    pub tnear: f32,
    pub tfar: f32,
    /// origin xyz, dir xyz, tnear, tfar as `0x...` f32 bit patterns.
    pub bits: [String; 8],
}

impl From<&Ray> for RayRecord {
    fn from(ray: &Ray) -> Self {
        Self {
            origin: ray.origin.to_array(),
            dir: ray.dir.to_array(),
            tnear: ray.tnear,
            tfar: ray.tfar,
            bits: ray.inputs().map(|v| format!("{:#010x}", v.to_bits())),
        }
    }
}

#[derive(Clone, Debug, Serialize)]
#[serde(tag = "answer", rename_all = "snake_case")]
pub enum AnswerRecord {
    Hit { prim: u32, t: f32, u: f32, v: f32 },
    Miss,
    Occluded { occluded: bool },
}

impl From<&Answer> for AnswerRecord {
    fn from(answer: &Answer) -> Self {
        match answer {
            Answer::Closest(Some(Hit { prim, t, u, v, .. })) => AnswerRecord::Hit {
                prim: *prim,
                t: *t,
                u: *u,
                v: *v,
            },
            Answer::Closest(None) => AnswerRecord::Miss,
            Answer::Occluded(occluded) => AnswerRecord::Occluded {
                occluded: *occluded,
            },
        }
    }
}

/// Builds `names` over `scene`'s mesh, traces the compare ray sets at
/// `resolution`² primary rays through all of them and judges them, on
/// `workers`.
pub fn compare_scene(
    scene: &Scene,
    names: &[BackendName],
    workers: &Workers,
    resolution: u32,
) -> anyhow::Result<CompareSummary> {
    workers.install(|| {
        let built: Vec<Box<dyn Backend>> = names
            .iter()
            .map(|name| name.build(&scene.mesh, workers.build_context()))
            .collect::<anyhow::Result<_>>()?;
        let backends: Vec<&dyn Backend> = built.iter().map(|b| b.as_ref()).collect();
        Ok(CompareSummary::new(
            scene,
            resolution,
            check::compare(scene, &backends, resolution),
        ))
    })
}

impl CompareSummary {
    /// Judges the logs of [`check::compare()`] (or any logs of one mesh, one
    /// per ray set) and sums them up.
    pub fn new(scene: &Scene, resolution: u32, logs: Vec<(RaySet, CheckLog)>) -> Self {
        let judgements = logs.iter().map(|(_, log)| log.judge(&scene.mesh)).collect();
        Self::from_judged(scene, resolution, logs, judgements)
    }

    /// The same, from logs already judged: `judgements` holds one list per
    /// log, as [`CheckLog::judge`] gives it.
    pub fn from_judged(
        scene: &Scene,
        resolution: u32,
        logs: Vec<(RaySet, CheckLog)>,
        judgements: Vec<Vec<Vec<Judgement>>>,
    ) -> Self {
        let judged: Vec<(RaySet, &CheckLog, Vec<Vec<Judgement>>)> = logs
            .iter()
            .zip(judgements)
            .map(|((set, log), judgements)| (*set, log, judgements))
            .collect();
        let mut verdicts = Verdicts::default();
        for (_, log, judgements) in &judged {
            let queries = log.intersect_queries + log.occluded_queries;
            verdicts += &Verdicts::count(log, judgements, queries);
        }
        CompareSummary {
            scene: scene.name.clone(),
            triangles: scene.mesh.triangle_count(),
            resolution,
            backends: logs
                .first()
                .map(|(_, log)| log.backends.iter().map(|b| b.name.clone()).collect())
                .unwrap_or_default(),
            rays_per_set: logs
                .iter()
                .map(|(set, log)| SetCount {
                    set: *set,
                    rays: log.intersect_queries + log.occluded_queries,
                })
                .collect(),
            verdicts,
            against_first: against_first(&judged),
            samples: samples(&judged),
        }
    }

    pub fn rays(&self) -> u64 {
        self.verdicts.rays
    }
}

fn against_first(judged: &[(RaySet, &CheckLog, Vec<Vec<Judgement>>)]) -> Vec<Differences> {
    let Some((_, first_log, _)) = judged.first() else {
        return Vec::new();
    };
    let intersect_queries: u64 = judged.iter().map(|(_, l, _)| l.intersect_queries).sum();
    let queries = intersect_queries
        + judged
            .iter()
            .map(|(_, l, _)| l.occluded_queries)
            .sum::<u64>();
    let fraction = |bad: u64, all: u64| {
        if all == 0 {
            1.0
        } else {
            1.0 - bad as f64 / all as f64
        }
    };
    (1..first_log.backends.len())
        .map(|index| {
            let of = |f: fn(&crate::check::BackendLog) -> u64| -> u64 {
                judged.iter().map(|(_, l, _)| f(&l.backends[index])).sum()
            };
            let max_of = |f: fn(&crate::check::BackendLog) -> f32| {
                judged
                    .iter()
                    .map(|(_, l, _)| f(&l.backends[index]))
                    .fold(0.0, f32::max)
            };
            let certified_ties = judged
                .iter()
                .flat_map(|(_, log, judgements)| log.records.iter().zip(judgements))
                .filter(|(record, judgement)| {
                    DifferenceKind::between(&record.answers[0], &record.answers[index])
                        == Some(DifferenceKind::Prim)
                        && judgement[0].is_admissible()
                        && judgement[index].is_admissible()
                })
                .count() as u64;
            let prim_mismatch = of(|b| b.prim_mismatch);
            let gives_uv = first_log.backends[0].gives_uv && first_log.backends[index].gives_uv;
            Differences {
                backend: first_log.backends[index].name.clone(),
                hit_mismatch: of(|b| b.hit_mismatch),
                prim_mismatch,
                t_mismatch: of(|b| b.t_mismatch),
                occlusion_mismatch: of(|b| b.occlusion_mismatch),
                max_rel_t_error: max_of(|b| b.max_rel_t_error),
                max_rel_t_error_primary: judged
                    .iter()
                    .filter(|(set, _, _)| *set == RaySet::Primary)
                    .map(|(_, l, _)| l.backends[index].max_rel_t_error)
                    .fold(0.0, f32::max),
                max_uv_error: gives_uv.then(|| max_of(|b| b.max_uv_error)),
                hit_agreement: fraction(
                    of(|b| b.hit_mismatch) + of(|b| b.occlusion_mismatch),
                    queries,
                ),
                prim_agreement: fraction(prim_mismatch - certified_ties, intersect_queries),
            }
        })
        .collect()
}

/// Per backend, the first records on which it is wrong, then those on
/// which its distance is off; then the first ambiguous disagreements.
fn samples(judged: &[(RaySet, &CheckLog, Vec<Vec<Judgement>>)]) -> Vec<SampleRecord> {
    let all: Vec<(RaySet, &Record, &Vec<Judgement>)> = judged
        .iter()
        .flat_map(|(set, log, judgements)| {
            log.records
                .iter()
                .zip(judgements)
                .map(|(r, j)| (*set, r, j))
        })
        .collect();
    let backends = judged.first().map_or(0, |(_, log, _)| log.backends.len());
    let mut chosen: Vec<usize> = Vec::new();
    let choose =
        |chosen: &mut Vec<usize>, limit: usize, keep: &dyn Fn(&Record, &[Judgement]) -> bool| {
            let picked = (0..all.len())
                .filter(|&i| keep(all[i].1, all[i].2) && !chosen.contains(&i))
                .take(limit)
                .collect::<Vec<_>>();
            chosen.extend(picked);
        };
    for index in 0..backends {
        for judgement in [
            Judgement::Wrong,
            Judgement::Undecided,
            Judgement::DistanceOff,
        ] {
            choose(&mut chosen, SAMPLES_PER_BACKEND, &|_, j| {
                j[index] == judgement
            });
        }
    }
    choose(&mut chosen, AMBIGUOUS_SAMPLES, &|r, j| {
        r.disagreement && j.iter().all(|j| j.is_admissible())
    });
    let names: Vec<String> = judged
        .first()
        .map(|(_, log, _)| log.backends.iter().map(|b| b.name.clone()).collect())
        .unwrap_or_default();
    chosen
        .into_iter()
        .map(|i| {
            let (set, record, judgements) = all[i];
            SampleRecord {
                ray_set: set,
                query: match record.answers[0] {
                    Answer::Closest(_) => "intersect",
                    Answer::Occluded(_) => "occluded",
                },
                ray: RayRecord::from(&record.ray),
                answers: record
                    .answers
                    .iter()
                    .zip(judgements)
                    .zip(&names)
                    .map(|((answer, &judgement), name)| JudgedAnswer {
                        backend: name.clone(),
                        judgement,
                        answer: AnswerRecord::from(answer),
                    })
                    .collect(),
            }
        })
        .collect()
}

impl CompareSummary {
    /// One row per backend: the referee's verdicts, then how it differs
    /// from the first backend ("—" on the first's own row; "n/a" for
    /// `u`, `v` where a backend gives none).
    pub fn table(&self, caption: &str) -> Table {
        let v = &self.verdicts;
        let sets: Vec<String> = self
            .rays_per_set
            .iter()
            .map(|s| format!("{} {}", s.rays, s.set.name()))
            .collect();
        let mut table = Table::new(
            &format!(
                "{}: {} rays ({}), {} judged, {} ambiguous",
                self.scene,
                v.rays,
                sets.join(", "),
                v.judged,
                v.ambiguous
            ),
            &AGREEMENT_HEADERS,
            caption,
        );
        for (index, tally) in v.backends.iter().enumerate() {
            let mut row = vec![
                Cell::from(tally.name.as_str()),
                Cell::wrong_count(tally.wrong),
                Cell::undecided_count(tally.undecided),
                Cell::wrong_count(tally.t_off),
                Cell::wrong_count(tally.nan_outputs),
            ];
            match index.checked_sub(1).and_then(|i| self.against_first.get(i)) {
                Some(d) => row.extend([
                    Cell::from(d.hit_mismatch.to_string()),
                    d.prim_mismatch.to_string().into(),
                    d.t_mismatch.to_string().into(),
                    d.occlusion_mismatch.to_string().into(),
                    scientific(d.max_rel_t_error).into(),
                    d.max_uv_error
                        .map_or_else(Cell::not_applicable, |e| scientific(e).into()),
                    format!("{:.5}%", 100.0 * d.hit_agreement).into(),
                    format!("{:.4}%", 100.0 * d.prim_agreement).into(),
                ]),
                None => row.extend((0..8).map(|_| Cell::from("—"))),
            }
            table.push(row);
        }
        table
    }
}

/// `x` with three significant digits in scientific notation; 0 as `0`.
fn scientific(x: f32) -> String {
    if x == 0.0 {
        "0".into()
    } else {
        format!("{x:.2e}")
    }
}

/// The columns of [`CompareSummary::table`].
pub const AGREEMENT_HEADERS: [&str; 13] = [
    "backend",
    "wrong",
    "undecided",
    "t off",
    "NaN outputs",
    "hit/miss ≠ first",
    "triangle ≠ first",
    "t ≠ first",
    "occlusion ≠ first",
    "max rel t error",
    "max uv error",
    "hit agreement",
    "prim agreement",
];
