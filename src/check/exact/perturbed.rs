//! Inputs one f32 ulp away, and signs that hold for all of them.
//!
//! The referee asks whether an answer is right for any ray or mesh that
//! differs from the given one by one ulp in one input. [`Perturbed`]
//! evaluates a polynomial once, in f64, with two bounds: the rounding
//! error of the value (the filter of [`Filtered`], Shewchuk 1997 section
//! 4.2) and how far the exact value can move when every input moves by up
//! to one ulp at once (first-order propagation of input radii, as in
//! interval arithmetic: Moore 1966, ch. 3). A sign that clears both bounds
//! is the sign for the inputs as given and for every one-ulp change of
//! them, so a decision built only from such signs need not be made again
//! for each change.

use crate::bvh::MAX_COORDINATE;
use crate::exact::filtered::Filtered;
use crate::exact::number::Number;
use std::cmp::Ordering;

/// Slack on the propagated radius for its own rounding (a few dozen f64
/// roundings, relative): far above them, far below any f32 step.
const RADIUS_SLACK: f64 = 1.0 + 1e-12;

/// The next f32 up or down, in flush-to-zero arithmetic: the backends run
/// with denormals flushed, so one ulp from zero is the smallest normal
/// float. Decided on the bits alone, so that it is the same step on a
/// thread that itself treats denormals as zero (where a denormal compares
/// equal to zero).
pub fn ulp_step(x: f32, up: bool) -> f32 {
    let next = if up { x.next_up() } else { x.next_down() };
    let magnitude = |v: f32| v.to_bits() & 0x7fff_ffff;
    if magnitude(next) == 0 || next.is_normal() || !next.is_finite() {
        next
    } else if magnitude(next) > magnitude(x) {
        f32::MIN_POSITIVE.copysign(next)
    } else {
        0.0
    }
}

/// A value computed in f64 from f32 inputs, with the bound on its rounding
/// error and the bound on how far the exact value moves when each input
/// moves by one ulp (an infinite radius when a step leaves the inputs a
/// tracer must answer: beyond [`MAX_COORDINATE`], or to an infinity).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Perturbed {
    pub filtered: Filtered,
    pub radius: f64,
}

impl Perturbed {
    /// An f32 input (given as f64), free to move one ulp either way.
    pub fn input(x: f64) -> Self {
        let single = x as f32;
        let radius = [true, false]
            .map(|up| (f64::from(ulp_step(single, up)) - x).abs())
            .into_iter()
            .fold(0.0, f64::max);
        let leaves = !radius.is_finite() || x.abs() + radius > f64::from(MAX_COORDINATE);
        Self {
            filtered: Filtered::exact(x),
            radius: if leaves { f64::INFINITY } else { radius },
        }
    }

    /// The sign of the exact value for the inputs as given and for every
    /// input one ulp away, when the bounds decide it.
    pub fn steady_sign(&self) -> Option<Ordering> {
        let reach = self.filtered.error_bound() + self.radius * RADIUS_SLACK;
        // A NaN or infinite reach decides nothing.
        if !reach.is_finite() {
            return None;
        }
        let value = self.filtered.value;
        if value > reach {
            Some(Ordering::Greater)
        } else if value < -reach {
            Some(Ordering::Less)
        } else {
            None
        }
    }
}

impl Number for Perturbed {
    fn exact(x: f64) -> Self {
        Self::input(x)
    }

    fn difference(a: f64, b: f64) -> Self {
        Self::input(a).sub(&Self::input(b))
    }

    fn add(&self, o: &Self) -> Self {
        Self {
            filtered: self.filtered.add(&o.filtered),
            radius: self.radius + o.radius,
        }
    }

    fn sub(&self, o: &Self) -> Self {
        Self {
            filtered: self.filtered.sub(&o.filtered),
            radius: self.radius + o.radius,
        }
    }

    /// `|a'b' - ab| <= |a|·|b' - b| + |b'|·|a' - a|`, with `|a|` bounded
    /// by its magnitude (the polynomial on absolute values) and
    /// `|b'| <= |b| + radius`.
    fn mul(&self, o: &Self) -> Self {
        let (a, b) = (&self.filtered, &o.filtered);
        Self {
            filtered: a.mul(b),
            radius: a.magnitude * o.radius + (b.magnitude + o.radius) * self.radius,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exact::number::{cross, dot, translated};
    use crate::random::Rng;

    #[test]
    fn one_ulp_steps_skip_subnormals() {
        assert_eq!(ulp_step(1.0, true), 1.0f32.next_up());
        assert_eq!(ulp_step(0.0, true), f32::MIN_POSITIVE);
        assert_eq!(ulp_step(-0.0, false), -f32::MIN_POSITIVE);
        assert_eq!(ulp_step(f32::MIN_POSITIVE, false), 0.0);
    }

    #[test]
    fn steps_are_the_same_where_denormals_are_zero() {
        // The referee judges on worker threads that flush denormals and
        // read them as zero: a step decided by float comparisons there
        // would leave zero where it is.
        let values = [0.0, -0.0, f32::MIN_POSITIVE, -f32::MIN_POSITIVE, 1.0, 1e-30];
        let steps =
            move || values.map(|x| [ulp_step(x, true), ulp_step(x, false)].map(f32::to_bits));
        let plain = steps();
        let flushed = std::thread::spawn(move || {
            raycheck_reference::enable_flush_to_zero_and_denormals_are_zero();
            steps()
        })
        .join()
        .unwrap();
        assert_eq!(flushed, plain);
        assert_eq!(plain[0][0], f32::MIN_POSITIVE.to_bits());
    }

    #[test]
    fn an_input_moves_by_its_larger_step() {
        // Below a power of two the step down is half the step up.
        assert_eq!(Perturbed::input(1.0).radius, f64::from(f32::EPSILON));
        assert_eq!(Perturbed::input(0.0).radius, f64::from(f32::MIN_POSITIVE));
        assert_eq!(Perturbed::input(f64::from(f32::MAX)).radius, f64::INFINITY);
        assert_eq!(
            Perturbed::input(f64::from(MAX_COORDINATE)).radius,
            f64::INFINITY
        );
    }

    /// `d · ((c - o) × (b - o))`, one edge function of the contact test.
    fn edge<T: Number>(d: &[f32; 3], o: &[f32; 3], b: &[f32; 3], c: &[f32; 3]) -> T {
        let d = d.map(|x| T::exact(f64::from(x)));
        dot(&d, &cross(&translated(c, o), &translated(b, o)))
    }

    #[test]
    fn a_steady_sign_holds_for_every_single_step() {
        // Random inputs near a sign change: wherever the bound certifies a
        // sign, every input moved one ulp either way keeps it.
        let mut rng = Rng::new(5);
        let (mut certified, mut left) = (0, 0);
        for _ in 0..2_000 {
            let mut point = || std::array::from_fn(|_| rng.range_f32(-4.0, 4.0));
            let (d, o, b) = (point(), point(), point());
            // c at 10^-k of the plane through o spanned by d and b - o.
            let off = 10f32.powi(-(rng.below(8) as i32)) * rng.range_f32(-1.0, 1.0);
            let c: [f32; 3] =
                std::array::from_fn(|k| o[k] + (b[k] - o[k]) * 0.5 + d[k] * 0.25 + off);
            let Some(sign) = edge::<Perturbed>(&d, &o, &b, &c).steady_sign() else {
                left += 1;
                continue;
            };
            certified += 1;
            let inputs = [d, o, b, c];
            for which in 0..4 {
                for axis in 0..3 {
                    for up in [true, false] {
                        let mut moved = inputs;
                        moved[which][axis] = ulp_step(moved[which][axis], up);
                        let [d, o, b, c] = moved;
                        let exact = edge::<crate::exact::expansion::Expansion>(&d, &o, &b, &c);
                        assert_eq!(exact.sign(), sign, "{moved:?}");
                    }
                }
            }
        }
        assert!(
            certified > 100 && left > 100,
            "{certified} certified, {left} left"
        );
    }
}
