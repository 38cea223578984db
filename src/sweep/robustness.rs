//! What robustness costs: for our tracer, Embree's default and Embree
//! ROBUST, how often the exact referee calls a ray's answer wrong, against
//! how many rays a second each traces.
//!
//! Wrong answers are counted as everywhere in the harness (in rays, every
//! disagreement judged and a fixed sample of the agreements, see
//! [`crate::results::Verdicts`]): on the stability catalogue's rays, from
//! results already computed, and on each scene's compare rays. Speed is
//! `raycheck perf`'s measurement of each backend on the scene's primary,
//! shadow and diffuse rays ([`crate::perf::measure`]); the catalogue's
//! point stands at each backend's speed over all those scenes together.

use crate::backends::BackendName;
use crate::parallel::Workers;
use crate::perf::measure::{PerfRow, measure};
use crate::perf::rays::RaySets;
use crate::results::{Verdicts, compare_scene};
use crate::scene::Scene;
use crate::stability::CaseResult;
use serde::Serialize;

/// Where the rays of a point come from.
pub const CATALOGUE: &str = "stability catalogue";

/// How big the measurement is.
#[derive(Clone, Debug)]
pub struct RobustnessPlan {
    /// Primary rays per side of each scene's view.
    pub resolution: u32,
    /// Timed runs of each ray set.
    pub runs: usize,
}

/// One backend on one set of rays.
#[derive(Clone, Debug, Serialize)]
pub struct RobustnessPoint {
    pub backend: String,
    /// [`CATALOGUE`] or a scene's name.
    pub rays_from: String,
    pub rays: u64,
    pub wrong: u64,
    /// `wrong / rays`.
    pub wrong_rate: f64,
    /// With no wrong ray, the rate below which the true one lies with 95%
    /// confidence ([`zero_rate_bound`]); `None` otherwise.
    pub zero_wrong_bound: Option<f64>,
    /// Mrays/s on the scene's rays, or over every scene for the catalogue.
    pub mrays_per_second: f64,
}

/// The measurement: every point, and the speeds they stand on.
#[derive(Clone, Debug, Serialize)]
pub struct Robustness {
    pub resolution: u32,
    pub points: Vec<RobustnessPoint>,
    /// `raycheck perf`'s rows, one per scene and backend.
    pub throughput: Vec<PerfRow>,
}

/// The one-sided 95% upper bound on a rate of which none of `rays` trials
/// happened: `1 − 0.05^(1/rays)` (Clopper–Pearson with no success; about
/// 3/rays, the "rule of three").
pub fn zero_rate_bound(rays: u64) -> f64 {
    1.0 - 0.05f64.powf(1.0 / rays.max(1) as f64)
}

/// Measures `scenes` (compare rays and speed) on `workers` and adds the
/// catalogue's `stability` results, for the default backends (ours, Embree
/// default, Embree ROBUST).
///
/// # Errors
/// A backend cannot be built.
pub fn measure_robustness(
    scenes: &[&Scene],
    stability: &[CaseResult],
    plan: &RobustnessPlan,
    workers: &Workers,
    progress: &dyn Fn(&str),
) -> anyhow::Result<Robustness> {
    let backends = BackendName::defaults();
    let pool = workers.pool();
    let mut points = Vec::new();
    let mut throughput = Vec::new();
    for scene in scenes {
        progress(&format!("{}: compare rays, judged", scene.name));
        let summary = compare_scene(scene, &backends, workers, plan.resolution)?;
        progress(&format!("{}: speed", scene.name));
        let rays = pool.install(|| RaySets::cached(scene, plan.resolution));
        let rows = measure(scene, &rays, workers, &backends, plan.runs)?;
        for row in &rows {
            let tally = summary.verdicts.backend(&row.backend);
            points.push(point(
                &row.backend,
                &scene.name,
                summary.verdicts.rays,
                tally.map_or(0, |t| t.wrong),
                mrays_per_second(&[row]),
            ));
        }
        throughput.extend(rows);
    }
    let mut catalogue = Verdicts::default();
    for case in stability {
        catalogue += &case.verdicts;
    }
    for name in backends.iter().map(|b| b.to_string()) {
        let Some(tally) = catalogue.backend(&name) else {
            continue;
        };
        let rows: Vec<&PerfRow> = throughput.iter().filter(|r| r.backend == name).collect();
        points.push(point(
            &name,
            CATALOGUE,
            catalogue.rays,
            tally.wrong,
            mrays_per_second(&rows),
        ));
    }
    Ok(Robustness {
        resolution: plan.resolution,
        points,
        throughput,
    })
}

fn point(backend: &str, rays_from: &str, rays: u64, wrong: u64, mrays: f64) -> RobustnessPoint {
    RobustnessPoint {
        backend: backend.to_string(),
        rays_from: rays_from.to_string(),
        rays,
        wrong,
        wrong_rate: wrong as f64 / rays.max(1) as f64,
        zero_wrong_bound: (wrong == 0).then(|| zero_rate_bound(rays)),
        mrays_per_second: mrays,
    }
}

/// Every ray of `rows` over the time they took (each set at its median
/// speed); NaN for no rows.
pub fn mrays_per_second(rows: &[&PerfRow]) -> f64 {
    let (rays, seconds) = rows
        .iter()
        .flat_map(|r| {
            [
                (r.primary_rays, r.mrays_primary.median),
                (r.shadow_rays, r.mrays_shadow.median),
                (r.diffuse_rays, r.mrays_diffuse.median),
            ]
        })
        .fold((0.0, 0.0), |(rays, seconds), (n, mrays)| {
            let n = n as f64 / 1e6;
            (rays + n, seconds + n / mrays)
        });
    if rays > 0.0 { rays / seconds } else { f64::NAN }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::perf::measure::Stat;

    #[test]
    fn the_zero_bound_is_the_rule_of_three() {
        // P(no event in n trials) = (1 − p)^n = 0.05 at the bound.
        for rays in [10u64, 1000, 1_000_000] {
            let p = zero_rate_bound(rays);
            assert!(((1.0 - p).powf(rays as f64) - 0.05).abs() < 1e-9);
            assert!((p * rays as f64 - 3.0).abs() < 0.5, "{rays}: {p}");
        }
    }

    #[test]
    fn throughput_over_sets_is_rays_over_total_time() {
        let row = |primary: usize, shadow: usize, rate: f64| PerfRow {
            scene: "s".into(),
            triangles: 1,
            threads: 1,
            backend: "ours".into(),
            primary_rays: primary,
            shadow_rays: shadow,
            diffuse_rays: 0,
            build_ms: Stat::of(vec![1.0]),
            builds_per_run: 1,
            mrays_primary: Stat::of(vec![rate]),
            mrays_shadow: Stat::of(vec![2.0 * rate]),
            mrays_diffuse: Stat::of(vec![rate]),
            peak_build_mib: None,
            bytes_per_tri: None,
        };
        // 1e6 rays at 1 Mrays/s and 2e6 at 2 Mrays/s: 3e6 rays in 2 s.
        let a = row(1_000_000, 2_000_000, 1.0);
        assert!((mrays_per_second(&[&a]) - 1.5).abs() < 1e-12);
        // Two scenes: 3e6 more rays in 1 s.
        let b = row(1_000_000, 2_000_000, 2.0);
        assert!((mrays_per_second(&[&a, &b]) - 2.0).abs() < 1e-12);
        assert!(mrays_per_second(&[]).is_nan());
    }
}
