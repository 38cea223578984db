//! The arithmetic the predicates are written in, once, for both the
//! filtered f64 fast path and the exact expansion fallback.

use super::expansion::Expansion;
use super::filtered::Filtered;

pub trait Number: Clone {
    fn exact(x: f64) -> Self;
    /// `a - b` of two f64 inputs (exact for expansions).
    fn difference(a: f64, b: f64) -> Self;
    fn add(&self, o: &Self) -> Self;
    fn sub(&self, o: &Self) -> Self;
    fn mul(&self, o: &Self) -> Self;
}

impl Number for Filtered {
    fn exact(x: f64) -> Self {
        Filtered::exact(x)
    }

    fn difference(a: f64, b: f64) -> Self {
        Filtered::exact(a).sub(&Filtered::exact(b))
    }

    fn add(&self, o: &Self) -> Self {
        Filtered::add(self, o)
    }

    fn sub(&self, o: &Self) -> Self {
        Filtered::sub(self, o)
    }

    fn mul(&self, o: &Self) -> Self {
        Filtered::mul(self, o)
    }
}

impl Number for Expansion {
    fn exact(x: f64) -> Self {
        Expansion::from_f64(x)
    }

    fn difference(a: f64, b: f64) -> Self {
        Expansion::difference(a, b)
    }

    fn add(&self, o: &Self) -> Self {
        Expansion::add(self, o)
    }

    fn sub(&self, o: &Self) -> Self {
        Expansion::sub(self, o)
    }

    fn mul(&self, o: &Self) -> Self {
        Expansion::mul(self, o)
    }
}

/// A vector of three numbers.
pub type Vector<T> = [T; 3];

pub fn cross<T: Number>(a: &Vector<T>, b: &Vector<T>) -> Vector<T> {
    [
        a[1].mul(&b[2]).sub(&a[2].mul(&b[1])),
        a[2].mul(&b[0]).sub(&a[0].mul(&b[2])),
        a[0].mul(&b[1]).sub(&a[1].mul(&b[0])),
    ]
}

/// `p - origin` for f32 points, exactly for expansions.
pub fn translated<T: Number>(p: &[f32; 3], origin: &[f32; 3]) -> Vector<T> {
    std::array::from_fn(|k| T::difference(f64::from(p[k]), f64::from(origin[k])))
}

pub fn dot<T: Number>(a: &Vector<T>, b: &Vector<T>) -> T {
    a[0].mul(&b[0]).add(&a[1].mul(&b[1])).add(&a[2].mul(&b[2]))
}
