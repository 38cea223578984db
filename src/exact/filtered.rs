//! The fast path of every exact decision: the value in f64 together with
//! the magnitude it was computed from, which bounds its rounding error.
//!
//! For a polynomial evaluated with `+`, `-` and `×` in `k` rounding steps
//! from exact inputs, the error is at most `γ_k · M`, where `M` is the same
//! polynomial evaluated on the absolute values (the "permanent" of Shewchuk
//! 1997, section 4.2; `γ_k = kε/(1-kε)`, pbrt-v4 section 6.8.1). The deepest
//! quantity the referee evaluates (a comparison of two hit distances) takes
//! fewer than 16 steps; [`ERROR_FACTOR`] allows twice that.

use std::cmp::Ordering;

/// Relative error bound on the magnitude: 32 units of f64 roundoff.
pub const ERROR_FACTOR: f64 = 32.0 * f64::EPSILON / 2.0;

/// A value computed in f64 and the magnitude bounding its error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Filtered {
    pub value: f64,
    pub magnitude: f64,
}

impl Filtered {
    pub fn exact(x: f64) -> Self {
        Self {
            value: x,
            magnitude: x.abs(),
        }
    }

    /// The bound on `|value - exact value|`.
    pub fn error_bound(&self) -> f64 {
        ERROR_FACTOR * self.magnitude
    }

    /// The sign of the exact value, when the rounding error cannot hide it.
    pub fn sign(&self) -> Option<Ordering> {
        let bound = self.error_bound();
        if self.value > bound {
            Some(Ordering::Greater)
        } else if self.value < -bound {
            Some(Ordering::Less)
        } else if self.magnitude == 0.0 {
            Some(Ordering::Equal)
        } else {
            None
        }
    }

    pub fn add(&self, o: &Self) -> Self {
        Self {
            value: self.value + o.value,
            magnitude: self.magnitude + o.magnitude,
        }
    }

    pub fn sub(&self, o: &Self) -> Self {
        Self {
            value: self.value - o.value,
            magnitude: self.magnitude + o.magnitude,
        }
    }

    pub fn mul(&self, o: &Self) -> Self {
        Self {
            value: self.value * o.value,
            magnitude: self.magnitude * o.magnitude,
        }
    }
}
