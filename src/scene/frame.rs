//! What a bare mesh, which comes without a manifest, is rendered with: a
//! camera that frames it, a light beside the camera, and the features its
//! content calls for.

use super::Scene;
use super::camera::Camera;
use super::feature::Feature;
use super::light::Light;
use crate::geometry::Aabb;
use glam::Vec3;

/// The features every bare mesh gets: it is lit by a point light.
pub const ALWAYS: [Feature; 2] = [Feature::Shading, Feature::HardShadows];

/// The features a bare mesh gets when its meshes and materials have what
/// they act on ([`Feature::support`]): a mirror, vertex normals, a diffuse
/// texture with texture coordinates, a rough mirror, an opacity below 1.
pub const FROM_CONTENT: [Feature; 5] = [
    Feature::Reflection,
    Feature::NormalInterpolation,
    Feature::Textures,
    Feature::Glossy,
    Feature::Transparency,
];

/// The features of a bare mesh's `scene`: [`ALWAYS`], then those of
/// [`FROM_CONTENT`] that it supports.
pub fn bare_mesh_features(scene: &Scene) -> Vec<Feature> {
    ALWAYS
        .into_iter()
        .chain(
            FROM_CONTENT
                .into_iter()
                .filter(|f| f.support(scene).is_ok()),
        )
        .collect()
}

/// Vertical field of view of a framing camera.
const FOV_Y_DEG: f32 = 40.0;

/// A camera looking at the centre of `bounds` from the +z side, slightly
/// above, far enough back that the bounding sphere fits the view.
pub fn framing_camera(bounds: &Aabb) -> Camera {
    let (center, radius) = sphere(bounds);
    let distance = radius / (0.5 * FOV_Y_DEG.to_radians()).sin();
    Camera {
        eye: center + distance * Vec3::new(0.0, 0.25, 1.0).normalize(),
        look_at: center,
        up: Vec3::Y,
        fov_y_deg: FOV_Y_DEG,
    }
}

/// A white point light above and to the right of `camera`, bright enough
/// that the irradiance at the centre of `bounds` is about 1.
pub fn default_light(bounds: &Aabb, camera: &Camera) -> Light {
    let (center, radius) = sphere(bounds);
    let forward = (camera.look_at - camera.eye).normalize();
    let right = forward.cross(camera.up).normalize();
    let position = camera.eye + radius * (right + camera.up.normalize());
    Light::Point {
        position,
        color: Vec3::splat((position - center).length_squared()),
    }
}

/// Centre and radius of a sphere around the box; a unit sphere at the
/// origin for an empty box.
fn sphere(bounds: &Aabb) -> (Vec3, f32) {
    if bounds.is_empty() {
        return (Vec3::ZERO, 1.0);
    }
    let radius = 0.5 * bounds.extent().length();
    (bounds.center(), if radius > 0.0 { radius } else { 1.0 })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_whole_box_is_in_view() {
        let bounds = Aabb {
            min: Vec3::new(-3.0, 1.0, 2.0),
            max: Vec3::new(5.0, 2.0, 4.0),
        };
        let camera = framing_camera(&bounds);
        let forward = (camera.look_at - camera.eye).normalize();
        let half_fov = (0.5 * camera.fov_y_deg).to_radians();
        for i in 0..8 {
            let corner = Vec3::new(
                if i & 1 == 0 {
                    bounds.min.x
                } else {
                    bounds.max.x
                },
                if i & 2 == 0 {
                    bounds.min.y
                } else {
                    bounds.max.y
                },
                if i & 4 == 0 {
                    bounds.min.z
                } else {
                    bounds.max.z
                },
            );
            let angle = forward.angle_between(corner - camera.eye);
            assert!(angle < half_fov, "corner {corner} at {angle} rad");
        }
        let light = default_light(&bounds, &camera);
        assert!(!bounds.contains(&Aabb::from_points(&[light.representative_point()])));
    }

    #[test]
    fn degenerate_boxes_still_give_a_usable_camera() {
        for bounds in [Aabb::EMPTY, Aabb::from_points(&[Vec3::ONE])] {
            let camera = framing_camera(&bounds);
            assert!(camera.eye.is_finite() && camera.eye != camera.look_at);
        }
    }
}
