//! The side of a triangle's plane on which a point lies, and the side a
//! direction points to, decided exactly: the signs of
//! `((b - a) × (c - a))·(p - a)` (Shewchuk's 1997 `orient3d` with the
//! opposite sign convention, positive on the side the right-hand normal of
//! `a, b, c` points to) and of `((b - a) × (c - a))·d`.

use super::expansion::Expansion;
use super::filtered::Filtered;
use super::number::{Number, cross, dot, translated};
use std::cmp::Ordering;

/// `((b - a) × (c - a))·v`.
fn along_normal<T: Number>(corners: &[[f32; 3]; 3], v: &[T; 3]) -> T {
    let [a, b, c] = corners;
    dot(&cross(&translated::<T>(b, a), &translated(c, a)), v)
}

fn orientation<T: Number>(corners: &[[f32; 3]; 3], p: &[f32; 3]) -> T {
    along_normal(corners, &translated(p, &corners[0]))
}

fn projection<T: Number>(corners: &[[f32; 3]; 3], direction: &[f32; 3]) -> T {
    along_normal(corners, &direction.map(|x| T::exact(f64::from(x))))
}

/// The exact sign of `((b - a) × (c - a))·(p - a)` for the f32 inputs as
/// given: `Greater` on the side of the normal, `Equal` in the plane (or for
/// a degenerate triangle). Finite inputs only.
pub fn plane_side(corners: &[[f32; 3]; 3], p: &[f32; 3]) -> Ordering {
    orientation::<Filtered>(corners, p)
        .sign()
        .unwrap_or_else(|| orientation::<Expansion>(corners, p).sign())
}

/// The exact sign of `((b - a) × (c - a))·d`: `Greater` when the direction
/// `d` points to the side of the normal. Finite inputs only.
pub fn normal_side(corners: &[[f32; 3]; 3], direction: &[f32; 3]) -> Ordering {
    projection::<Filtered>(corners, direction)
        .sign()
        .unwrap_or_else(|| projection::<Expansion>(corners, direction).sign())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::Rng;

    const FLOOR: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

    #[test]
    fn the_side_follows_the_normal_and_the_winding() {
        assert_eq!(plane_side(&FLOOR, &[0.3, 0.3, 1.0]), Ordering::Greater);
        assert_eq!(plane_side(&FLOOR, &[5.0, -7.0, -1e-30]), Ordering::Less);
        assert_eq!(plane_side(&FLOOR, &[5.0, -7.0, 0.0]), Ordering::Equal);
        let [a, b, c] = FLOOR;
        assert_eq!(plane_side(&[a, c, b], &[0.3, 0.3, 1.0]), Ordering::Less);
        assert_eq!(normal_side(&FLOOR, &[9.0, 9.0, 1e-30]), Ordering::Greater);
        assert_eq!(normal_side(&FLOOR, &[9.0, 9.0, 0.0]), Ordering::Equal);
        assert_eq!(normal_side(&[a, c, b], &[0.0, 0.0, 1.0]), Ordering::Less);
    }

    /// The determinant in i128, exact for integer-valued inputs below 2^24.
    fn exact_side(corners: &[[f32; 3]; 3], p: &[f32; 3]) -> Ordering {
        let i = |v: &[f32; 3]| v.map(|x| x as i128);
        let ([a, b, c], p) = (corners.map(|v| i(&v)), i(p));
        let (u, w, q) = (
            [0, 1, 2].map(|k| b[k] - a[k]),
            [0, 1, 2].map(|k| c[k] - a[k]),
            [0, 1, 2].map(|k| p[k] - a[k]),
        );
        let n = [
            u[1] * w[2] - u[2] * w[1],
            u[2] * w[0] - u[0] * w[2],
            u[0] * w[1] - u[1] * w[0],
        ];
        (n[0] * q[0] + n[1] * q[1] + n[2] * q[2]).cmp(&0)
    }

    #[test]
    fn points_one_step_off_a_large_plane_match_integer_arithmetic() {
        // Integer corners below 2^22 and points on their plane, then moved
        // by one in one coordinate: the products reach 2^69, beyond what f64
        // holds, so most signs come from the expansions.
        let mut rng = Rng::new(3);
        let mut next = |bound: usize| rng.below(bound) as f32;
        for _ in 0..20_000 {
            let corners: [[f32; 3]; 3] =
                std::array::from_fn(|_| std::array::from_fn(|_| next(1 << 22)));
            let [a, b, c] = corners;
            let (s, t) = (next(3), next(3));
            let mut p: [f32; 3] =
                std::array::from_fn(|k| a[k] + s * (b[k] - a[k]) + t * (c[k] - a[k]));
            assert_eq!(plane_side(&corners, &p), exact_side(&corners, &p));
            let (axis, step) = (next(3) as usize, 2.0 * next(2) - 1.0);
            p[axis] += step;
            assert_eq!(
                plane_side(&corners, &p),
                exact_side(&corners, &p),
                "{corners:?} {p:?}"
            );
        }
    }
}
