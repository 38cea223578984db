//! Light sources: points, segments (line lights) and parallelograms (area lights).
//!
//! A light's colour is its radiant intensity per channel: a point light
//! gives irradiance `color / d²` at distance `d` (facing it). Extended lights
//! carry a colour per vertex, interpolated over the light.

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
    /// `colors` at (s, t) = (0,0), (1,0), (1,1), (0,1).
    Parallelogram {
        corner: Vec3,
        edge_u: Vec3,
        edge_v: Vec3,
        colors: [Vec3; 4],
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

    /// The mean colour over the light.
    pub fn mean_color(&self) -> Vec3 {
        match self {
            Light::Point { color, .. } => *color,
            Light::Segment { colors, .. } => 0.5 * (colors[0] + colors[1]),
            Light::Parallelogram { colors, .. } => 0.25 * colors.iter().copied().sum::<Vec3>(),
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
        let quad = Light::Parallelogram {
            corner: Vec3::ONE,
            edge_u: Vec3::new(2.0, 0.0, 0.0),
            edge_v: Vec3::new(0.0, 0.0, 4.0),
            colors: [Vec3::ZERO, Vec3::ONE, Vec3::ONE, Vec3::ZERO],
        };
        assert_eq!(quad.representative_point(), Vec3::new(2.0, 1.0, 3.0));
        assert_eq!(quad.mean_color(), Vec3::splat(0.5));
    }
}
