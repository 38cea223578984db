//! The pinhole camera.

use crate::geometry::Ray;
use glam::{Vec2, Vec3};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub eye: Vec3,
    pub look_at: Vec3,
    pub up: Vec3,
    /// Full vertical field of view, in degrees.
    pub fov_y_deg: f32,
}

impl Camera {
    /// The primary ray through raster point (`x`, `y`) of a `width` x
    /// `height` image.
    ///
    /// Raster coordinates are continuous: pixel (i, j) covers
    /// `[i, i+1) x [j, j+1)`, so its centre is (i + 0.5, j + 0.5); `y` grows
    /// downward. The ray starts at the eye; its direction is *not*
    /// normalized (it reaches the image plane at distance 1 at t = 1).
    pub fn ray(&self, x: f32, y: f32, width: u32, height: u32) -> Ray {
        self.rays(width, height).ray(x, y)
    }

    /// The primary rays of a `width` x `height` image, for many rays: the
    /// frame and the image plane's extent are worked out once.
    pub fn rays(&self, width: u32, height: u32) -> CameraRays {
        CameraRays {
            eye: self.eye,
            frame: self.frame(),
            half: self.half_extent(width, height),
            size: Vec2::new(width as f32, height as f32),
        }
    }

    /// `point` in the camera's frame: x right, y up, z forward (depth).
    pub fn to_view(&self, point: Vec3) -> Vec3 {
        let [right, true_up, forward] = self.frame();
        let d = point - self.eye;
        Vec3::new(d.dot(right), d.dot(true_up), d.dot(forward))
    }

    /// The raster point where a view-space point in front of the camera
    /// (`view.z > 0`) appears: the inverse of [`Camera::ray`].
    pub fn raster(&self, view: Vec3, width: u32, height: u32) -> Vec2 {
        let half = self.half_extent(width, height);
        Vec2::new(
            (view.x / (view.z * half.x) + 1.0) * 0.5 * width as f32,
            (1.0 - view.y / (view.z * half.y)) * 0.5 * height as f32,
        )
    }

    /// Unit right, up and forward vectors.
    fn frame(&self) -> [Vec3; 3] {
        let forward = (self.look_at - self.eye).normalize();
        let right = forward.cross(self.up).normalize();
        [right, right.cross(forward), forward]
    }

    /// Half the image plane's width and height at distance 1.
    fn half_extent(&self, width: u32, height: u32) -> Vec2 {
        let half_height = (0.5 * self.fov_y_deg.to_radians()).tan();
        Vec2::new(half_height * width as f32 / height as f32, half_height)
    }
}

/// The primary rays of one image size ([`Camera::rays`]): [`Camera::ray`]
/// with its per-image part done once. Per pixel that part was two
/// normalisations, a tangent and three divisions, more than the ray
/// itself: a quarter of a render's shading and sampling time (dragon-48k).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraRays {
    eye: Vec3,
    /// Unit right, up and forward vectors.
    frame: [Vec3; 3],
    /// Half the image plane's width and height at distance 1.
    half: Vec2,
    /// The image's width and height in pixels.
    size: Vec2,
}

impl CameraRays {
    /// The primary ray through raster point (`x`, `y`) (see [`Camera::ray`]).
    pub fn ray(&self, x: f32, y: f32) -> Ray {
        let [right, true_up, forward] = self.frame;
        let sx = (2.0 * x / self.size.x - 1.0) * self.half.x;
        let sy = (1.0 - 2.0 * y / self.size.y) * self.half.y;
        Ray::new(self.eye, forward + sx * right + sy * true_up)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Camera {
        Camera {
            eye: Vec3::new(1.0, 2.0, 3.0),
            look_at: Vec3::new(1.0, 2.0, 10.0),
            up: Vec3::Y,
            fov_y_deg: 90.0,
        }
    }

    #[test]
    fn image_centre_looks_at_the_target() {
        let ray = camera().ray(50.0, 25.0, 100, 50);
        assert_eq!(ray.origin, Vec3::new(1.0, 2.0, 3.0));
        assert!((ray.dir - Vec3::Z).length() < 1e-6);
    }

    #[test]
    fn top_edge_is_half_the_fov_up_and_y_grows_downward() {
        let top = camera().ray(50.0, 0.0, 100, 50).dir;
        assert!((top - Vec3::new(0.0, 1.0, 1.0)).length() < 1e-6, "{top}");
        let bottom = camera().ray(50.0, 50.0, 100, 50).dir;
        assert!(bottom.y < 0.0);
    }

    #[test]
    fn raster_inverts_ray() {
        let camera = Camera {
            eye: Vec3::new(1.0, 2.0, 3.0),
            look_at: Vec3::new(4.0, -1.0, 9.0),
            up: Vec3::Y,
            fov_y_deg: 40.0,
        };
        for (x, y) in [(0.0, 0.0), (12.5, 40.25), (99.0, 49.5)] {
            let ray = camera.ray(x, y, 100, 50);
            let view = camera.to_view(ray.at(7.0));
            assert!(view.z > 0.0);
            let back = camera.raster(view, 100, 50);
            assert!((back - Vec2::new(x, y)).length() < 1e-3, "{back}");
        }
    }

    #[test]
    fn right_edge_follows_the_aspect_ratio_and_right_hand_rule() {
        // Looking down +z with +y up, the image's right is -x.
        let right = camera().ray(100.0, 25.0, 100, 50).dir;
        assert!(
            (right - Vec3::new(-2.0, 0.0, 1.0)).length() < 1e-6,
            "{right}"
        );
    }
}
