//! The side of a ray on which a directed edge passes, decided exactly: the
//! sign of the signed volume `d·((p - o) × (q - o))`, the edge function of
//! the watertight test (Woop, Benthin, Wald 2013) without the shear. It is
//! antisymmetric in `p` and `q`, so the two triangles sharing an edge always
//! get opposite signs.

use super::expansion::Expansion;
use super::filtered::Filtered;
use super::number::{Number, cross, dot, translated};
use std::cmp::Ordering;

fn edge_function<T: Number>(
    origin: &[f32; 3],
    direction: &[f32; 3],
    p: &[f32; 3],
    q: &[f32; 3],
) -> T {
    let d = direction.map(|x| T::exact(f64::from(x)));
    dot(&d, &cross(&translated(p, origin), &translated(q, origin)))
}

/// The exact sign of `d·((p - o) × (q - o))` for the f32 inputs as given:
/// from the filtered f64 value when its error bound allows, else from
/// expansions. Finite inputs only (the product of two f32 differences and
/// an f32 never overflows or underflows f64).
pub fn edge_sign(origin: &[f32; 3], direction: &[f32; 3], p: &[f32; 3], q: &[f32; 3]) -> Ordering {
    edge_function::<Filtered>(origin, direction, p, q)
        .sign()
        .unwrap_or_else(|| edge_function::<Expansion>(origin, direction, p, q).sign())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sign_follows_the_side_and_flips_with_the_edge() {
        let (o, d) = ([0.0, 0.0, 1.0], [0.0, 0.0, -1.0]);
        let (p, q) = ([1.0, -1.0, 0.0], [1.0, 1.0, 0.0]);
        // The ray at x = 0 passes left of the edge x = 1 seen from above.
        let side = edge_sign(&o, &d, &p, &q);
        assert_ne!(side, Ordering::Equal);
        assert_eq!(edge_sign(&o, &d, &q, &p), side.reverse());
        // Through the edge's line: exactly zero.
        let on = [1.0, 0.5, 1.0];
        assert_eq!(edge_sign(&on, &d, &p, &q), Ordering::Equal);
    }

    #[test]
    fn a_volume_below_f64_rounding_is_still_signed() {
        // The edge runs 2^-40 beside the ray at a distance of 2^30: the f64
        // filter cannot decide, the expansions do.
        let big = 2f32.powi(30);
        let tiny = 2f32.powi(-40);
        let (o, d) = ([0.0, 0.0, big], [0.0, 0.0, -1.0]);
        let (p, q) = ([tiny, -1.0, 0.0], [tiny, 1.0, 0.0]);
        let beside = edge_sign(&o, &d, &p, &q);
        let through = edge_sign(&o, &d, &[0.0, -1.0, 0.0], &[0.0, 1.0, 0.0]);
        let other_side = edge_sign(&o, &d, &[-tiny, -1.0, 0.0], &[-tiny, 1.0, 0.0]);
        assert_eq!(through, Ordering::Equal);
        assert_ne!(beside, Ordering::Equal);
        assert_eq!(other_side, beside.reverse());
    }
}
