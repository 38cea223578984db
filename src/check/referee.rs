//! Who is right when the backends disagree, decided exactly.
//!
//! Every ray/triangle decision (the edge-function signs, the denominator,
//! the interval bounds) and the order of two hits is evaluated exactly from
//! the f32 inputs ([`super::exact`]). An answer is *right* when it is the
//! exact answer: a miss when no triangle is hit; a hit on a triangle that no
//! other is hit strictly nearer than, at a distance within
//! `Referee::distance_tolerance` of the exact one; "occluded" when some
//! triangle is hit in the interval. It is *admissible* when it is right for
//! the inputs as given, for a ray one f32 ulp away in one input (an origin
//! or direction component, `tnear` or `tfar`), or for the mesh with one
//! coordinate of one vertex moved by one ulp (a vertex of the claimed
//! triangle, of a triangle the ray hits, or, for a claimed occlusion that
//! nothing causes, of a triangle whose box the ray meets): there the exact
//! answer flips, and no f32 tracer can be asked to land on either side. A
//! moved vertex moves every triangle sharing it, so a ray through a closed
//! mesh's vertex or edge still hits it. Exact ties (one point on several
//! triangles) make several answers right at once.
//!
//! Each answer gets a [`Judgement`]: `Right` (the exact answer),
//! `Admissible` (right after a one-ulp change, or one of a tie), `Wrong`
//! (the decision — hit or miss, which triangle, occluded or not — is not
//! admissible) or `DistanceOff` (an admissible decision at a distance
//! beyond the tolerance: imprecision, counted apart from wrong decisions).
//!
//! The search over one-ulp changes decides each contact of the ray once
//! and, per change, only what the change can touch
//! ([`super::exact::Neighbourhood`]), so judging a wrong answer costs a
//! bounded multiple of judging a right one. It is also capped
//! ([`SEARCH_BUDGET`]): an answer whose search would pass the cap is
//! `Undecided`, counted in its own column, never guessed.

use super::answer::{Answer, T_TOLERANCE};
use super::exact::{
    Change, Claim, Neighbourhood, Oracle, one_ulp_neighbours, one_ulp_vertex_moves,
};
use crate::geometry::{Ray, TriangleMesh};

/// Ulps of the largest coordinate a hit point may be off by; see
/// `Referee::distance_tolerance`.
pub const POSITION_ULPS: f64 = 4.0;

/// Exact evaluations one answer's one-ulp search may make, per triangle
/// whose box the ray meets (plus one): judging a right answer makes about
/// one per such triangle, and a whole search needs far fewer than this
/// (see [`Neighbourhood`]), so an answer is left undecided only where the
/// bound on a search's cost would otherwise be broken.
pub const SEARCH_BUDGET: u64 = 64;

/// The referee's label for one answer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Judgement {
    /// The exact answer for the inputs as given.
    Right,
    /// Not exactly right, but right for a one-ulp change of a ray input or
    /// of a vertex coordinate: no f32 tracer can be asked to do better.
    Admissible,
    /// The decision (hit or miss, which triangle, occluded or not) is not
    /// admissible.
    Wrong,
    /// An admissible triangle at a distance beyond the tolerance.
    DistanceOff,
    /// Not the exact answer, and the one-ulp search ran out of its budget
    /// ([`SEARCH_BUDGET`]) before finding a change that makes it right or
    /// trying them all: neither admissible nor wrong, counted apart.
    Undecided,
}

impl Judgement {
    /// Right or admissible.
    pub fn is_admissible(self) -> bool {
        matches!(self, Judgement::Right | Judgement::Admissible)
    }
}

/// Judges answers against one mesh.
pub struct Referee<'a> {
    mesh: &'a TriangleMesh,
    oracle: Oracle<'a>,
    /// Exact evaluations per nearby triangle one search may make.
    budget: u64,
}

impl<'a> Referee<'a> {
    pub fn new(mesh: &'a TriangleMesh) -> Self {
        Self::with_budget(mesh, SEARCH_BUDGET)
    }

    /// A referee whose searches may make `budget` exact evaluations per
    /// nearby triangle (see [`SEARCH_BUDGET`]).
    pub fn with_budget(mesh: &'a TriangleMesh, budget: u64) -> Self {
        Self {
            mesh,
            oracle: Oracle::new(mesh),
            budget,
        }
    }

    /// The judgement on `answer` to `ray`.
    pub fn judge(&self, ray: &Ray, answer: Answer) -> Judgement {
        self.judge_all(ray, &[answer])[0]
    }

    /// The judgement on each of `answers` to `ray`: equal answers are
    /// judged once, and the answers that are not exactly right share one
    /// search of the ray's neighbourhood.
    pub fn judge_all(&self, ray: &Ray, answers: &[Answer]) -> Vec<Judgement> {
        let mut neighbourhood: Option<Neighbourhood> = None;
        let mut judged: Vec<(Answer, Judgement)> = Vec::new();
        answers
            .iter()
            .map(|&answer| {
                if let Some(&(_, judgement)) = judged.iter().find(|(a, _)| *a == answer) {
                    return judgement;
                }
                let judgement = if self.right(ray, answer) {
                    Judgement::Right
                } else {
                    let neighbourhood =
                        neighbourhood.get_or_insert_with(|| Neighbourhood::new(&self.oracle, *ray));
                    self.search(neighbourhood, ray, answer)
                };
                judged.push((answer, judgement));
                judgement
            })
            .collect()
    }

    /// The judgement on an answer that is not exactly right: the first
    /// one-ulp change that makes it right makes it admissible; one that
    /// makes its decision right at another distance makes it a distance
    /// off; none makes it wrong.
    fn search(&self, neighbourhood: &Neighbourhood, ray: &Ray, answer: Answer) -> Judgement {
        let claim = match answer {
            Answer::Closest(Some(hit)) => Some(neighbourhood.claim(hit.prim)),
            _ => None,
        };
        if claim.as_ref().is_some_and(Claim::beaten) {
            return Judgement::Wrong;
        }
        let budget =
            neighbourhood.work() + self.budget * (neighbourhood.candidates().len() as u64 + 1);
        let (claimed, others) = self.vertices_involved(neighbourhood, answer, claim.as_ref());
        let changes = std::iter::once(Change::None)
            .chain(one_ulp_vertex_moves(self.mesh, &claimed).map(Change::Vertex))
            .chain(one_ulp_neighbours(ray).map(Change::Ray))
            .chain(one_ulp_vertex_moves(self.mesh, &others).map(Change::Vertex));
        let mut decision_right = false;
        for change in changes {
            if neighbourhood.work() > budget {
                return Judgement::Undecided;
            }
            let (decision, distance) =
                self.outcome(neighbourhood, ray, answer, claim.as_ref(), &change);
            if decision && distance {
                return Judgement::Admissible;
            }
            decision_right |= decision;
        }
        if decision_right {
            Judgement::DistanceOff
        } else {
            Judgement::Wrong
        }
    }

    /// Under `change`: whether the decision of `answer` is right, and
    /// whether its distance is within the tolerance too.
    fn outcome(
        &self,
        neighbourhood: &Neighbourhood,
        ray: &Ray,
        answer: Answer,
        claim: Option<&Claim>,
        change: &Change,
    ) -> (bool, bool) {
        match (answer, claim) {
            (Answer::Occluded(occluded), _) => (neighbourhood.any_hit(change) == occluded, true),
            (Answer::Closest(None), _) => (!neighbourhood.any_hit(change), true),
            (Answer::Closest(Some(hit)), Some(claim)) => {
                match neighbourhood.claimed_hit(claim, change) {
                    None => (false, false),
                    Some((t, nearer)) => {
                        let ray = match change {
                            Change::Ray(moved) => moved,
                            _ => ray,
                        };
                        let tolerance = self.distance_tolerance(ray, hit.prim, t);
                        (!nearer, (hit.t as f64 - t).abs() <= tolerance)
                    }
                }
            }
            (Answer::Closest(Some(_)), None) => (false, false),
        }
    }

    /// The vertices whose one-ulp moves may change the answer to `answer`:
    /// those of the claimed triangle, then those of every triangle the ray
    /// hits and, for a claimed occlusion with nothing hit, of every
    /// triangle whose box the ray meets, leaving out the vertices whose
    /// moves can change nothing the answer depends on.
    fn vertices_involved(
        &self,
        neighbourhood: &Neighbourhood,
        answer: Answer,
        claim: Option<&Claim>,
    ) -> (Vec<u32>, Vec<u32>) {
        let claimed: Vec<u32> = match answer {
            Answer::Closest(Some(hit)) => self.vertices_of([hit.prim]),
            _ => Vec::new(),
        };
        let hit: Vec<u32> = neighbourhood.hit_prims().collect();
        let triangles = match answer {
            Answer::Occluded(true) if hit.is_empty() => neighbourhood.candidates().to_vec(),
            _ => hit,
        };
        let others = self
            .vertices_of(triangles)
            .into_iter()
            .filter(|v| !claimed.contains(v) && !neighbourhood.settled(*v, claim))
            .collect();
        (claimed, others)
    }

    /// The vertices of `triangles`, sorted, each once.
    fn vertices_of(&self, triangles: impl IntoIterator<Item = u32>) -> Vec<u32> {
        let mut vertices: Vec<u32> = triangles
            .into_iter()
            .filter_map(|prim| self.mesh.indices.get(prim as usize))
            .flatten()
            .copied()
            .collect();
        vertices.sort_unstable();
        vertices.dedup();
        vertices
    }

    /// Whether `answer` is the exact answer for `ray`.
    fn right(&self, ray: &Ray, answer: Answer) -> bool {
        let oracle = &self.oracle;
        match answer {
            Answer::Occluded(occluded) => oracle.any_hit(ray) == occluded,
            Answer::Closest(None) => !oracle.any_hit(ray),
            Answer::Closest(Some(hit)) => {
                let Some(t) = oracle.hit(ray, hit.prim) else {
                    return false;
                };
                (hit.t as f64 - t).abs() <= self.distance_tolerance(ray, hit.prim, t)
                    && !oracle.nearer_hit_exists(ray, hit.prim)
            }
        }
    }

    /// How far a claimed `t` may be from the exact `t`: [`T_TOLERANCE`]
    /// relative, or [`POSITION_ULPS`] f32 ulps of the largest coordinate
    /// involved, measured along the ray, whichever is larger. The second
    /// term matters for hits much nearer the origin than the coordinates'
    /// magnitude (a secondary ray meeting the surface next to its start):
    /// there no f32 tracer can pin `t` down relatively, yet a hit point
    /// within a few ulps of the exact one is as right as f32 can be.
    fn distance_tolerance(&self, ray: &Ray, prim: u32, t: f64) -> f64 {
        let magnitude = self
            .mesh
            .triangle(prim as usize)
            .iter()
            .fold(ray.origin.abs().max_element(), |m, p| {
                m.max(p.abs().max_element())
            }) as f64;
        let position = POSITION_ULPS * f32::EPSILON as f64 * magnitude / ray.dir.length() as f64;
        (T_TOLERANCE as f64 * t.abs()).max(position)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check::answer::hit;
    use crate::check::exact::MovedVertex;
    use crate::random::Rng;
    use Judgement::{Admissible, DistanceOff, Right, Undecided, Wrong};
    use glam::Vec3;

    fn down_at(x: f32, y: f32) -> Ray {
        Ray::new(Vec3::new(x, y, 1.0), Vec3::new(0.0, 0.0, -1.0))
    }

    fn two_triangle_quad() -> TriangleMesh {
        TriangleMesh {
            positions: vec![
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
                // A second quad behind the first.
                Vec3::new(0.0, 0.0, -1.0),
                Vec3::new(1.0, 0.0, -1.0),
                Vec3::new(0.0, 1.0, -1.0),
            ],
            indices: vec![[0, 1, 2], [0, 2, 3], [4, 5, 6]],
            materials: vec![0, 0, 0],
            ..Default::default()
        }
    }

    const MISS: Answer = Answer::Closest(None);

    #[test]
    fn judges_closest_hits() {
        let mesh = two_triangle_quad();
        let referee = Referee::new(&mesh);
        // The diagonal is shared: either triangle is exactly right.
        let diagonal = down_at(0.5, 0.5);
        assert_eq!(referee.judge(&diagonal, hit(0, 1.0)), Right);
        assert_eq!(referee.judge(&diagonal, hit(1, 1.0)), Right);
        let interior = down_at(0.2, 0.1);
        assert_eq!(referee.judge(&interior, hit(0, 1.0)), Right);
        // Skipping the front quad for the one behind it is wrong.
        assert_eq!(referee.judge(&interior, hit(2, 2.0)), Wrong);
        // A miss where a hit is certain is wrong.
        assert_eq!(referee.judge(&interior, MISS), Wrong);
        // The right triangle at the wrong distance is a distance fault.
        assert_eq!(referee.judge(&interior, hit(0, 1.5)), DistanceOff);
        assert_eq!(referee.judge(&interior, hit(0, 1.0002)), DistanceOff);
    }

    #[test]
    fn a_tiny_t_is_judged_by_the_position_it_gives() {
        // A triangle at z = 1000 and a ray starting 1e-3 above it: f32
        // coordinates near 1000 are 6e-5 apart, so t cannot be known to 1e-5
        // relative; one ulp of 1000 along the ray is still right, 100 not.
        let mesh = TriangleMesh {
            positions: vec![
                Vec3::new(999.0, 999.0, 1000.0),
                Vec3::new(1001.0, 999.0, 1000.0),
                Vec3::new(999.0, 1001.0, 1000.0),
            ],
            indices: vec![[0, 1, 2]],
            materials: vec![0],
            ..Default::default()
        };
        let referee = Referee::new(&mesh);
        let ray = Ray::new(Vec3::new(999.5, 999.5, 1000.001), Vec3::new(0.0, 0.0, -1.0));
        let exact = 1000.001f32 as f64 - 1000.0;
        let ulp = (1000f32.next_up() - 1000.0) as f64;
        let judge = |error: f64| referee.judge(&ray, hit(0, (exact + error) as f32));
        assert_eq!(judge(0.0), Right);
        assert_eq!(judge(ulp), Right);
        assert_eq!(judge(100.0 * ulp), DistanceOff);
    }

    #[test]
    fn judges_occlusion() {
        let mesh = two_triangle_quad();
        let referee = Referee::new(&mesh);
        let blocked = down_at(0.2, 0.1);
        assert_eq!(referee.judge(&blocked, Answer::Occluded(false)), Wrong);
        assert_eq!(referee.judge(&blocked, Answer::Occluded(true)), Right);
        // Ending exactly on the front quad: occluded (the interval is
        // closed), and one ulp shorter it is not.
        let mut stops_at_front = down_at(0.2, 0.1);
        stops_at_front.tfar = 1.0;
        assert_eq!(
            referee.judge(&stops_at_front, Answer::Occluded(true)),
            Right
        );
        assert_eq!(
            referee.judge(&stops_at_front, Answer::Occluded(false)),
            Admissible
        );
        let outside = down_at(3.0, 3.0);
        assert_eq!(referee.judge(&outside, Answer::Occluded(true)), Wrong);
    }

    /// Steps `x` by `n` f32 ulps.
    fn ulps(x: f32, n: i32) -> f32 {
        f32::from_bits((x.to_bits() as i32 + n) as u32)
    }

    #[test]
    fn one_ulp_beside_an_edge_is_admissible_two_is_not() {
        // The unit triangle; its hypotenuse x + y = 1.
        let mesh = TriangleMesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            indices: vec![[0, 1, 2]],
            materials: vec![0],
            ..Default::default()
        };
        let referee = Referee::new(&mesh);
        let judge = |x: f32, answer| referee.judge(&down_at(x, 0.5), answer);
        // Exactly on the edge: a hit is right, a miss is one ulp away.
        assert_eq!(judge(0.5, hit(0, 1.0)), Right);
        assert_eq!(judge(0.5, MISS), Admissible);
        // One ulp outside: a miss is right, a hit is one ulp away.
        assert_eq!(judge(ulps(0.5, 1), MISS), Right);
        assert_eq!(judge(ulps(0.5, 1), hit(0, 1.0)), Admissible);
        // Two ulps outside or inside: only one answer is admissible.
        assert_eq!(judge(ulps(0.5, 2), hit(0, 1.0)), Wrong);
        assert_eq!(judge(ulps(0.5, 2), MISS), Right);
        assert_eq!(judge(ulps(0.5, -2), MISS), Wrong);
    }

    #[test]
    fn a_vertex_one_ulp_away_makes_an_edge_admissible() {
        // One triangle below the diagonal y = x, its corners at ±1000 where
        // f32 steps are 6.1e-5: moving the corner (1000, 1000) by one step
        // shifts the diagonal by 3e-5 near the origin, far more than one
        // step of the ray's inputs there (6e-8).
        let mesh = TriangleMesh {
            positions: vec![
                Vec3::new(-1000.0, -1000.0, 0.0),
                Vec3::new(1000.0, -1000.0, 0.0),
                Vec3::new(1000.0, 1000.0, 0.0),
            ],
            indices: vec![[0, 1, 2]],
            materials: vec![0],
            ..Default::default()
        };
        let referee = Referee::new(&mesh);
        let judge = |steps: i32, answer| referee.judge(&down_at(0.5, ulps(0.5, steps)), answer);
        // 16 steps above the diagonal: a miss exactly, a hit once the
        // corner moves one step left.
        assert_eq!(judge(16, MISS), Right);
        assert_eq!(judge(16, hit(0, 1.0)), Admissible);
        // 2,000 steps above: out of reach of any one-ulp change.
        assert_eq!(judge(2_000, MISS), Right);
        assert_eq!(judge(2_000, hit(0, 1.0)), Wrong);
    }

    #[test]
    fn a_miss_through_a_closed_fan_vertex_is_wrong() {
        // Four triangles around the origin: a ray through the shared
        // vertex hits all four exactly (a tie), and no one-ulp change of
        // the ray makes it miss them all.
        let mesh = TriangleMesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::NEG_X, Vec3::NEG_Y],
            indices: vec![[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1]],
            materials: vec![0; 4],
            ..Default::default()
        };
        let referee = Referee::new(&mesh);
        let ray = Ray::new(Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.0, 0.0, -1.0));
        assert_eq!(referee.judge(&ray, hit(3, 1.0)), Right);
        assert_eq!(referee.judge(&ray, hit(0, 1.0)), Right);
        assert_eq!(referee.judge(&ray, MISS), Wrong);
    }

    /// The referee's judgement by its definition, every change decided
    /// from scratch: the search the referee makes incrementally.
    fn by_definition(mesh: &TriangleMesh, ray: &Ray, answer: Answer) -> Judgement {
        let oracle = Oracle::new(mesh);
        let referee = Referee::new(mesh);
        let right = |oracle: &Oracle, ray: &Ray, distance: bool| match answer {
            Answer::Occluded(occluded) => oracle.any_hit(ray) == occluded,
            Answer::Closest(None) => !oracle.any_hit(ray),
            Answer::Closest(Some(hit)) => oracle.hit(ray, hit.prim).is_some_and(|t| {
                (!distance
                    || (hit.t as f64 - t).abs() <= referee.distance_tolerance(ray, hit.prim, t))
                    && !oracle.nearer_hit_exists(ray, hit.prim)
            }),
        };
        let candidates = oracle.candidates(ray);
        let hit: Vec<u32> = candidates
            .iter()
            .copied()
            .filter(|&prim| oracle.hit(ray, prim).is_some())
            .collect();
        let triangles = match answer {
            Answer::Closest(Some(claimed)) => [hit, vec![claimed.prim]].concat(),
            Answer::Occluded(true) if hit.is_empty() => candidates,
            _ => hit,
        };
        let vertices = referee.vertices_of(triangles);
        let moves: Vec<MovedVertex> = one_ulp_vertex_moves(mesh, &vertices).collect();
        let admissible = |distance: bool| {
            right(&oracle, ray, distance)
                || one_ulp_neighbours(ray).any(|r| right(&oracle, &r, distance))
                || moves
                    .iter()
                    .any(|&m| right(&oracle.with_vertex_moved(m), ray, distance))
        };
        if right(&oracle, ray, true) {
            Right
        } else if admissible(true) {
            Admissible
        } else if matches!(answer, Answer::Closest(Some(_))) && admissible(false) {
            DistanceOff
        } else {
            Wrong
        }
    }

    /// Fans around shared vertices, a copy one ulp above, duplicates, a
    /// collapsed triangle and a sliver: nearly coincident geometry where
    /// one-ulp changes decide.
    fn crowded_mesh(rng: &mut Rng) -> TriangleMesh {
        let mut mesh = TriangleMesh::default();
        let scale = [1e-3f32, 1.0, 1e3][rng.below(3)];
        let fan = |mesh: &mut TriangleMesh, z: f32| {
            let centre = mesh.positions.len() as u32;
            mesh.positions.push(Vec3::new(0.0, 0.0, z));
            for k in 0..6 {
                let angle = k as f32 * std::f32::consts::TAU / 6.0;
                mesh.positions
                    .push(Vec3::new(angle.cos() * scale, angle.sin() * scale, z));
            }
            for k in 0..6 {
                mesh.indices
                    .push([centre, centre + 1 + k, centre + 1 + (k + 1) % 6]);
            }
        };
        fan(&mut mesh, 0.0);
        fan(&mut mesh, f32::MIN_POSITIVE);
        fan(&mut mesh, (0.5 * scale).next_up());
        let first = mesh.triangle(0);
        let sliver = [
            first[0],
            first[1],
            first[1] + Vec3::new(0.0, 0.0, scale * 1e-7),
        ];
        let collapsed = [first[1]; 3];
        for triangle in [first, sliver, collapsed] {
            let base = mesh.positions.len() as u32;
            mesh.positions.extend(triangle);
            mesh.indices.push([base, base + 1, base + 2]);
        }
        mesh.materials = vec![0; mesh.indices.len()];
        mesh
    }

    #[test]
    fn the_incremental_search_judges_as_the_definition_does() {
        let mut rng = Rng::new(23);
        let mut seen = std::collections::BTreeMap::new();
        for _ in 0..12 {
            let mesh = crowded_mesh(&mut rng);
            let referee = Referee::new(&mesh);
            let oracle = Oracle::new(&mesh);
            for _ in 0..10 {
                // Aim at a vertex, an edge's middle or a corner's
                // neighbourhood, exactly or one ulp beside.
                let triangle = mesh.triangle(rng.below(mesh.triangle_count()));
                let (a, b) = (triangle[rng.below(3)], triangle[rng.below(3)]);
                let mut target = (a + b) * 0.5;
                if rng.below(2) == 0 {
                    target.x = target.x.next_up();
                }
                let origin = target + rng.direction() * 2.0 + Vec3::new(0.0, 0.0, 1.5);
                let mut ray = Ray::new(origin, target - origin);
                if rng.below(4) == 0 {
                    ray.tfar = 1.0;
                }
                let mut answers = vec![
                    Answer::Closest(None),
                    Answer::Occluded(true),
                    Answer::Occluded(false),
                ];
                for prim in oracle.candidates(&ray) {
                    let t = oracle.hit(&ray, prim).unwrap_or(1.0) as f32;
                    answers.push(hit(prim, t));
                    answers.push(hit(prim, t * 1.01));
                }
                let judged = referee.judge_all(&ray, &answers);
                for (answer, judgement) in answers.iter().zip(judged) {
                    assert_eq!(
                        judgement,
                        by_definition(&mesh, &ray, *answer),
                        "{ray:?} {answer:?}"
                    );
                    *seen.entry(judgement).or_insert(0) += 1;
                }
            }
        }
        // Every label, each many times.
        assert!(
            seen.len() == 4 && seen.values().all(|&n| n > 20),
            "{seen:?}"
        );
    }

    #[test]
    fn a_search_past_its_budget_is_undecided() {
        let mesh = TriangleMesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            indices: vec![[0, 1, 2]],
            materials: vec![0],
            ..Default::default()
        };
        // A hit one ulp outside the hypotenuse: admissible, found by a
        // search that a budget of nothing cannot make.
        let ray = down_at(ulps(0.5, 1), 0.5);
        assert_eq!(Referee::new(&mesh).judge(&ray, hit(0, 1.0)), Admissible);
        let starved = Referee::with_budget(&mesh, 0);
        assert_eq!(starved.judge(&ray, hit(0, 1.0)), Undecided);
        // Right answers need no search.
        assert_eq!(starved.judge(&ray, MISS), Right);
    }
}
