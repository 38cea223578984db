//! How build time and time per ray grow with the triangle count: the
//! exponent `k` of `y ≈ c·n^k`, fitted by least squares on `log y` against
//! `log n`. Build time growing as `n log n` shows as `k` a little above 1
//! over these sizes, time per ray growing as `log n` as `k` well below 1.

use super::measure::PerfRow;
use serde::{Deserialize, Serialize};

/// One scene's point of a scaling table.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ScalingPoint {
    pub scene: String,
    pub triangles: usize,
    /// Median build time.
    pub build_ms: f64,
    /// Nanoseconds per primary ray on the row's threads (from the median
    /// throughput).
    pub ns_per_ray: f64,
    pub bytes_per_tri: Option<f64>,
    pub peak_build_mib: Option<f64>,
}

/// How one backend's build time and time per ray grow on one thread
/// count, with the fitted exponents.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Scaling {
    pub threads: usize,
    pub backend: String,
    pub points: Vec<ScalingPoint>,
    /// `None` where fewer than two scenes of different sizes were run.
    pub build_exponent: Option<f64>,
    pub ns_per_ray_exponent: Option<f64>,
}

impl Scaling {
    /// The table over `rows` (one per scene, same threads and backend),
    /// sorted by triangle count.
    pub fn from_rows(rows: &[&PerfRow]) -> Option<Scaling> {
        let first = rows.first()?;
        let mut points: Vec<ScalingPoint> = rows
            .iter()
            .map(|r| ScalingPoint {
                scene: r.scene.clone(),
                triangles: r.triangles,
                build_ms: r.build_ms.median,
                ns_per_ray: 1e3 / r.mrays_primary.median,
                bytes_per_tri: r.bytes_per_tri,
                peak_build_mib: r.peak_build_mib,
            })
            .collect();
        points.sort_by_key(|p| p.triangles);
        let fit = |y: fn(&ScalingPoint) -> f64| {
            let samples: Vec<(f64, f64)> =
                points.iter().map(|p| (p.triangles as f64, y(p))).collect();
            power_law_exponent(&samples)
        };
        Some(Scaling {
            threads: first.threads,
            backend: first.backend.clone(),
            build_exponent: fit(|p| p.build_ms),
            ns_per_ray_exponent: fit(|p| p.ns_per_ray),
            points,
        })
    }
}

/// The slope of the least-squares line through `(ln x, ln y)`; `None`
/// with fewer than two distinct `x` or any non-positive value.
pub fn power_law_exponent(samples: &[(f64, f64)]) -> Option<f64> {
    crate::fit::log_log_line(samples).map(|line| line.slope)
}

/// An exponent as a table shows it: two decimals, or a dash where there
/// was nothing to fit.
pub fn exponent_text(exponent: Option<f64>) -> String {
    exponent.map_or_else(|| "– (one size)".into(), |k| format!("{k:.2}"))
}

#[cfg(test)]
mod tests {
    use super::{exponent_text, power_law_exponent};

    #[test]
    fn exponents_of_known_power_laws() {
        let xs = [32.0, 3936.0, 11_102.0, 47_794.0, 202_520.0, 871_414.0];
        for k in [0.0, 0.5, 1.0, 1.7] {
            let samples: Vec<(f64, f64)> = xs.iter().map(|&x: &f64| (x, 3.0 * x.powf(k))).collect();
            let fitted = power_law_exponent(&samples).unwrap();
            assert!((fitted - k).abs() < 1e-9, "{k}");
        }
        // n log n over these sizes fits an exponent a little above 1.
        let nlogn: Vec<(f64, f64)> = xs.iter().map(|&x: &f64| (x, x * x.ln())).collect();
        let k = power_law_exponent(&nlogn).unwrap();
        assert!(k > 1.0 && k < 1.25, "{k}");
        assert_eq!(power_law_exponent(&[(1.0, 1.0)]), None);
        assert_eq!(power_law_exponent(&[(1.0, 1.0), (2.0, 0.0)]), None);
        assert_eq!(exponent_text(None), "– (one size)");
        assert_eq!(exponent_text(Some(1.234)), "1.23");
    }
}
