//! How a ray meets one triangle, decided exactly.
//!
//! The decision is the Plücker form of the watertight test (Woop, Benthin,
//! Wald 2013, without the shear): with the corners translated to the ray
//! origin, `A = p0 - o`, `B = p1 - o`, `C = p2 - o`, the three edge
//! functions are the signed volumes `d·(C×B)`, `d·(A×C)`, `d·(B×A)`. The ray
//! passes through the closed triangle when none of them has a sign opposite
//! to another's and their sum `D = -d·n` is not zero (a ray in the plane, or
//! a degenerate triangle, is never hit). It meets the plane at
//! `t = N / D` with `N = A·(C×B)`, and the interval test
//! `tnear <= t <= tfar` becomes the signs of `N - tnear·D` and
//! `tfar·D - N` relative to `D`'s. Every quantity is a polynomial in the f32
//! inputs, each of which is exact in f64: its sign is taken from the
//! filtered f64 value when the error bound allows, else from an exact
//! expansion (Shewchuk 1997).

use super::perturbed::Perturbed;
use crate::bvh::MAX_COORDINATE;
use crate::exact::expansion::Expansion;
use crate::exact::filtered::Filtered;
use crate::exact::number::{Number, Vector, cross, dot, translated};
use crate::geometry::Ray;
use std::cmp::Ordering;

/// A triangle's corners, as the f32 values the backends see.
pub type Corners = [[f32; 3]; 3];

/// The polynomials the decision is made of.
struct Quantities<T> {
    edges: [T; 3],
    denominator: T,
    numerator: T,
    /// `N - tnear·D`, absent when `tnear` is `-∞`.
    near: Option<T>,
    /// `tfar·D - N`, absent when `tfar` is `+∞`.
    far: Option<T>,
}

impl<T> Quantities<T> {
    fn map<U>(&self, f: impl Fn(&T) -> U) -> Quantities<U> {
        Quantities {
            edges: [f(&self.edges[0]), f(&self.edges[1]), f(&self.edges[2])],
            denominator: f(&self.denominator),
            numerator: f(&self.numerator),
            near: self.near.as_ref().map(&f),
            far: self.far.as_ref().map(&f),
        }
    }
}

fn quantities<T: Number>(ray: &Ray, corners: &Corners) -> Quantities<T> {
    let origin = ray.origin.to_array();
    let [a, b, c]: [Vector<T>; 3] = [
        translated(&corners[0], &origin),
        translated(&corners[1], &origin),
        translated(&corners[2], &origin),
    ];
    let d: Vector<T> = ray.dir.to_array().map(|x| T::exact(f64::from(x)));
    let c_cross_b = cross(&c, &b);
    let edges = [
        dot(&d, &c_cross_b),
        dot(&d, &cross(&a, &c)),
        dot(&d, &cross(&b, &a)),
    ];
    let denominator = edges[0].add(&edges[1]).add(&edges[2]);
    let numerator = dot(&a, &c_cross_b);
    let bound = |t: f32| T::exact(f64::from(t)).mul(&denominator);
    let near = (ray.tnear != f32::NEG_INFINITY).then(|| numerator.sub(&bound(ray.tnear)));
    let far = (ray.tfar != f32::INFINITY).then(|| bound(ray.tfar).sub(&numerator));
    Quantities {
        edges,
        denominator,
        numerator,
        near,
        far,
    }
}

/// The signs that decide a contact.
struct Signs {
    edges: [Ordering; 3],
    denominator: Ordering,
    /// `None` when the bound is infinite, so always met.
    near: Option<Ordering>,
    far: Option<Ordering>,
}

impl Signs {
    fn of<T>(q: &Quantities<T>, sign: impl Fn(&T) -> Option<Ordering>) -> Option<Signs> {
        let bound = |x: &Option<T>| match x {
            None => Some(None),
            Some(v) => sign(v).map(Some),
        };
        Some(Signs {
            edges: [sign(&q.edges[0])?, sign(&q.edges[1])?, sign(&q.edges[2])?],
            denominator: sign(&q.denominator)?,
            near: bound(&q.near)?,
            far: bound(&q.far)?,
        })
    }

    fn is_hit(&self) -> bool {
        let positive = self.edges.contains(&Ordering::Greater);
        let negative = self.edges.contains(&Ordering::Less);
        let within =
            |s: Option<Ordering>| s.is_none_or(|s| (s as i8) * (self.denominator as i8) >= 0);
        !(positive && negative)
            && self.denominator != Ordering::Equal
            && within(self.near)
            && within(self.far)
    }
}

/// Whether the inputs are ones a tracer must answer: a finite ray with a
/// NaN-free interval, and corners Embree keeps (finite, within
/// [`MAX_COORDINATE`]).
fn is_decidable(ray: &Ray, corners: &Corners) -> bool {
    ray.origin.is_finite()
        && ray.dir.is_finite()
        && !ray.tnear.is_nan()
        && !ray.tfar.is_nan()
        && ray.tnear != f32::INFINITY
        && ray.tfar != f32::NEG_INFINITY
        && corners.iter().flatten().all(|x| x.abs() <= MAX_COORDINATE)
}

/// The exact `t` at which `ray` hits the triangle, or `None` when it does
/// not (exactly, inputs as given). The returned `t` is `N / D` to about
/// f64 precision.
pub fn exact_hit(ray: &Ray, corners: &Corners) -> Option<f64> {
    if !is_decidable(ray, corners) || has_equal_corners(corners) {
        return None;
    }
    decide(ray, corners, &quantities::<Filtered>(ray, corners))
}

/// Whether two corners are equal: then the normal, and with it `D`, is
/// exactly zero, and no ray hits the triangle (decided without the
/// expansions its zero would otherwise need).
fn has_equal_corners([a, b, c]: &Corners) -> bool {
    a == b || b == c || a == c
}

/// The exact decision of a decidable contact, from the filtered
/// quantities when their signs are certain, else from expansions.
fn decide(ray: &Ray, corners: &Corners, filtered: &Quantities<Filtered>) -> Option<f64> {
    let hit = match Signs::of(filtered, Filtered::sign) {
        Some(signs) => signs.is_hit(),
        None => {
            let exact = quantities::<Expansion>(ray, corners);
            Signs::of(&exact, |x| Some(x.sign()))?.is_hit()
        }
    };
    hit.then(|| distance(ray, corners, filtered))
}

/// How a ray meets one triangle: the exact `t` of a hit (`None` for a
/// miss), and whether the same decision, hit or miss, holds for every ray
/// and triangle one f32 ulp away in any of their inputs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contact {
    pub t: Option<f64>,
    pub steady: bool,
}

/// The contact of `ray` with the triangle: [`exact_hit`], and whether its
/// signs clear every one-ulp change ([`Perturbed`]). A triangle with three
/// equal corners is a steady miss: two equal corners make `D` zero, and
/// one vertex moved leaves two equal.
pub fn contact(ray: &Ray, corners: &Corners) -> Contact {
    if corners[0] == corners[1] && corners[1] == corners[2] {
        return Contact {
            t: None,
            steady: true,
        };
    }
    if !is_decidable(ray, corners) || has_equal_corners(corners) {
        return Contact {
            t: None,
            steady: false,
        };
    }
    let perturbed = quantities::<Perturbed>(ray, corners);
    let filtered = perturbed.map(|p| p.filtered);
    match Signs::of(&perturbed, Perturbed::steady_sign) {
        Some(signs) => Contact {
            t: signs.is_hit().then(|| distance(ray, corners, &filtered)),
            steady: true,
        },
        None => Contact {
            t: decide(ray, corners, &filtered),
            steady: false,
        },
    }
}

/// `N / D` from the filtered values when both are known to 20 bits beyond
/// f64's error bound, else from the exact expansions.
fn distance(ray: &Ray, corners: &Corners, filtered: &Quantities<Filtered>) -> f64 {
    let tight = |x: &Filtered| x.value.abs() > x.error_bound() * (1 << 20) as f64;
    if tight(&filtered.numerator) && tight(&filtered.denominator) {
        filtered.numerator.value / filtered.denominator.value
    } else {
        let exact = quantities::<Expansion>(ray, corners);
        exact.numerator.estimate() / exact.denominator.estimate()
    }
}

/// `N1·D2 - N2·D1` and `D1·D2`, whose signs order two hits.
fn order_quantities<T: Number>(ray: &Ray, first: &Corners, second: &Corners) -> (T, T) {
    let p = quantities::<T>(ray, first);
    let q = quantities::<T>(ray, second);
    let cross_difference = p
        .numerator
        .mul(&q.denominator)
        .sub(&q.numerator.mul(&p.denominator));
    (cross_difference, p.denominator.mul(&q.denominator))
}

/// The order of two hits from the signs of [`order_quantities`]; both are
/// hits, so `D1·D2` is not zero.
fn order(value: Ordering, scale: Ordering) -> Ordering {
    if scale == Ordering::Less {
        value.reverse()
    } else {
        value
    }
}

/// The exact order of the distances at which `ray` hits two triangles it
/// is known to hit: the sign of `N1/D1 - N2/D2`.
pub fn compare_hits(ray: &Ray, first: &Corners, second: &Corners) -> Ordering {
    if first == second {
        return Ordering::Equal;
    }
    let (value, scale) = order_quantities::<Filtered>(ray, first, second);
    let (value, scale) = value.sign().zip(scale.sign()).unwrap_or_else(|| {
        let (value, scale) = order_quantities::<Expansion>(ray, first, second);
        (value.sign(), scale.sign())
    });
    order(value, scale)
}

/// The order of two hits ([`compare_hits`]) when it is the same for every
/// ray and pair of triangles one f32 ulp away in any of their inputs (and
/// both are hit there).
pub fn steady_order(ray: &Ray, first: &Corners, second: &Corners) -> Option<Ordering> {
    let (value, scale) = order_quantities::<Perturbed>(ray, first, second);
    Some(order(value.steady_sign()?, scale.steady_sign()?))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::Rng;
    use glam::Vec3;

    const UNIT: Corners = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

    fn down_at(x: f32, y: f32) -> Ray {
        Ray::new(Vec3::new(x, y, 1.0), Vec3::NEG_Z)
    }

    #[test]
    fn closed_triangle_edges_and_corners_are_hit() {
        for (x, y) in [(0.25, 0.25), (0.5, 0.5), (0.0, 0.0), (1.0, 0.0), (0.0, 0.3)] {
            assert_eq!(exact_hit(&down_at(x, y), &UNIT), Some(1.0), "({x}, {y})");
        }
        // One f32 ulp outside the hypotenuse x + y = 1: a certain miss.
        let beside = 0.5f32.next_up();
        assert_eq!(exact_hit(&down_at(beside, 0.5), &UNIT), None);
        assert_eq!(exact_hit(&down_at(-f32::MIN_POSITIVE, 0.5), &UNIT), None);
    }

    #[test]
    fn interval_is_inclusive_and_exact() {
        let ray = |tnear: f32, tfar: f32| {
            Ray::segment(Vec3::new(0.25, 0.25, 1.0), Vec3::NEG_Z, tnear, tfar)
        };
        assert_eq!(exact_hit(&ray(1.0, 1.0), &UNIT), Some(1.0));
        assert_eq!(exact_hit(&ray(0.0, 1.0f32.next_down()), &UNIT), None);
        assert_eq!(exact_hit(&ray(1.0f32.next_up(), 2.0), &UNIT), None);
        assert_eq!(exact_hit(&ray(2.0, 1.0), &UNIT), None);
        assert_eq!(exact_hit(&ray(f32::NEG_INFINITY, 5.0), &UNIT), Some(1.0));
        assert_eq!(exact_hit(&ray(f32::NAN, 5.0), &UNIT), None);
    }

    #[test]
    fn rays_in_the_plane_and_degenerate_triangles_miss() {
        let in_plane = Ray::new(Vec3::new(-1.0, 0.25, 0.0), Vec3::X);
        assert_eq!(exact_hit(&in_plane, &UNIT), None);
        let collinear = [[0.0, 0.0, 0.0], [1.0, 1.0, 0.0], [2.0, 2.0, 0.0]];
        assert_eq!(exact_hit(&down_at(1.0, 1.0), &collinear), None);
        assert_eq!(exact_hit(&down_at(0.0, 0.0), &[[0.0; 3]; 3]), None);
    }

    /// The decision in i128 for integer inputs: exact by construction.
    fn integer_hit(o: [i128; 3], d: [i128; 3], p: [[i128; 3]; 3]) -> bool {
        let sub = |a: [i128; 3]| [a[0] - o[0], a[1] - o[1], a[2] - o[2]];
        let cross = |a: [i128; 3], b: [i128; 3]| {
            [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ]
        };
        let dot = |a: [i128; 3], b: [i128; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let [a, b, c] = p.map(sub);
        let e = [
            dot(d, cross(c, b)),
            dot(d, cross(a, c)),
            dot(d, cross(b, a)),
        ];
        let denominator: i128 = e.iter().sum();
        let numerator = dot(a, cross(c, b));
        let mixed = e.iter().any(|&x| x > 0) && e.iter().any(|&x| x < 0);
        !mixed && denominator != 0 && numerator.signum() * denominator.signum() >= 0
    }

    #[test]
    fn decisions_match_integer_arithmetic_on_and_beside_edges() {
        // Integer coordinates below 2^22 are exact in f32; rays aimed at
        // points exactly on an edge, or one grid step beside it, put every
        // decision at or next to the boundary, where naive f64 products of
        // this size (beyond 2^53) round.
        let mut rng = Rng::new(11);
        let mut int = |bits: u32| (rng.next_u64() >> (64 - bits)) as i128 - (1 << (bits - 1));
        let (mut hits, mut misses) = (0, 0);
        for _ in 0..20_000 {
            let p: [[i128; 3]; 3] = std::array::from_fn(|_| std::array::from_fn(|_| int(20) * 4));
            let o: [i128; 3] = std::array::from_fn(|_| int(21));
            let edge = (int(8) & 1) as usize;
            let (from, to) = (p[edge], p[edge + 1]);
            let step = int(8);
            let target: [i128; 3] = std::array::from_fn(|k| {
                from[k] + (to[k] - from[k]) / 4 * 2 + step.signum() * (k as i128 % 2)
            });
            let d: [i128; 3] = std::array::from_fn(|k| target[k] - o[k]);
            let to_f32 = |v: [i128; 3]| v.map(|x| x as f32);
            let ray = Ray::new(Vec3::from_array(to_f32(o)), Vec3::from_array(to_f32(d)));
            let expected = integer_hit(o, d, p);
            assert_eq!(
                exact_hit(&ray, &p.map(to_f32)).is_some(),
                expected,
                "{o:?} {d:?} {p:?}"
            );
            if expected { hits += 1 } else { misses += 1 }
        }
        assert!(hits > 1000 && misses > 1000, "{hits} hits, {misses} misses");
    }

    #[test]
    fn hit_order_is_exact() {
        let plane = |z: f32| -> Corners { [[-1.0, -1.0, z], [4.0, -1.0, z], [-1.0, 4.0, z]] };
        let ray = down_at(0.25, 0.25);
        let (lower, upper) = (plane(0.0), plane(f32::MIN_POSITIVE));
        assert_eq!(compare_hits(&ray, &upper, &lower), Ordering::Less);
        assert_eq!(compare_hits(&ray, &lower, &upper), Ordering::Greater);
        assert_eq!(compare_hits(&ray, &lower, &plane(0.0)), Ordering::Equal);
        // The same plane through other corners: an exact tie.
        let other: Corners = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        assert_eq!(compare_hits(&ray, &lower, &other), Ordering::Equal);
    }
}
