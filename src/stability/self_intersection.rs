//! Case 11: self-intersection, after the pbrt-v4 `Triangle.Reintersect`
//! test (Pharr, Jakob, Humphreys, pbrt-v4, section 6.8.6): from points hit
//! on random triangles, rays spawned over the hemisphere must not hit the
//! triangle again, shadow rays to a point on the same side must not be
//! blocked by it, and a second surface a small gap above must still be
//! hit. Our offset (`geometry::offset`, Wächter & Binder) against fixed
//! `tnear` epsilons from 1e-2 to 1e-9.

use super::harness::Backends;
use super::shapes::Placement;
use super::{CaseDetails, CaseResult, Context};
use crate::exact::{normal_side, plane_side};
use crate::geometry::offset::offset_ray_origin;
use crate::geometry::triangle::{WatertightRay, geometric_normal};
use crate::geometry::{Ray, TriangleMesh};
use crate::random::Rng;
use crate::results::Verdicts;
use glam::{DVec3, Vec3};
use serde::Serialize;
use std::cmp::Ordering;

/// How a spawned ray avoids the surface it leaves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Spawn {
    /// Our method: the origin moved off the surface.
    Offset,
    /// The origin on the surface, `tnear` = this epsilon.
    Epsilon(f32),
}

impl Spawn {
    fn ray(self, point: Vec3, normal: Vec3, dir: Vec3, tfar: f32) -> Ray {
        match self {
            Spawn::Offset => Ray::segment(offset_ray_origin(point, normal), dir, 0.0, tfar),
            Spawn::Epsilon(e) => Ray::segment(point, dir, e, tfar),
        }
    }

    pub fn name(self) -> String {
        match self {
            Spawn::Offset => "offset".into(),
            Spawn::Epsilon(e) => format!("epsilon {e:e}"),
        }
    }
}

/// The methods compared: ours and the fixed epsilons.
pub fn methods() -> Vec<Spawn> {
    std::iter::once(Spawn::Offset)
        .chain((2..=9).map(|k| Spawn::Epsilon(10f32.powi(-k))))
        .collect()
}

/// What one method did at one placement.
#[derive(Clone, Debug, Default, Serialize)]
pub struct SpawnStats {
    pub method: String,
    pub scale: f64,
    pub translation: f64,
    pub rays: u64,
    pub self_hits: u64,
    pub false_occlusions: u64,
    /// The smallest gap (relative to the scale) between two parallel
    /// surfaces that every spawned ray still resolved, if any did.
    pub smallest_resolved_gap: Option<f64>,
}

/// A surface point: the triangle, the hit point as the renderer computes
/// it (from barycentrics) and the geometric normal towards the viewer.
struct Sample {
    corners: [Vec3; 3],
    point: Vec3,
    normal: Vec3,
    /// The exact side of the triangle's plane `normal` points to.
    facing: Ordering,
    /// The unit normal in f64 of the unrounded triangle, for the gap test.
    unit_normal: DVec3,
    /// The unrounded triangle at unit scale, where the light is placed.
    exact: [DVec3; 3],
}

/// Draws attempts per sample asked for: where f32 collapses every triangle
/// of the placement (scale 1e-6 at 1e7), fewer samples come back.
const ATTEMPTS_PER_SAMPLE: usize = 100;

fn samples(placement: Placement, count: usize, rng: &mut Rng) -> Vec<Sample> {
    let mut out = Vec::with_capacity(count);
    for _ in 0..count * ATTEMPTS_PER_SAMPLE {
        if out.len() == count {
            break;
        }
        let exact: [DVec3; 3] = std::array::from_fn(|_| rng.direction().as_dvec3());
        let corners = exact.map(|p| placement.apply(p));
        let n = geometric_normal(corners[0], corners[1], corners[2]);
        let unit_normal = (exact[1] - exact[0]).cross(exact[2] - exact[0]).normalize();
        if n == Vec3::ZERO || !unit_normal.is_finite() {
            continue;
        }
        let (u, v) = (rng.unit(), rng.unit());
        let (u, v) = if u + v > 1.0 {
            (1.0 - u, 1.0 - v)
        } else {
            (u, v)
        };
        // Aimed at a point of the rounded triangle, which the ray then hits.
        let [p0, p1, p2] = corners.map(Vec3::as_dvec3);
        let target = p0 * (1.0 - u - v) + p1 * u + p2 * v;
        let eye = placement.apply(placement.unapply(target) + 2.0 * rng.direction().as_dvec3());
        let ray = Ray::new(eye, target.as_vec3() - eye);
        let Some(hit) = WatertightRay::new(&ray).intersect(
            corners[0],
            corners[1],
            corners[2],
            0.0,
            f32::INFINITY,
        ) else {
            continue;
        };
        let point = (1.0 - hit.u - hit.v) * corners[0] + hit.u * corners[1] + hit.v * corners[2];
        // The side the ray came from, decided exactly so that a light on
        // the other side is never counted as a false occlusion.
        let facing = normal_side(&corners.map(|c| c.to_array()), &ray.dir.to_array()).reverse();
        let normal = if facing == Ordering::Less { -n } else { n };
        let unit_normal = if unit_normal.dot(normal.as_dvec3()) > 0.0 {
            unit_normal
        } else {
            -unit_normal
        };
        out.push(Sample {
            corners,
            point,
            normal,
            facing,
            unit_normal,
            exact,
        });
    }
    out
}

fn hits(ray: &Ray, corners: &[Vec3; 3]) -> bool {
    WatertightRay::new(ray)
        .intersect(corners[0], corners[1], corners[2], ray.tnear, ray.tfar)
        .is_some()
}

/// An equilateral triangle of unit circumradius, parallel to the sample's
/// triangle at `gap` above the sample point and centred over it, so that
/// the ray straight up meets it far from its edges however thin the
/// sample's own triangle is.
fn surface_above(s: &Sample, placement: Placement, gap: f64) -> [Vec3; 3] {
    let centre = placement.unapply(s.point.as_dvec3()) + s.unit_normal * gap;
    let (u, w) = s.unit_normal.any_orthonormal_pair();
    std::array::from_fn(|k| {
        let angle = k as f64 * std::f64::consts::TAU / 3.0;
        placement.apply(centre + u * angle.cos() + w * angle.sin())
    })
}

/// A direction on the hemisphere around `normal`.
fn hemisphere(rng: &mut Rng, normal: Vec3) -> Vec3 {
    let d = rng.direction();
    if d.dot(normal) < 0.0 { -d } else { d }
}

/// Spawns one hemisphere ray and one shadow ray per sample with `method`,
/// and the gap test over gaps 10^-1 … 10^-9 of the scale.
pub fn spawn_trial(placement: Placement, method: Spawn, count: usize, seed: u64) -> SpawnStats {
    let mut rng = Rng::new(seed);
    let samples = samples(placement, count, &mut rng);
    let mut stats = SpawnStats {
        method: method.name(),
        scale: placement.scale,
        translation: placement.offset.x,
        ..Default::default()
    };
    for s in &samples {
        let leave = method.ray(
            s.point,
            s.normal,
            hemisphere(&mut rng, s.normal),
            f32::INFINITY,
        );
        stats.self_hits += hits(&leave, &s.corners) as u64;
        let light = placement.apply(
            s.exact[0] + s.unit_normal * rng.range(0.1, 1.0) + 0.5 * rng.direction().as_dvec3(),
        );
        let origin = method.ray(s.point, s.normal, Vec3::ZERO, 1.0).origin;
        let shadow = method.ray(s.point, s.normal, light - origin, 1.0);
        let on_side = plane_side(&s.corners.map(|c| c.to_array()), &light.to_array()) == s.facing;
        stats.false_occlusions += (on_side && hits(&shadow, &s.corners)) as u64;
        stats.rays += 2;
    }
    stats.smallest_resolved_gap = (1..=9)
        .map(|k| 10f64.powi(-k))
        .take_while(|&gap| {
            !samples.is_empty()
                && samples.iter().all(|s| {
                    let upper = surface_above(s, placement, gap);
                    let up = method.ray(s.point, s.normal, s.unit_normal.as_vec3(), f32::INFINITY);
                    hits(&up, &upper) && !hits(&up, &s.corners)
                })
        })
        .last();
    stats
}

pub fn run(context: &Context) -> anyhow::Result<CaseResult> {
    let count = context.rays(100_000, 2_000);
    let table: Vec<SpawnStats> = methods()
        .into_iter()
        .map(|m| spawn_trial(Placement::IDENTITY, m, count, 11))
        .collect();
    let verdicts = judged_spawns(context, Placement::IDENTITY, context.rays(20_000, 500))?;
    let mut result = CaseResult::judged("self_intersection", verdicts);
    result.self_hits = Some(table[0].self_hits);
    result.rays += table.iter().map(|s| s.rays).sum::<u64>();
    result.details = CaseDetails::Spawns { methods: table };
    Ok(result)
}

/// Rays spawned with our offset from hits on 64 random triangles, traced
/// through every selected backend against the 64 triangles and judged.
pub fn judged_spawns(
    context: &Context,
    placement: Placement,
    count: usize,
) -> anyhow::Result<Verdicts> {
    let mut rng = Rng::new(111);
    let pool = samples(placement, 64, &mut rng);
    let mesh = TriangleMesh::soup(&pool.iter().map(|s| s.corners).collect::<Vec<_>>());
    let backends = Backends::new(context, &mesh)?;
    let rays: Vec<Ray> = (0..count)
        .map(|i| {
            let s = &pool[i % pool.len()];
            Spawn::Offset.ray(
                s.point,
                s.normal,
                hemisphere(&mut rng, s.normal),
                f32::INFINITY,
            )
        })
        .collect();
    Ok(backends.trace(&rays))
}
