//! Case 5: grazing rays, at angles 10^-k rad (k = 1..7) to a plane of
//! triangles, aimed at points of its interior.

use super::harness::Backends;
use super::shapes::{Placement, grid};
use super::{CaseDetails, CaseResult, Context, Trial};
use crate::geometry::Ray;
use crate::random::Rng;
use crate::results::Verdicts;
use glam::DVec3;

pub fn run(context: &Context) -> anyhow::Result<CaseResult> {
    let (total, trials) = grazing_trial(context, Placement::IDENTITY, context.rays(30_000, 500))?;
    let mut result = CaseResult::judged("grazing_rays", total);
    result.details = CaseDetails::Trials { trials };
    Ok(result)
}

/// `per_angle` rays for each angle against a 16×16 grid of unit quads
/// centred on the origin, placed by `placement`.
pub fn grazing_trial(
    context: &Context,
    placement: Placement,
    per_angle: usize,
) -> anyhow::Result<(Verdicts, Vec<Trial>)> {
    let centred = Placement {
        scale: placement.scale,
        offset: placement.offset - DVec3::new(8.0, 8.0, 0.0) * placement.scale,
    };
    let mesh = grid(16, centred);
    let backends = Backends::new(context, &mesh)?;
    let mut rng = Rng::new(5);
    let mut total = Verdicts::default();
    let mut trials = Vec::new();
    for k in 1..=7 {
        let angle = 10f64.powi(-k);
        let rays: Vec<Ray> = (0..per_angle)
            .map(|_| {
                let azimuth = rng.range(0.0, std::f64::consts::TAU);
                let dir = DVec3::new(
                    angle.cos() * azimuth.cos(),
                    angle.cos() * azimuth.sin(),
                    -angle.sin(),
                );
                let target = DVec3::new(rng.range(-6.0, 6.0), rng.range(-6.0, 6.0), 0.0);
                let origin = placement.apply(target - dir * rng.range(0.5, 2.0));
                Ray::new(origin, dir.as_vec3())
            })
            .collect();
        let verdicts = backends.trace(&rays);
        total += &verdicts;
        trials.push(Trial {
            label: format!("angle {angle:e} rad"),
            verdicts,
        });
    }
    Ok((total, trials))
}
