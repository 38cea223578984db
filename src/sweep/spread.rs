//! A quantity measured over several seeds: its mean, how much one seed
//! varies (the sample standard deviation, with n − 1), and how well the
//! mean is known (its standard error and a Student-t interval).

use crate::fit::student_t_critical;
use anyhow::ensure;

/// The mean and spread of values measured over seeds.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Spread {
    pub mean: f64,
    /// The sample standard deviation (divided by n − 1).
    pub std_dev: f64,
    /// The standard error of the mean, `std_dev / √n`.
    pub std_error: f64,
    pub min: f64,
    pub max: f64,
    pub count: usize,
}

impl Spread {
    /// # Errors
    /// Fewer than two values (one seed has no spread), or one not finite.
    pub fn of(values: &[f64]) -> anyhow::Result<Self> {
        ensure!(
            values.len() >= 2,
            "a spread needs at least 2 values, got {}",
            values.len()
        );
        ensure!(
            values.iter().all(|v| v.is_finite()),
            "values must be finite: {values:?}"
        );
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n;
        let variance = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
        let std_dev = variance.sqrt();
        Ok(Self {
            mean,
            std_dev,
            std_error: std_dev / n.sqrt(),
            min: values.iter().copied().fold(f64::INFINITY, f64::min),
            max: values.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            count: values.len(),
        })
    }

    /// The interval that holds the true mean with probability `confidence`
    /// (Student's t with n − 1 degrees of freedom).
    pub fn mean_interval(&self, confidence: f64) -> (f64, f64) {
        let half = student_t_critical(confidence, self.count as f64 - 1.0) * self.std_error;
        (self.mean - half, self.mean + half)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mean_and_spread_of_known_values() {
        let s = Spread::of(&[1.0, 2.0, 3.0, 4.0]).unwrap();
        assert_eq!(s.mean, 2.5);
        // Σ(v − 2.5)² = 5, over n − 1 = 3.
        assert!((s.std_dev - (5.0f64 / 3.0).sqrt()).abs() < 1e-12);
        assert!((s.std_error - (5.0f64 / 12.0).sqrt()).abs() < 1e-12);
        assert_eq!((s.min, s.max, s.count), (1.0, 4.0, 4));
        // t(0.975, 3) = 3.182 from the tables.
        let (low, high) = s.mean_interval(0.95);
        assert!((high - 2.5 - 3.182 * s.std_error).abs() < 1e-3, "{high}");
        assert!((2.5 - low - (high - 2.5)).abs() < 1e-12);
        let same = Spread::of(&[0.5; 8]).unwrap();
        assert_eq!((same.mean, same.std_dev), (0.5, 0.0));
        assert!(Spread::of(&[1.0]).is_err());
        assert!(Spread::of(&[1.0, f64::NAN]).is_err());
    }
}
