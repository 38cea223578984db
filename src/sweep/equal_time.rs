//! What stratification buys, read off two measured error curves: the
//! error each sampler reaches in the same time, and the time each needs
//! for the same error.
//!
//! A curve is the mean (time, error) of each sample count, in count order.
//! Between measured points both are interpolated linearly on log-log axes
//! (where a power law is a straight line). Beyond the largest count, the
//! curve's power law fitted against time (over its largest counts, where
//! it holds) extrapolates, and the result says so; before the smallest
//! count nothing is read, since there a render's fixed cost, not its
//! samples, sets the time.

use crate::fit::LogLogFit;
use serde::Serialize;

/// One sampler's measured curve.
#[derive(Clone, Copy, Debug)]
pub struct Curve<'a> {
    /// (samples, mean seconds, mean error) per count, in count order.
    pub points: &'a [(u32, f64, f64)],
    /// The error against seconds, fitted over every seed.
    pub fit: &'a LogLogFit,
}

/// A value read off a curve.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Reading {
    pub value: f64,
    /// Outside the measured points: from the fitted power law.
    pub extrapolated: bool,
}

/// The error of both samplers at the time of one stratified count.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EqualTime {
    pub seconds: f64,
    pub stratified_samples: u32,
    pub stratified_rel_mse: f64,
    pub independent_rel_mse: Reading,
    /// Independent over stratified error: how many times lower the
    /// stratified error is in the same time.
    pub error_ratio: f64,
}

/// The time both samplers need for the error of one independent count.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EqualError {
    pub rel_mse: f64,
    pub independent_samples: u32,
    pub independent_seconds: f64,
    pub stratified_seconds: Reading,
    /// Independent over stratified time.
    pub speedup: f64,
}

/// For each stratified count above 1, the independent error in the same
/// time, where the independent curve reaches that time. (One sample
/// stratifies nothing: both samplers render the same image, and the row
/// would only compare two timings of it.)
pub fn equal_time(stratified: Curve, independent: Curve) -> Vec<EqualTime> {
    stratified
        .points
        .iter()
        .filter(|p| p.0 > 1)
        .filter_map(|&(samples, seconds, error)| {
            let other = error_at(independent, seconds)?;
            Some(EqualTime {
                seconds,
                stratified_samples: samples,
                stratified_rel_mse: error,
                independent_rel_mse: other,
                error_ratio: other.value / error,
            })
        })
        .collect()
}

/// For each independent count above 1, the stratified time to the same
/// error, where the stratified curve reaches that error.
pub fn equal_error(stratified: Curve, independent: Curve) -> Vec<EqualError> {
    independent
        .points
        .iter()
        .filter(|p| p.0 > 1)
        .filter_map(|&(samples, seconds, error)| {
            let other = time_to(stratified, error)?;
            Some(EqualError {
                rel_mse: error,
                independent_samples: samples,
                independent_seconds: seconds,
                stratified_seconds: other,
                speedup: seconds / other.value,
            })
        })
        .collect()
}

/// `y` at `x` on the first segment of `points` (as (x, y)) that spans it,
/// interpolated on log-log axes.
fn interpolate(points: &[(f64, f64)], x: f64) -> Option<f64> {
    points.windows(2).find_map(|w| {
        let [(x0, y0), (x1, y1)] = [w[0], w[1]];
        let spans = (x0.min(x1)..=x0.max(x1)).contains(&x);
        spans.then(|| {
            if x0 == x1 {
                return y0;
            }
            let s = (x / x0).ln() / (x1 / x0).ln();
            (y0.ln() + s * (y1 / y0).ln()).exp()
        })
    })
}

/// The curve's error after `seconds`; `None` before its first point.
pub fn error_at(curve: Curve, seconds: f64) -> Option<Reading> {
    let points: Vec<(f64, f64)> = curve.points.iter().map(|p| (p.1, p.2)).collect();
    let interpolated = interpolate(&points, seconds).map(|value| Reading {
        value,
        extrapolated: false,
    });
    let longest = points.iter().map(|p| p.0).fold(f64::NEG_INFINITY, f64::max);
    interpolated.or_else(|| {
        (seconds > longest).then(|| Reading {
            value: (curve.fit.intercept + curve.fit.slope * seconds.ln()).exp(),
            extrapolated: true,
        })
    })
}

/// The curve's time to reach `error`; `None` above its first point.
pub fn time_to(curve: Curve, error: f64) -> Option<Reading> {
    let points: Vec<(f64, f64)> = curve.points.iter().map(|p| (p.2, p.1)).collect();
    let interpolated = interpolate(&points, error).map(|value| Reading {
        value,
        extrapolated: false,
    });
    let smallest = points.iter().map(|p| p.0).fold(f64::INFINITY, f64::min);
    interpolated.or_else(|| {
        (error < smallest).then(|| Reading {
            value: ((error.ln() - curve.fit.intercept) / curve.fit.slope).exp(),
            extrapolated: true,
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::fit_log_log;

    const COUNTS: [u32; 5] = [1, 4, 16, 64, 256];

    /// Points and fit of error = scale·seconds^slope with seconds = n·time.
    fn curve(time_per_sample: f64, scale: f64, slope: f64) -> (Vec<(u32, f64, f64)>, LogLogFit) {
        let points: Vec<(u32, f64, f64)> = COUNTS
            .iter()
            .map(|&n| {
                let t = n as f64 * time_per_sample;
                (n, t, scale * t.powf(slope))
            })
            .collect();
        let fit =
            fit_log_log(&points.iter().map(|p| (p.1, p.2)).collect::<Vec<_>>(), 0.95).unwrap();
        (points, fit)
    }

    #[test]
    fn equal_time_and_equal_error_on_known_power_laws() {
        // Stratified: error 1/t² at t = n; independent: error 2/t at t = 2n
        // (half as fast per sample, same error per sample as 1/n).
        let (s_points, s_fit) = curve(1.0, 1.0, -2.0);
        let (i_points, i_fit) = curve(2.0, 2.0, -1.0);
        let s = Curve {
            points: &s_points,
            fit: &s_fit,
        };
        let i = Curve {
            points: &i_points,
            fit: &i_fit,
        };
        let rows = equal_time(s, i);
        // No row for one sample; at t = 4 (4 stratified samples) the
        // independent curve, which starts at t = 2, is interpolated.
        assert_eq!(rows[0].stratified_samples, 4);
        // At t = 16 (16 stratified samples): 1/256 against 2/16.
        let row = &rows[1];
        assert_eq!((row.stratified_samples, row.seconds), (16, 16.0));
        assert!((row.independent_rel_mse.value - 0.125).abs() < 1e-12);
        assert!(!row.independent_rel_mse.extrapolated);
        assert!((row.error_ratio - 32.0).abs() < 1e-9, "{row:?}");

        // Stratified twice as slow per sample: at its t = 512 (256
        // samples) the independent curve (up to t = 512) is interpolated;
        // past it, 4.0 × 256 = 1024 s, the fit extrapolates, exactly since
        // the law is exact: 2/1024.
        let (slow_points, slow_fit) = curve(4.0, 16.0, -2.0);
        let slow = Curve {
            points: &slow_points,
            fit: &slow_fit,
        };
        let last = equal_time(slow, i).pop().unwrap();
        assert!(last.independent_rel_mse.extrapolated);
        assert!((last.independent_rel_mse.value - 2.0 / 1024.0).abs() < 1e-12);

        let rows = equal_error(s, i);
        // Independent 64 samples: t = 128, error 1/64; stratified reaches
        // 1/64 at t = 8, sixteen times sooner.
        let row = &rows[2];
        assert_eq!(row.independent_samples, 64);
        assert!((row.stratified_seconds.value - 8.0).abs() < 1e-9, "{row:?}");
        assert!((row.speedup - 16.0).abs() < 1e-9);
        // Independent 4 samples: t = 8, error 1/4, which stratified has at
        // t = 2, between its first two points: interpolated.
        assert_eq!(rows[0].independent_samples, 4);
        assert!(!rows[0].stratified_seconds.extrapolated);
        assert!((rows[0].speedup - 4.0).abs() < 1e-9);
    }

    #[test]
    fn interpolation_is_log_log_and_takes_the_first_spanning_segment() {
        let points = [(1.0, 1.0), (100.0, 0.01), (1000.0, 0.5)];
        // Halfway in log x between 1 and 100: halfway in log y, 0.1.
        assert!((interpolate(&points, 10.0).unwrap() - 0.1).abs() < 1e-12);
        assert_eq!(interpolate(&points, 0.5), None);
        assert!((interpolate(&points, 1000.0).unwrap() - 0.5).abs() < 1e-12);
    }
}
