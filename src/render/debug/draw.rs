//! Lines in the scene drawn onto an image as the camera sees them: clipped
//! to the near plane, projected, clipped to the image and stepped one
//! pixel at a time (a DDA), one pixel wide.

use crate::render::image::Image;
use crate::scene::Camera;
use glam::{Vec2, Vec3};

/// Points closer to the eye than this (view-space depth) are clipped away.
const NEAR: f32 = 1e-4;

/// Draws the scene segment `a`–`b` as `camera` sees it, in linear `colour`.
pub fn segment(image: &mut Image, camera: &Camera, a: Vec3, b: Vec3, colour: Vec3) {
    let (mut a, mut b) = (camera.to_view(a), camera.to_view(b));
    if a.z < NEAR && b.z < NEAR {
        return;
    }
    // Cut the part behind the near plane.
    if a.z < NEAR {
        a = a.lerp(b, (NEAR - a.z) / (b.z - a.z));
    } else if b.z < NEAR {
        b = b.lerp(a, (NEAR - b.z) / (a.z - b.z));
    }
    let (w, h) = (image.width, image.height);
    line(
        image,
        camera.raster(a, w, h),
        camera.raster(b, w, h),
        colour,
    );
}

/// Draws the raster segment `a`–`b` (continuous coordinates, pixel (i, j)
/// covering [i, i+1) × [j, j+1)).
pub fn line(image: &mut Image, a: Vec2, b: Vec2, colour: Vec3) {
    let size = Vec2::new(image.width as f32, image.height as f32);
    let Some((a, b)) = clip(a, b, size) else {
        return;
    };
    let steps = (b - a).abs().max_element().ceil().max(1.0) as u32;
    for i in 0..=steps {
        let p = a.lerp(b, i as f32 / steps as f32);
        plot(image, p, colour);
    }
}

/// A small `+` of arm `arm` pixels centred on raster point `centre`.
pub fn cross(image: &mut Image, centre: Vec2, arm: f32, colour: Vec3) {
    line(
        image,
        centre - Vec2::X * arm,
        centre + Vec2::X * arm,
        colour,
    );
    line(
        image,
        centre - Vec2::Y * arm,
        centre + Vec2::Y * arm,
        colour,
    );
}

fn plot(image: &mut Image, p: Vec2, colour: Vec3) {
    let (x, y) = (p.x.floor(), p.y.floor());
    if x >= 0.0 && y >= 0.0 && x < image.width as f32 && y < image.height as f32 {
        image.pixels[y as usize * image.width as usize + x as usize] = colour;
    }
}

/// The part of `a`–`b` inside [0, size] (Liang and Barsky 1984), if any.
fn clip(a: Vec2, b: Vec2, size: Vec2) -> Option<(Vec2, Vec2)> {
    if !(a.is_finite() && b.is_finite()) {
        return None;
    }
    let d = b - a;
    let (mut enter, mut leave) = (0.0f32, 1.0f32);
    for (p, q) in [
        (-d.x, a.x),
        (d.x, size.x - a.x),
        (-d.y, a.y),
        (d.y, size.y - a.y),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                enter = enter.max(r);
            } else {
                leave = leave.min(r);
            }
        }
    }
    (enter <= leave).then(|| (a + enter * d, a + leave * d))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lit(image: &Image) -> Vec<(u32, u32)> {
        (0..image.height)
            .flat_map(|y| (0..image.width).map(move |x| (x, y)))
            .filter(|&(x, y)| image.get(x, y) != Vec3::ZERO)
            .collect()
    }

    #[test]
    fn lines_are_clipped_to_the_image() {
        let mut image = Image::new(8, 4);
        line(
            &mut image,
            Vec2::new(-100.0, 1.5),
            Vec2::new(100.0, 1.5),
            Vec3::ONE,
        );
        assert_eq!(lit(&image), (0..8).map(|x| (x, 1)).collect::<Vec<_>>());
        let mut image = Image::new(8, 4);
        line(
            &mut image,
            Vec2::new(-5.0, -5.0),
            Vec2::new(-1.0, 9.0),
            Vec3::ONE,
        );
        assert!(lit(&image).is_empty());
    }

    #[test]
    fn a_segment_behind_the_eye_is_cut_at_the_near_plane() {
        let camera = Camera {
            eye: Vec3::ZERO,
            look_at: Vec3::Z,
            up: Vec3::Y,
            fov_y_deg: 90.0,
        };
        // From behind the camera to straight ahead: only the part in front
        // shows, ending at the image centre.
        let mut image = Image::new(9, 9);
        let (behind, ahead) = (Vec3::new(1.0, 0.0, -1.0), Vec3::new(0.0, 0.0, 5.0));
        segment(&mut image, &camera, behind, ahead, Vec3::ONE);
        let pixels = lit(&image);
        assert!(pixels.contains(&(4, 4)), "{pixels:?}");
        assert!(pixels.iter().all(|&(_, y)| y == 4), "{pixels:?}");
        // Wholly behind: nothing.
        let mut image = Image::new(9, 9);
        segment(&mut image, &camera, behind, -ahead, Vec3::ONE);
        assert!(lit(&image).is_empty());
    }
}
