//! Who is right when the backends disagree: every triangle involved is
//! re-evaluated in f64 from the exact f32 inputs.
//!
//! The test is the Plücker form of the ray/triangle test (the edge
//! functions of Woop, Benthin, Wald 2013 without the shear), evaluated with
//! the vertices translated to the ray origin. An f32 input converts exactly
//! to f64, and every quantity here is a short sum of products, so its f64
//! value carries a relative error near 1e-15, far below the f32 precision
//! the backends work at. A decision within [`BOUNDARY`] (relative to the
//! magnitude of its terms) of flipping is *on the boundary*: an f32 tracer
//! may take either side of it, so both answers are valid there.

use super::difference::{Difference, T_TOLERANCE};
use crate::geometry::{Hit, Ray, TriangleMesh};
use rayon::prelude::*;

/// Relative band around a zero edge function, or around `tnear`/`tfar`,
/// inside which either decision is valid: 64 f32 ulps.
pub const BOUNDARY: f64 = 64.0 * f32::EPSILON as f64 / 2.0;

/// Ulps of the largest coordinate a hit point may be off by; see
/// [`Referee::distance_tolerance`].
pub const POSITION_ULPS: f64 = 4.0;

/// The referee's label for one difference.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Verdict {
    /// Our answer is not a valid one (whatever Embree's is).
    OursWrong,
    /// Ours is valid and Embree's is not.
    EmbreeWrong,
    /// Both answers are valid: a tie, or a ray on an edge within f32 precision.
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

/// How a ray meets one triangle, in f64.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Contact {
    /// Certainly no hit within the ray's interval.
    Miss,
    /// A hit at `t` that f32 rounding could turn into a miss.
    Boundary { t: f64 },
    /// Certainly a hit at `t` within the ray's interval.
    Hit { t: f64 },
}

impl Contact {
    fn t(self) -> Option<f64> {
        match self {
            Contact::Miss => None,
            Contact::Boundary { t } | Contact::Hit { t } => Some(t),
        }
    }
}

/// Judges differences against one mesh.
pub struct Referee<'a> {
    mesh: &'a TriangleMesh,
}

impl<'a> Referee<'a> {
    pub fn new(mesh: &'a TriangleMesh) -> Self {
        Self { mesh }
    }

    pub fn judge(&self, difference: &Difference) -> Verdict {
        match difference {
            Difference::Intersect {
                ray,
                ours,
                reference,
            } => self.verdict(
                self.closest_hit_valid(ray, ours),
                self.closest_hit_valid(ray, reference),
            ),
            Difference::Occluded {
                ray,
                ours,
                reference,
            } => self.verdict(
                self.occlusion_valid(ray, *ours),
                self.occlusion_valid(ray, *reference),
            ),
        }
    }

    fn verdict(&self, ours_valid: bool, reference_valid: bool) -> Verdict {
        match (ours_valid, reference_valid) {
            (false, _) => Verdict::OursWrong,
            (true, false) => Verdict::EmbreeWrong,
            (true, true) => Verdict::Ambiguous,
        }
    }

    /// How `ray` meets triangle `prim`.
    pub fn contact(&self, ray: &Ray, prim: u32) -> Contact {
        contact(ray, self.mesh.triangle(prim as usize).map(|p| p.to_array()))
    }

    /// The nearest certain hit over all triangles, if any.
    fn nearest_certain_hit(&self, ray: &Ray) -> Option<f64> {
        (0..self.mesh.triangle_count() as u32)
            .into_par_iter()
            .filter_map(|prim| match self.contact(ray, prim) {
                Contact::Hit { t } => Some(t),
                _ => None,
            })
            .min_by(f64::total_cmp)
    }

    /// A claimed closest hit is valid when its triangle is (possibly) hit at
    /// the claimed `t` and no triangle is certainly hit clearly nearer; a
    /// claimed miss is valid when no triangle is certainly hit.
    fn closest_hit_valid(&self, ray: &Ray, claim: &Option<Hit>) -> bool {
        let nearest = self.nearest_certain_hit(ray);
        let Some(hit) = claim else {
            return nearest.is_none();
        };
        if hit.prim as usize >= self.mesh.triangle_count() {
            return false;
        }
        let Some(t) = self.contact(ray, hit.prim).t() else {
            return false;
        };
        let tolerance = self.distance_tolerance(ray, hit.prim, t);
        let t_matches = (hit.t as f64 - t).abs() <= tolerance;
        let none_nearer = nearest.is_none_or(|n| n >= t - tolerance);
        t_matches && none_nearer
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

    /// "Occluded" is valid when some triangle is (possibly) hit in the
    /// interval; "not occluded" when none is certainly hit.
    fn occlusion_valid(&self, ray: &Ray, claim: bool) -> bool {
        let contacts = (0..self.mesh.triangle_count() as u32)
            .into_par_iter()
            .map(|prim| self.contact(ray, prim));
        if claim {
            contacts.any(|c| c != Contact::Miss)
        } else {
            !contacts.any(|c| matches!(c, Contact::Hit { .. }))
        }
    }
}

/// How `ray` meets the triangle with corners `p`, evaluated in f64.
pub fn contact(ray: &Ray, p: [[f32; 3]; 3]) -> Contact {
    let o = ray.origin.to_array().map(f64::from);
    let d = ray.dir.to_array().map(f64::from);
    let [a, b, c] = p.map(|v| sub(v.map(f64::from), o));
    if ![a, b, c, d].iter().flatten().all(|x| x.is_finite()) {
        return Contact::Miss;
    }
    // Edge functions: the signed volumes spanned by the ray and each edge.
    // `u` (weight of p1) pairs with the edge opposite p1, and so on.
    let e0 = triple(d, c, b);
    let e1 = triple(d, a, c);
    let e2 = triple(d, b, a);
    let scale = |x: [f64; 3], y: [f64; 3]| norm(d) * norm(x) * norm(y);
    let bands = [scale(c, b), scale(a, c), scale(b, a)].map(|s| s * BOUNDARY);
    let edges = [e0, e1, e2];
    let positive = edges.iter().zip(&bands).any(|(e, band)| *e > *band);
    let negative = edges.iter().zip(&bands).any(|(e, band)| *e < -*band);
    if positive && negative {
        return Contact::Miss;
    }
    let on_edge = edges.iter().zip(&bands).any(|(e, band)| e.abs() <= *band);
    let normal = cross(sub(b, a), sub(c, a));
    let denominator = dot(d, normal);
    let det_band = BOUNDARY * norm(d) * norm(normal);
    if denominator.abs() <= det_band {
        // The ray lies in the triangle's plane (to f32 precision).
        return Contact::Miss;
    }
    let t = dot(a, normal) / denominator;
    let (tnear, tfar) = (ray.tnear as f64, ray.tfar as f64);
    let t_band = BOUNDARY * t.abs().max(tnear.abs());
    if t < tnear - t_band || t > tfar + t_band {
        return Contact::Miss;
    }
    let at_bound = t <= tnear + t_band || (tfar.is_finite() && t >= tfar - BOUNDARY * tfar.abs());
    if on_edge || at_bound {
        Contact::Boundary { t }
    } else {
        Contact::Hit { t }
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn triple(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    dot(a, cross(b, c))
}

fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    const TRI: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

    fn down_at(x: f32, y: f32) -> Ray {
        Ray::new(Vec3::new(x, y, 1.0), Vec3::new(0.0, 0.0, -1.0))
    }

    #[test]
    fn interior_edge_and_outside() {
        assert_eq!(contact(&down_at(0.25, 0.25), TRI), Contact::Hit { t: 1.0 });
        assert_eq!(
            contact(&down_at(0.5, 0.5), TRI),
            Contact::Boundary { t: 1.0 }
        );
        assert_eq!(
            contact(&down_at(0.0, 0.0), TRI),
            Contact::Boundary { t: 1.0 }
        );
        assert_eq!(contact(&down_at(0.6, 0.6), TRI), Contact::Miss);
        assert_eq!(contact(&down_at(-0.1, 0.2), TRI), Contact::Miss);
    }

    #[test]
    fn interval_bounds() {
        let mut ray = down_at(0.25, 0.25);
        ray.tfar = 0.5;
        assert_eq!(contact(&ray, TRI), Contact::Miss);
        ray.tfar = 1.0;
        assert_eq!(contact(&ray, TRI), Contact::Boundary { t: 1.0 });
        ray.tfar = 2.0;
        ray.tnear = 1.5;
        assert_eq!(contact(&ray, TRI), Contact::Miss);
    }

    #[test]
    fn ray_in_the_plane_misses() {
        let ray = Ray::new(Vec3::new(-1.0, 0.25, 0.0), Vec3::X);
        assert_eq!(contact(&ray, TRI), Contact::Miss);
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
}
