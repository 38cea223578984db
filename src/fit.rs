//! Power laws fitted on log-log axes: error ≈ c·samples^slope (or time), or
//! build time ≈ c·triangles^k, is a straight line through (ln x, ln y),
//! fitted by ordinary least squares;
//! the slope's confidence interval comes from its standard error and
//! Student's t with n − 2 degrees of freedom (any regression text, e.g.
//! Montgomery, Peck, Vining, "Introduction to Linear Regression Analysis",
//! ch. 2).

use anyhow::{Context, ensure};
use statrs::distribution::{ContinuousCDF, StudentsT};

/// `y ≈ exp(intercept)·x^slope`, with a confidence interval on the slope.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct LogLogFit {
    pub slope: f64,
    pub intercept: f64,
    /// The slope's interval at `confidence`.
    pub slope_low: f64,
    pub slope_high: f64,
    /// The slope's standard error.
    pub slope_error: f64,
    pub confidence: f64,
    pub points: usize,
}

/// Fits a line to `(ln x, ln y)` for every point (several seeds per x may
/// all be given), with the slope's interval at `confidence` (e.g. 0.95).
///
/// # Errors
/// Fewer than three points (the interval needs a residual degree of
/// freedom), a value that is not finite and positive, every x the same, or
/// a confidence outside (0, 1).
pub fn fit_log_log(points: &[(f64, f64)], confidence: f64) -> anyhow::Result<LogLogFit> {
    ensure!(
        points.len() >= 3,
        "a slope with an interval needs at least 3 points, got {}",
        points.len()
    );
    ensure!(
        confidence > 0.0 && confidence < 1.0,
        "confidence {confidence} is not between 0 and 1"
    );
    if let Some((x, y)) = points.iter().find(|&&point| !has_logarithm(point)) {
        anyhow::bail!("point ({x}, {y}) has no logarithm: both must be finite and positive");
    }
    let line = log_log_line(points).context("every point has the same x: no slope")?;
    let (slope, intercept) = (line.slope, line.intercept);
    let n = points.len() as f64;
    let slope_error = (line.residuals / (n - 2.0) / line.sxx).sqrt();
    let half_width = student_t_critical(confidence, n - 2.0) * slope_error;
    Ok(LogLogFit {
        slope,
        intercept,
        slope_low: slope - half_width,
        slope_high: slope + half_width,
        slope_error,
        confidence,
        points: points.len(),
    })
}

/// The least-squares line through `(ln x, ln y)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Line {
    pub slope: f64,
    pub intercept: f64,
    /// The spread of the `ln x`: Σ (ln x - mean)².
    pub sxx: f64,
    /// The sum of the squared residuals in `ln y`.
    pub residuals: f64,
}

fn has_logarithm((x, y): (f64, f64)) -> bool {
    x.is_finite() && x > 0.0 && y.is_finite() && y > 0.0
}

/// The least-squares line through `(ln x, ln y)` of every point; `None`
/// with fewer than two distinct `x` or a value that is not finite and
/// positive.
pub fn log_log_line(points: &[(f64, f64)]) -> Option<Line> {
    if !points.iter().all(|&point| has_logarithm(point)) {
        return None;
    }
    let logs: Vec<(f64, f64)> = points.iter().map(|(x, y)| (x.ln(), y.ln())).collect();
    let n = logs.len() as f64;
    let mean_x = logs.iter().map(|p| p.0).sum::<f64>() / n;
    let mean_y = logs.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = logs.iter().map(|(x, _)| (x - mean_x).powi(2)).sum();
    let sxy: f64 = logs.iter().map(|(x, y)| (x - mean_x) * (y - mean_y)).sum();
    if sxx <= 0.0 {
        return None;
    }
    let slope = sxy / sxx;
    let intercept = mean_y - slope * mean_x;
    let residuals = logs
        .iter()
        .map(|(x, y)| (y - intercept - slope * x).powi(2))
        .sum();
    Some(Line {
        slope,
        intercept,
        sxx,
        residuals,
    })
}

/// The two-sided critical value t with P(|T| ≤ t) = `confidence` for
/// Student's t with `freedom` degrees of freedom.
///
/// # Panics
/// If `freedom` is not positive.
pub fn student_t_critical(confidence: f64, freedom: f64) -> f64 {
    let t = StudentsT::new(0.0, 1.0, freedom).expect("positive degrees of freedom");
    t.inverse_cdf(0.5 + 0.5 * confidence)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::Rng;

    #[test]
    fn an_exact_power_law_gives_its_slope_with_no_width() {
        let points: Vec<(f64, f64)> = [1.0, 4.0, 16.0, 64.0, 256.0]
            .iter()
            .map(|&n: &f64| (n, 3.0 / n))
            .collect();
        let fit = fit_log_log(&points, 0.95).unwrap();
        assert!((fit.slope + 1.0).abs() < 1e-12, "{fit:?}");
        assert!((fit.intercept - 3.0f64.ln()).abs() < 1e-12, "{fit:?}");
        assert!(fit.slope_high - fit.slope_low < 1e-9, "{fit:?}");
    }

    /// Points off any one line, worked by hand in log space: x = 0, 1, 2,
    /// 3 and y = 0, 1, 1, 3 give mean x 1.5, mean y 1.25, Sxx 5, Sxy 4.5,
    /// so slope 0.9 and intercept -0.1; the residuals 0.1, 0.2, -0.7, 0.4
    /// square to 0.7, so the slope's standard error is √(0.7 / 2 / 5). Any
    /// subset of the points gives another line.
    #[test]
    fn a_least_squares_fit_uses_every_point() {
        let points: Vec<(f64, f64)> = [(0.0, 0.0), (1.0, 1.0), (2.0, 1.0), (3.0, 3.0)]
            .iter()
            .map(|&(x, y): &(f64, f64)| (x.exp(), y.exp()))
            .collect();
        let fit = fit_log_log(&points, 0.95).unwrap();
        assert!((fit.slope - 0.9).abs() < 1e-12, "{fit:?}");
        assert!((fit.intercept + 0.1).abs() < 1e-12, "{fit:?}");
        assert!((fit.slope_error - 0.07f64.sqrt()).abs() < 1e-12, "{fit:?}");
        assert_eq!(fit.points, 4);
        let line = log_log_line(&points).unwrap();
        assert!((line.residuals - 0.7).abs() < 1e-12, "{line:?}");
    }

    #[test]
    fn critical_values_match_the_tables() {
        // Student's t tables, 95% two-sided: 12.706 (1), 3.182 (3), 2.228 (10).
        for (freedom, table) in [(1.0, 12.706), (3.0, 3.182), (10.0, 2.228)] {
            let t = student_t_critical(0.95, freedom);
            assert!((t - table).abs() < 1e-3, "{freedom}: {t}");
        }
    }

    #[test]
    fn the_interval_covers_the_true_slope_as_often_as_it_claims() {
        // Five points with log-normal noise, as a sweep's few counts give:
        // with Student's t the 95% intervals cover -1 in 95% of the fits
        // (the normal's 1.96 would cover only about 88%). Over 2000 fits the
        // coverage has a standard deviation of 0.5%, so 93.5–96.5% is 3σ.
        let mut rng = Rng::new(11);
        let trials = 2000;
        let covered = (0..trials)
            .filter(|_| {
                let points: Vec<(f64, f64)> = [1.0, 4.0, 16.0, 64.0, 256.0]
                    .iter()
                    .map(|&n| {
                        // A standard normal from two uniforms (Box–Muller).
                        let (u, v) = (1.0 - rng.unit(), rng.unit());
                        let normal = (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos();
                        (n, 0.5 / n * (0.3 * normal).exp())
                    })
                    .collect();
                let fit = fit_log_log(&points, 0.95).unwrap();
                fit.slope_low <= -1.0 && -1.0 <= fit.slope_high
            })
            .count();
        let coverage = covered as f64 / trials as f64;
        assert!((0.935..=0.965).contains(&coverage), "coverage {coverage}");
    }

    #[test]
    fn bad_points_are_errors() {
        let two = fit_log_log(&[(1.0, 1.0), (2.0, 0.5)], 0.95).unwrap_err();
        assert_eq!(
            two.to_string(),
            "a slope with an interval needs at least 3 points, got 2"
        );
        let zero = fit_log_log(&[(1.0, 1.0), (2.0, 0.0), (4.0, 0.1)], 0.95).unwrap_err();
        assert!(
            zero.to_string()
                .starts_with("point (2, 0) has no logarithm")
        );
        let flat = fit_log_log(&[(2.0, 1.0), (2.0, 0.5), (2.0, 0.1)], 0.95).unwrap_err();
        assert_eq!(flat.to_string(), "every point has the same x: no slope");
        assert!(fit_log_log(&[(1.0, 1.0), (2.0, 0.5), (4.0, 0.2)], 1.0).is_err());
    }
}
