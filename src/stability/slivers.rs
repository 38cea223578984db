//! Case 7: slivers and small triangles. Closed spindles whose triangles
//! have aspect ratios 1e3 to 1e7, hit from inside (every ray must hit); and
//! a 100×100-quad plane seen from 1e6 away, rays aimed at the centroids.

use super::harness::Backends;
use super::shapes::{Placement, grid, sliver_spindle};
use super::{CaseDetails, CaseResult, Context, Trial};
use crate::geometry::Ray;
use crate::random::Rng;
use crate::results::Verdicts;
use glam::{DVec3, Vec3};

pub fn run(context: &Context) -> anyhow::Result<CaseResult> {
    let mut rng = Rng::new(7);
    let mut total = Verdicts::default();
    let mut trials = Vec::new();
    for k in 3..=7 {
        let length = 10f64.powi(k);
        let mesh = sliver_spindle(64, length, Placement::IDENTITY);
        let backends = Backends::new(context, &mesh)?;
        let rays: Vec<Ray> = (0..context.rays(40_000, 600))
            .map(|i| {
                let origin = Vec3::new(
                    rng.range(-0.3, 0.3) as f32,
                    rng.range(-0.3, 0.3) as f32,
                    rng.range(-0.3, 0.3) as f32,
                );
                let [a, b, c] = mesh.triangle(rng.below(mesh.triangle_count()));
                let target = if i % 2 == 0 {
                    b.lerp(c, rng.unit() as f32)
                } else {
                    a.lerp(b, (rng.unit() * 1e-3) as f32 + 0.999)
                };
                Ray::new(origin, target - origin)
            })
            .collect();
        let verdicts = backends.trace_must_hit(&rays);
        total += &verdicts;
        trials.push(Trial {
            label: format!("spindle, aspect ratio {length:e}"),
            verdicts,
        });
    }
    // A plane of 1-unit quads, 1e6 away along z.
    let mesh = grid(
        100,
        Placement {
            scale: 1.0,
            offset: DVec3::new(-50.0, -50.0, 0.0),
        },
    );
    let backends = Backends::new(context, &mesh)?;
    let eye = Vec3::new(0.0, 0.0, 1e6);
    let rays: Vec<Ray> = (0..context.rays(100_000, 2_000))
        .map(|_| {
            let [a, b, c] = mesh.triangle(rng.below(mesh.triangle_count()));
            Ray::new(eye, (a + b + c) / 3.0 - eye)
        })
        .collect();
    let far = backends.trace_must_hit(&rays);
    total += &far;
    trials.push(Trial {
        label: "100×100 plane seen from 1e6".into(),
        verdicts: far,
    });
    let mut result = CaseResult::judged("slivers_and_small_triangles", total).with_leaks();
    result.details = CaseDetails::Trials { trials };
    Ok(result)
}
