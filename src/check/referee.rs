//! Who is right when the backends disagree, decided exactly.
//!
//! Every ray/triangle decision (the edge-function signs, the denominator,
//! the interval bounds) and the order of two hits is evaluated exactly from
//! the f32 inputs ([`super::exact`]). An answer is *right* when it is the
//! exact answer: a miss when no triangle is hit; a hit on a triangle that no
//! other is hit strictly nearer than, at a distance within
//! [`Referee::distance_tolerance`] of the exact one; "occluded" when some
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
//! A difference is `ours_wrong` when our answer is not admissible,
//! `embree_wrong` when ours is and Embree's is not, `ambiguous` otherwise.

use super::difference::{Difference, T_TOLERANCE};
use super::exact::{Oracle, one_ulp_neighbours, one_ulp_vertex_moves};
use crate::geometry::{Hit, Ray, TriangleMesh};

/// Ulps of the largest coordinate a hit point may be off by; see
/// [`Referee::distance_tolerance`].
pub const POSITION_ULPS: f64 = 4.0;

/// The referee's label for one difference.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Verdict {
    /// Our answer is not an admissible one (whatever Embree's is).
    OursWrong,
    /// Ours is admissible and Embree's is not.
    EmbreeWrong,
    /// Both answers are admissible: an exact tie, or an answer that a
    /// one-ulp change of a ray input or of a vertex coordinate makes right.
    Ambiguous,
}

impl Verdict {
    pub fn name(self) -> &'static str {
        match self {
            Verdict::OursWrong => "ours_wrong",
            Verdict::EmbreeWrong => "embree_wrong",
            Verdict::Ambiguous => "ambiguous",
        }
    }
}

/// One backend's answer to one query.
#[derive(Clone, Copy, Debug)]
enum Claim {
    Closest(Option<Hit>),
    Occluded(bool),
}

/// Judges differences against one mesh.
pub struct Referee<'a> {
    mesh: &'a TriangleMesh,
    oracle: Oracle<'a>,
}

impl<'a> Referee<'a> {
    pub fn new(mesh: &'a TriangleMesh) -> Self {
        Self {
            mesh,
            oracle: Oracle::new(mesh),
        }
    }

    pub fn judge(&self, difference: &Difference) -> Verdict {
        let (ray, ours, reference) = match *difference {
            Difference::Intersect {
                ray,
                ours,
                reference,
            } => (ray, Claim::Closest(ours), Claim::Closest(reference)),
            Difference::Occluded {
                ray,
                ours,
                reference,
            } => (ray, Claim::Occluded(ours), Claim::Occluded(reference)),
        };
        if !self.admissible(&ray, ours) {
            Verdict::OursWrong
        } else if !self.admissible(&ray, reference) {
            Verdict::EmbreeWrong
        } else {
            Verdict::Ambiguous
        }
    }

    /// Whether `claim` is the exact answer for `ray`, for a ray one ulp
    /// away in one input, or for the mesh with one vertex coordinate one
    /// ulp away.
    fn admissible(&self, ray: &Ray, claim: Claim) -> bool {
        let oracle = &self.oracle;
        self.right(oracle, ray, claim)
            || one_ulp_neighbours(ray).any(|r| self.right(oracle, &r, claim))
            || one_ulp_vertex_moves(self.mesh, &self.vertices_involved(ray, claim))
                .any(|moved| self.right(&oracle.with_vertex_moved(moved), ray, claim))
    }

    /// The vertices whose one-ulp moves may change the answer to `claim`:
    /// those of the claimed triangle and of every triangle `ray` hits, and
    /// for a claimed occlusion with nothing hit, of every triangle whose
    /// box the ray meets.
    fn vertices_involved(&self, ray: &Ray, claim: Claim) -> Vec<u32> {
        let candidates = self.oracle.candidates(ray);
        let hit: Vec<u32> = candidates
            .iter()
            .copied()
            .filter(|&prim| self.oracle.hit(ray, prim).is_some())
            .collect();
        let triangles = match claim {
            Claim::Closest(Some(claimed)) => [hit, vec![claimed.prim]].concat(),
            Claim::Occluded(true) if hit.is_empty() => candidates,
            _ => hit,
        };
        let mut vertices: Vec<u32> = triangles
            .iter()
            .filter_map(|&prim| self.mesh.indices.get(prim as usize))
            .flatten()
            .copied()
            .collect();
        vertices.sort_unstable();
        vertices.dedup();
        vertices
    }

    /// Whether `claim` is the exact answer for `ray` against `oracle`'s mesh.
    fn right(&self, oracle: &Oracle, ray: &Ray, claim: Claim) -> bool {
        match claim {
            Claim::Occluded(occluded) => oracle.any_hit(ray) == occluded,
            Claim::Closest(None) => !oracle.any_hit(ray),
            Claim::Closest(Some(hit)) => {
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

    fn hit(prim: u32, t: f32) -> Option<Hit> {
        Some(Hit {
            t,
            u: 0.0,
            v: 0.0,
            prim,
            ng: Vec3::Z,
        })
    }

    #[test]
    fn judges_closest_hit_differences() {
        let mesh = two_triangle_quad();
        let referee = Referee::new(&mesh);
        let diagonal = down_at(0.5, 0.5);
        let interior = down_at(0.2, 0.1);
        let judge = |ray: Ray, ours, reference| {
            referee.judge(&Difference::Intersect {
                ray,
                ours,
                reference,
            })
        };
        // The diagonal is shared: either triangle is a valid answer.
        assert_eq!(
            judge(diagonal, hit(0, 1.0), hit(1, 1.0)),
            Verdict::Ambiguous
        );
        // Skipping the front quad for the one behind it is wrong.
        assert_eq!(
            judge(interior, hit(2, 2.0), hit(0, 1.0)),
            Verdict::OursWrong
        );
        assert_eq!(
            judge(interior, hit(0, 1.0), hit(2, 2.0)),
            Verdict::EmbreeWrong
        );
        // A miss where a hit is certain is wrong.
        assert_eq!(judge(interior, None, hit(0, 1.0)), Verdict::OursWrong);
        // A hit at the wrong distance is wrong.
        assert_eq!(
            judge(interior, hit(0, 1.5), hit(0, 1.0)),
            Verdict::OursWrong
        );
        assert_eq!(
            judge(interior, hit(0, 1.0002), hit(0, 1.0)),
            Verdict::OursWrong
        );
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
        let judge = |error: f64| {
            referee.judge(&Difference::Intersect {
                ray,
                ours: hit(0, exact as f32),
                reference: hit(0, (exact + error) as f32),
            })
        };
        assert_eq!(judge(ulp), Verdict::Ambiguous);
        assert_eq!(judge(100.0 * ulp), Verdict::EmbreeWrong);
    }

    #[test]
    fn judges_occlusion_differences() {
        let mesh = two_triangle_quad();
        let referee = Referee::new(&mesh);
        let judge = |ray: Ray, ours, reference| {
            referee.judge(&Difference::Occluded {
                ray,
                ours,
                reference,
            })
        };
        let blocked = down_at(0.2, 0.1);
        assert_eq!(judge(blocked, false, true), Verdict::OursWrong);
        assert_eq!(judge(blocked, true, false), Verdict::EmbreeWrong);
        let mut stops_at_front = down_at(0.2, 0.1);
        stops_at_front.tfar = 1.0;
        assert_eq!(judge(stops_at_front, true, false), Verdict::Ambiguous);
        let outside = down_at(3.0, 3.0);
        assert_eq!(judge(outside, true, false), Verdict::OursWrong);
    }
    /// Steps `x` by `n` f32 ulps.
    fn ulps(x: f32, n: i32) -> f32 {
        f32::from_bits((x.to_bits() as i32 + n) as u32)
    }

    #[test]
    fn one_ulp_beside_an_edge_is_ambiguous_two_is_not() {
        // The unit triangle; its hypotenuse x + y = 1.
        let mesh = TriangleMesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            indices: vec![[0, 1, 2]],
            materials: vec![0],
            ..Default::default()
        };
        let referee = Referee::new(&mesh);
        let judge = |x: f32, ours, reference| {
            referee.judge(&Difference::Intersect {
                ray: down_at(x, 0.5),
                ours,
                reference,
            })
        };
        // Exactly on the edge: a hit is right, a miss is one ulp away.
        assert_eq!(judge(0.5, hit(0, 1.0), None), Verdict::Ambiguous);
        assert_eq!(judge(0.5, None, hit(0, 1.0)), Verdict::Ambiguous);
        // One ulp outside: a miss is right, a hit is one ulp away.
        assert_eq!(judge(ulps(0.5, 1), None, hit(0, 1.0)), Verdict::Ambiguous);
        // Two ulps outside or inside: only one answer is admissible.
        assert_eq!(judge(ulps(0.5, 2), hit(0, 1.0), None), Verdict::OursWrong);
        assert_eq!(judge(ulps(0.5, 2), None, hit(0, 1.0)), Verdict::EmbreeWrong);
        assert_eq!(judge(ulps(0.5, -2), None, hit(0, 1.0)), Verdict::OursWrong);
    }

    #[test]
    fn a_vertex_one_ulp_away_makes_an_edge_ambiguous() {
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
        let judge = |steps: i32, ours, reference| {
            referee.judge(&Difference::Intersect {
                ray: down_at(0.5, ulps(0.5, steps)),
                ours,
                reference,
            })
        };
        // 16 steps above the diagonal: a miss exactly, a hit once the
        // corner moves one step left.
        assert_eq!(judge(16, hit(0, 1.0), None), Verdict::Ambiguous);
        assert_eq!(judge(16, None, hit(0, 1.0)), Verdict::Ambiguous);
        // 2,000 steps above: out of reach of any one-ulp change.
        assert_eq!(judge(2_000, hit(0, 1.0), None), Verdict::OursWrong);
        assert_eq!(judge(2_000, None, hit(0, 1.0)), Verdict::EmbreeWrong);
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
        let judge = |ours, reference| {
            referee.judge(&Difference::Intersect {
                ray,
                ours,
                reference,
            })
        };
        assert_eq!(judge(hit(3, 1.0), hit(0, 1.0)), Verdict::Ambiguous);
        assert_eq!(judge(None, hit(0, 1.0)), Verdict::OursWrong);
        assert_eq!(judge(hit(2, 1.0), None), Verdict::EmbreeWrong);
    }
}
