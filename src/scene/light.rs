//! Light sources: points, segments (line lights) and parallelograms (area lights).
//!
//! What a light's colour means depends on its kind, per channel:
//!
//! - a point's colour is its radiant intensity, the same in every
//!   direction: it gives irradiance `color / d²` at distance `d` to a
//!   surface facing it;
//! - a segment is a line of such points, isotropic too, and its colours
//!   (one per end, interpolated along it) are the intensity of the whole
//!   segment: a segment of colour `c` seen from far away is a point of
//!   colour `c`;
//! - a parallelogram is a Lambertian emitter: its colours (one per corner,
//!   interpolated bilinearly) are the radiance `L` leaving its emitting side
//!   in every direction, so a patch `dA` sends intensity `L·cos θ·dA` at an
//!   angle θ from the light's normal and nothing behind it (unless it is
//!   two-sided). A small parallelogram of area `A` seen along its normal
//!   from far away is a point of colour `L·A`.

use glam::Vec3;

#[derive(Clone, Debug, PartialEq)]
pub enum Light {
    Point {
        position: Vec3,
        color: Vec3,
    },
    /// The segment from `a` to `b`; `colors` at `a` and `b`.
    Segment {
        a: Vec3,
        b: Vec3,
        colors: [Vec3; 2],
    },
    /// The points `corner + s·edge_u + t·edge_v`, s and t in [0, 1];
    /// `colors` at (s, t) = (0,0), (1,0), (1,1), (0,1). It emits on the side
    /// its normal `edge_u × edge_v` points to (the right-hand rule), or on
    /// both sides when `two_sided`.
    Parallelogram {
        corner: Vec3,
        edge_u: Vec3,
        edge_v: Vec3,
        colors: [Vec3; 4],
        two_sided: bool,
    },
}

impl Light {
    /// The centre of the light, for renderers that treat every light as a point.
    pub fn representative_point(&self) -> Vec3 {
        match self {
            Light::Point { position, .. } => *position,
            Light::Segment { a, b, .. } => 0.5 * (*a + *b),
            Light::Parallelogram {
                corner,
                edge_u,
                edge_v,
                ..
            } => *corner + 0.5 * (*edge_u + *edge_v),
        }
    }

    /// The mean colour over the light (intensity or radiance, see the
    /// module's documentation).
    pub fn mean_color(&self) -> Vec3 {
        match self {
            Light::Point { color, .. } => *color,
            Light::Segment { colors, .. } => 0.5 * (colors[0] + colors[1]),
            Light::Parallelogram { colors, .. } => 0.25 * colors.iter().copied().sum::<Vec3>(),
        }
    }

    /// A parallelogram's unit normal `edge_u × edge_v`, the direction its
    /// emitting side faces; `None` for points and segments, which have no side.
    pub fn normal(&self) -> Option<Vec3> {
        match self {
            Light::Parallelogram { edge_u, edge_v, .. } => Some(edge_u.cross(*edge_v).normalize()),
            _ => None,
        }
    }

    /// A parallelogram's area; 0 for points and segments.
    pub fn area(&self) -> f32 {
        match self {
            Light::Parallelogram { edge_u, edge_v, .. } => edge_u.cross(*edge_v).length(),
            _ => 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn representative_points_are_centres() {
        let seg = Light::Segment {
            a: Vec3::ZERO,
            b: Vec3::new(2.0, 0.0, 0.0),
            colors: [Vec3::ONE; 2],
        };
        assert_eq!(seg.representative_point(), Vec3::X);
        assert_eq!(seg.normal(), None);
        let quad = Light::Parallelogram {
            corner: Vec3::ONE,
            edge_u: Vec3::new(2.0, 0.0, 0.0),
            edge_v: Vec3::new(0.0, 0.0, 4.0),
            colors: [Vec3::ZERO, Vec3::ONE, Vec3::ONE, Vec3::ZERO],
            two_sided: false,
        };
        assert_eq!(quad.representative_point(), Vec3::new(2.0, 1.0, 3.0));
        assert_eq!(quad.mean_color(), Vec3::splat(0.5));
        // x × z = -y: this one faces down.
        assert_eq!(quad.normal(), Some(Vec3::NEG_Y));
        assert_eq!(quad.area(), 8.0);
    }
}
