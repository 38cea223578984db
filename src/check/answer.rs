//! One backend's answer to one query, and how two answers differ.

use crate::geometry::{Hit, Ray};

/// What a backend answered: a closest hit (or a miss) for `intersect`, a
/// yes or no for `occluded`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Answer {
    Closest(Option<Hit>),
    Occluded(bool),
}

/// Relative `t` difference above which two hits on the same triangle count
/// as different answers (f32 arithmetic on either side stays far below it).
pub const T_TOLERANCE: f32 = 1e-5;

/// `|a - b| / |b|`, guarded against `b == 0`; 0 for equal values (two
/// equal infinities included), NaN when either is NaN or only `b` is
/// infinite.
pub fn relative_error(a: f32, b: f32) -> f32 {
    if a == b {
        0.0
    } else {
        (a - b).abs() / b.abs().max(f32::MIN_POSITIVE)
    }
}

/// Whether two distances are the same answer: equal, or within
/// [`T_TOLERANCE`] relative. A NaN or an infinity against a finite
/// distance is a different answer, whichever side it is on.
fn same_distance(a: f32, b: f32) -> bool {
    relative_error(a, b) <= T_TOLERANCE
}

/// What two answers differ in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum DifferenceKind {
    /// One backend hit, the other missed.
    HitMiss,
    /// Both hit, different triangles.
    Prim,
    /// Both hit the same triangle at distances beyond [`T_TOLERANCE`].
    Distance,
    /// Any-hit answers differ.
    Occlusion,
}

impl DifferenceKind {
    /// How `a` and `b` differ, or `None` when they are the same answer.
    pub fn between(a: &Answer, b: &Answer) -> Option<DifferenceKind> {
        match (a, b) {
            (Answer::Closest(None), Answer::Closest(None)) => None,
            (Answer::Closest(Some(x)), Answer::Closest(Some(y))) => {
                if x.prim != y.prim {
                    Some(DifferenceKind::Prim)
                } else if !same_distance(x.t, y.t) {
                    Some(DifferenceKind::Distance)
                } else {
                    None
                }
            }
            (Answer::Closest(_), Answer::Closest(_)) => Some(DifferenceKind::HitMiss),
            (Answer::Occluded(x), Answer::Occluded(y)) => {
                (x != y).then_some(DifferenceKind::Occlusion)
            }
            _ => Some(DifferenceKind::HitMiss),
        }
    }
}

/// One query kept with every backend's answer, in the order the backends
/// were given: a query on which two answers differ, or one drawn into the
/// referee's sample of agreeing queries.
#[derive(Clone, Debug, PartialEq)]
pub struct Record {
    pub ray: Ray,
    pub answers: Vec<Answer>,
    /// Whether two answers differ (else the record is a sampled agreement).
    pub disagreement: bool,
}

impl Record {
    /// A total order on the query and the ray's bits, so that lists of
    /// records come out the same whatever the thread count.
    pub fn sort_key(&self) -> (u8, [u32; 8]) {
        let occluded = matches!(self.answers.first(), Some(Answer::Occluded(_))) as u8;
        (occluded, ray_bits(&self.ray))
    }
}

/// The ray's eight inputs as bits: the key that says two queries were
/// asked of the same ray.
pub fn ray_bits(ray: &Ray) -> [u32; 8] {
    ray.inputs().map(f32::to_bits)
}

/// A hit on `prim` at `t`, for tests.
#[cfg(test)]
pub fn hit(prim: u32, t: f32) -> Answer {
    Answer::Closest(Some(Hit {
        t,
        u: 0.0,
        v: 0.0,
        prim,
        ng: glam::Vec3::Z,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kinds_of_difference() {
        let miss = Answer::Closest(None);
        assert_eq!(DifferenceKind::between(&miss, &miss), None);
        assert_eq!(
            DifferenceKind::between(&hit(0, 1.0), &hit(0, 1.0 + 1e-6)),
            None
        );
        assert_eq!(
            DifferenceKind::between(&hit(0, 1.0), &hit(0, 1.001)),
            Some(DifferenceKind::Distance)
        );
        assert_eq!(
            DifferenceKind::between(&hit(0, 1.0), &hit(1, 1.0)),
            Some(DifferenceKind::Prim)
        );
        // An infinite or NaN distance differs from a finite one, on either
        // side; two equal infinities do not.
        for odd in [f32::INFINITY, f32::NAN] {
            for (a, b) in [(hit(0, 1.0), hit(0, odd)), (hit(0, odd), hit(0, 1.0))] {
                assert_eq!(
                    DifferenceKind::between(&a, &b),
                    Some(DifferenceKind::Distance),
                    "{a:?} {b:?}"
                );
            }
        }
        let far = hit(0, f32::INFINITY);
        assert_eq!(DifferenceKind::between(&far, &far), None);
        assert_eq!(
            DifferenceKind::between(&hit(0, 1.0), &miss),
            Some(DifferenceKind::HitMiss)
        );
        assert_eq!(
            DifferenceKind::between(&Answer::Occluded(true), &Answer::Occluded(false)),
            Some(DifferenceKind::Occlusion)
        );
    }
}
