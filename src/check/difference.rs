//! One ray on which two backends answered differently.

use crate::geometry::{Hit, Ray};

/// The answers of both backends to one query, kept whole so the referee can
/// judge them and anyone can replay the ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Difference {
    /// Closest-hit answers that differ in hit/miss, triangle, or `t`
    /// beyond [`T_TOLERANCE`].
    Intersect {
        ray: Ray,
        ours: Option<Hit>,
        reference: Option<Hit>,
    },
    /// Any-hit answers that differ.
    Occluded {
        ray: Ray,
        ours: bool,
        reference: bool,
    },
}

/// Relative `t` difference above which two hits on the same triangle count
/// as different answers (f32 arithmetic on either side stays far below it).
pub const T_TOLERANCE: f32 = 1e-5;

/// `|a - b| / |b|`, guarded against `b == 0`.
pub fn relative_error(a: f32, b: f32) -> f32 {
    let diff = (a - b).abs();
    if diff == 0.0 {
        0.0
    } else {
        diff / b.abs().max(f32::MIN_POSITIVE)
    }
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

impl Difference {
    pub fn kind(&self) -> DifferenceKind {
        match self {
            Difference::Intersect {
                ours: Some(a),
                reference: Some(b),
                ..
            } => {
                if a.prim == b.prim {
                    DifferenceKind::Distance
                } else {
                    DifferenceKind::Prim
                }
            }
            Difference::Intersect { .. } => DifferenceKind::HitMiss,
            Difference::Occluded { .. } => DifferenceKind::Occlusion,
        }
    }

    pub fn ray(&self) -> &Ray {
        match self {
            Difference::Intersect { ray, .. } | Difference::Occluded { ray, .. } => ray,
        }
    }

    /// A total order on the bits of the ray, so that lists of differences
    /// come out the same whatever the thread count.
    pub fn sort_key(&self) -> (u8, [u32; 8]) {
        let kind = matches!(self, Difference::Occluded { .. }) as u8;
        (kind, self.ray().inputs().map(f32::to_bits))
    }
}
