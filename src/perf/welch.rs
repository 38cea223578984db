//! Welch's unequal-variances t-test (Welch 1947, "The generalization of
//! 'Student's' problem when several different population variances are
//! involved", Biometrika 34) on the logarithms of two samples of a speed:
//! the difference of the mean logs is the log of the ratio of geometric
//! means, its standard error takes each sample's own variance, and its
//! degrees of freedom come from the Welch–Satterthwaite equation. Logs
//! make a ratio's interval symmetric and a slow outlier weigh as a fast
//! one of the same factor.

use statrs::distribution::{ContinuousCDF, StudentsT};

/// The test of `new` against `old`, on log scale.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Welch {
    /// Mean of the new logs minus mean of the old: the log of the ratio
    /// of the geometric means.
    pub difference: f64,
    pub standard_error: f64,
    pub degrees_of_freedom: f64,
}

impl Welch {
    /// The test of two samples of positive values, or `None` when either
    /// has fewer than two values (no variance to judge by) or a value
    /// that is not positive and finite.
    pub fn of(old: &[f64], new: &[f64]) -> Option<Self> {
        let (old, new) = (LogSample::of(old)?, LogSample::of(new)?);
        let (old_share, new_share) = (old.mean_variance(), new.mean_variance());
        let variance = old_share + new_share;
        Some(Self {
            difference: new.mean - old.mean,
            standard_error: variance.sqrt(),
            degrees_of_freedom: variance * variance
                / (old_share * old_share / (old.count - 1.0)
                    + new_share * new_share / (new.count - 1.0)),
        })
    }

    /// The two-sided p-value of no change. Two samples without spread
    /// give 1 when they are equal and 0 when they are not.
    pub fn p_value(&self) -> f64 {
        if self.standard_error == 0.0 {
            return if self.difference == 0.0 { 1.0 } else { 0.0 };
        }
        let t = (self.difference / self.standard_error).abs();
        (2.0 * self.student().sf(t)).min(1.0)
    }

    /// The `confidence` interval of `difference`.
    pub fn interval(&self, confidence: f64) -> (f64, f64) {
        if self.standard_error == 0.0 {
            return (self.difference, self.difference);
        }
        let quantile = self.student().inverse_cdf(0.5 + confidence / 2.0);
        let half_width = quantile * self.standard_error;
        (self.difference - half_width, self.difference + half_width)
    }

    fn student(&self) -> StudentsT {
        StudentsT::new(0.0, 1.0, self.degrees_of_freedom)
            .expect("a positive standard error gives positive degrees of freedom")
    }
}

/// A sample's logs: their count, mean and unbiased variance.
struct LogSample {
    count: f64,
    mean: f64,
    variance: f64,
}

impl LogSample {
    fn of(values: &[f64]) -> Option<Self> {
        if values.len() < 2 || values.iter().any(|v| !(v.is_finite() && *v > 0.0)) {
            return None;
        }
        let count = values.len() as f64;
        let logs: Vec<f64> = values.iter().map(|v| v.ln()).collect();
        let mean = logs.iter().sum::<f64>() / count;
        let variance = logs.iter().map(|l| (l - mean).powi(2)).sum::<f64>() / (count - 1.0);
        Some(Self {
            count,
            mean,
            variance,
        })
    }

    /// The variance of the mean.
    fn mean_variance(&self) -> f64 {
        self.variance / self.count
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Welch's statistic and degrees of freedom worked by hand, and the
    /// p-value against Student's t table (Fisher & Yates): with 4 degrees
    /// of freedom, |t| = 2.776 has a two-sided p of 0.05.
    #[test]
    fn matches_the_formula_and_the_t_table() {
        let old = [1.0f64, 2.0, 4.0].map(f64::exp);
        let new = [2.0f64, 3.0, 5.0].map(f64::exp);
        let welch = Welch::of(&old, &new).unwrap();
        // Both variances are 7/3, so the standard error is sqrt(14/9) and
        // the degrees of freedom are 2(3 - 1) = 4.
        assert!((welch.difference - 1.0).abs() < 1e-12, "{welch:?}");
        assert!((welch.standard_error - (14.0f64 / 9.0).sqrt()).abs() < 1e-12);
        assert!((welch.degrees_of_freedom - 4.0).abs() < 1e-12);
        let at = |t: f64| Welch {
            difference: t,
            standard_error: 1.0,
            degrees_of_freedom: 4.0,
        };
        assert!((at(2.776).p_value() - 0.05).abs() < 1e-4);
        assert!((at(-2.776).p_value() - 0.05).abs() < 1e-4);
        let (low, high) = at(0.0).interval(0.95);
        assert!((high - 2.776).abs() < 1e-3 && (low + high).abs() < 1e-12);
    }

    #[test]
    fn samples_without_spread_are_equal_or_apart() {
        let same = Welch::of(&[2.0, 2.0], &[2.0, 2.0]).unwrap();
        assert_eq!(same.p_value(), 1.0);
        assert_eq!(same.interval(0.95), (0.0, 0.0));
        let apart = Welch::of(&[2.0, 2.0], &[3.0, 3.0]).unwrap();
        assert_eq!(apart.p_value(), 0.0);
    }

    #[test]
    fn a_sample_it_cannot_judge_gives_no_test() {
        assert_eq!(Welch::of(&[1.0], &[1.0, 2.0]), None);
        assert_eq!(Welch::of(&[1.0, 0.0], &[1.0, 2.0]), None);
        assert_eq!(Welch::of(&[1.0, 2.0], &[f64::NAN, 2.0]), None);
    }
}
