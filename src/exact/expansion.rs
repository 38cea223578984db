//! Exact arithmetic on floating-point expansions: a number is held as a sum
//! of f64 components that do not overlap, in increasing magnitude, so sums,
//! differences and products of f64 values are represented without error.
//!
//! Shewchuk, "Adaptive Precision Floating-Point Arithmetic and Fast Robust
//! Geometric Predicates", Discrete & Computational Geometry 18 (1997):
//! `two_sum` (Theorem 7), `fast_two_sum` (Theorem 6), `grow_expansion`
//! (Figure 6), `scale_expansion` (Figure 9) and `compress` (Figure 13), all
//! with zero elimination. `two_product` uses a fused multiply-add instead of
//! Dekker's splitting: `fma(a, b, -a·b)` is exactly the rounding error of
//! `a·b`. Exact as long as no intermediate underflows or overflows, which
//! holds for the degree-6 polynomials in f32 inputs the referee evaluates.

use smallvec::SmallVec;
use std::cmp::Ordering;

/// The components, held inline up to this many: most values the
/// referee's predicates meet are short, and the rest spill to the heap.
type Components = SmallVec<[f64; 8]>;

/// An exact value: the sum of `components`, nonoverlapping, smallest first,
/// with no zero component (so zero is the empty expansion).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Expansion {
    components: Components,
}

/// `a + b` as `(sum, error)`, exactly (Shewchuk, Theorem 7).
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let x = a + b;
    let b_virtual = x - a;
    let a_virtual = x - b_virtual;
    (x, (a - a_virtual) + (b - b_virtual))
}

/// `a + b` as `(sum, error)` when `|a| >= |b|` (Shewchuk, Theorem 6).
fn fast_two_sum(a: f64, b: f64) -> (f64, f64) {
    let x = a + b;
    (x, b - (x - a))
}

/// `a · b` as `(product, error)`, exactly.
fn two_product(a: f64, b: f64) -> (f64, f64) {
    let x = a * b;
    (x, a.mul_add(b, -x))
}

impl Expansion {
    pub fn zero() -> Self {
        Self::default()
    }

    pub fn from_f64(x: f64) -> Self {
        Self::from_parts(&[x])
    }

    fn from_parts(parts: &[f64]) -> Self {
        Self {
            components: parts.iter().copied().filter(|&c| c != 0.0).collect(),
        }
    }

    /// `a - b` for two f64 values, exactly.
    pub fn difference(a: f64, b: f64) -> Self {
        let (x, y) = two_sum(a, -b);
        Self::from_parts(&[y, x])
    }

    /// The sign of the exact value.
    pub fn sign(&self) -> Ordering {
        // The largest component dominates the sum of all the others.
        self.components
            .last()
            .map_or(Ordering::Equal, |c| c.total_cmp(&0.0))
    }

    /// The value rounded to f64 (within a few ulps: the components are
    /// summed smallest first).
    pub fn estimate(&self) -> f64 {
        self.components.iter().sum()
    }

    pub fn neg(&self) -> Self {
        Self {
            components: self.components.iter().map(|c| -c).collect(),
        }
    }

    /// This expansion plus the single value `b` (Shewchuk, Figure 6).
    fn grow(&self, b: f64) -> Self {
        let mut components = Components::with_capacity(self.components.len() + 1);
        let mut q = b;
        for &e in &self.components {
            let (sum, error) = two_sum(q, e);
            if error != 0.0 {
                components.push(error);
            }
            q = sum;
        }
        if q != 0.0 {
            components.push(q);
        }
        Self { components }
    }

    /// This expansion times the single value `b` (Shewchuk, Figure 9).
    fn scale(&self, b: f64) -> Self {
        let Some((&first, rest)) = self.components.split_first() else {
            return Self::zero();
        };
        let mut components = Components::with_capacity(2 * self.components.len());
        let (mut q, error) = two_product(first, b);
        components.push(error);
        for &e in rest {
            let (product, product_error) = two_product(e, b);
            let (sum, error) = two_sum(q, product_error);
            components.push(error);
            let (sum, error) = fast_two_sum(product, sum);
            components.push(error);
            q = sum;
        }
        components.push(q);
        Self::from_parts(&components)
    }

    pub fn add(&self, other: &Self) -> Self {
        other
            .components
            .iter()
            .fold(self.clone(), |sum, &c| sum.grow(c))
            .compress()
    }

    pub fn sub(&self, other: &Self) -> Self {
        self.add(&other.neg())
    }

    pub fn mul(&self, other: &Self) -> Self {
        other
            .components
            .iter()
            .fold(Self::zero(), |sum, &c| sum.add(&self.scale(c)))
    }

    /// The same value in as few components as possible (Shewchuk,
    /// Figure 13), so products of sums stay short.
    fn compress(self) -> Self {
        let e = self.components;
        let Some(&largest) = e.last() else {
            return Self::zero();
        };
        // Top-down pass: collect the large parts of pairwise sums.
        let mut g = Components::with_capacity(e.len());
        let mut q = largest;
        for &c in e.iter().rev().skip(1) {
            let (sum, small) = fast_two_sum(q, c);
            if small != 0.0 {
                g.push(sum);
                q = small;
            } else {
                q = sum;
            }
        }
        g.push(q);
        // `g` is largest first; the bottom-up pass sums from its small end.
        let mut h = Components::with_capacity(g.len());
        let mut q = g.pop().unwrap_or(0.0);
        while let Some(c) = g.pop() {
            let (sum, small) = fast_two_sum(c, q);
            if small != 0.0 {
                h.push(small);
            }
            q = sum;
        }
        h.push(q);
        Self::from_parts(&h)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::Rng;

    fn exact(x: f64) -> Expansion {
        Expansion::from_f64(x)
    }

    #[test]
    fn sums_keep_what_f64_loses() {
        let big = exact(2f64.powi(60));
        let one = exact(1.0);
        // (2^60 + 1) - 2^60 is 0 in f64, exactly 1 here.
        let sum = big.add(&one).sub(&big);
        assert_eq!(sum.estimate(), 1.0);
        assert_eq!(sum.sign(), Ordering::Greater);
        assert_eq!(big.sub(&big).sign(), Ordering::Equal);
        assert_eq!(
            Expansion::difference(1e30, 1e-30).neg().sign(),
            Ordering::Less
        );
    }

    #[test]
    fn products_keep_every_bit() {
        // (1 + 2^-30)^2 = 1 + 2^-29 + 2^-60: the last term is below f64 precision.
        let x = exact(1.0 + 2f64.powi(-30));
        let square = x.mul(&x);
        let rest = square.sub(&exact(1.0 + 2f64.powi(-29)));
        assert_eq!(rest.estimate(), 2f64.powi(-60));
    }

    #[test]
    fn agrees_with_integer_arithmetic() {
        // Integers below 2^31: products of three exceed f64's 53 bits but
        // fit in i128, which gives the exact answer to compare with.
        let mut rng = Rng::new(7);
        for _ in 0..20_000 {
            let v: [i64; 6] = std::array::from_fn(|_| (rng.next_u64() >> 33) as i64 - (1 << 30));
            let exact_value = v[0] as i128 * v[1] as i128 * v[2] as i128
                - v[3] as i128 * v[4] as i128 * v[5] as i128;
            let e = v.map(|x| exact(x as f64));
            let value = e[0].mul(&e[1]).mul(&e[2]).sub(&e[3].mul(&e[4]).mul(&e[5]));
            assert_eq!(value.sign(), exact_value.cmp(&0), "{v:?}");
            assert_eq!(value.estimate(), exact_value as f64, "{v:?}");
        }
    }

    #[test]
    fn exact_cancellation_of_near_equal_products() {
        // a·b and c·d equal in f64 but not exactly.
        let (a, b) = (3.0 * 2f64.powi(26) + 1.0, 3.0 * 2f64.powi(26) - 1.0);
        let c = 3.0 * 2f64.powi(26);
        assert_eq!(a * b, c * c - 1.0);
        let exact_difference = exact(a).mul(&exact(b)).sub(&exact(c).mul(&exact(c)));
        assert_eq!(exact_difference.estimate(), -1.0);
    }
}
