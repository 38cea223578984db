//! The renderer: generic over any [`Intersector`], so the same code renders
//! on our BVH, on Embree, or on both at once (checked).
//!
//! One file per feature: [`shading`] (Phong), [`shadows`] (hard shadows),
//! [`reflection`] (mirrors); [`pipeline`] decides which of them a scene
//! needs, [`surface`] resolves hits, [`image`] holds and writes the result.

pub mod image;
pub mod pipeline;
pub mod reflection;
pub mod shading;
pub mod shadows;
pub mod surface;

use crate::geometry::Ray;
use crate::scene::Scene;
use crate::trace::Intersector;
use glam::Vec3;
use image::Image;
use pipeline::Passes;
use rayon::prelude::*;
use surface::SurfacePoint;

/// How big an image to render and how deep to recurse.
#[derive(Clone, Copy, Debug)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    /// Reflection rays followed per primary ray, at most.
    pub max_depth: u32,
}

impl RenderSettings {
    pub fn square(resolution: u32) -> Self {
        Self {
            width: resolution,
            height: resolution,
            max_depth: 4,
        }
    }
}

/// Renders `scene` through `intersector`, one primary ray through each
/// pixel's centre. Every pixel depends only on its coordinates, so the image
/// is the same for any thread count; run it inside
/// [`crate::parallel::thread_pool`] to choose the count.
pub fn render<I: Intersector + ?Sized>(
    scene: &Scene,
    intersector: &I,
    settings: &RenderSettings,
) -> Image {
    let tracer = Tracer {
        scene,
        intersector,
        passes: Passes::for_scene(scene),
        max_depth: settings.max_depth,
    };
    let (width, height) = (settings.width, settings.height);
    let mut image = Image::new(width, height);
    image
        .pixels
        .par_chunks_mut(width as usize)
        .enumerate()
        .for_each(|(y, row)| {
            for (x, pixel) in row.iter_mut().enumerate() {
                let ray = scene
                    .camera
                    .ray(x as f32 + 0.5, y as f32 + 0.5, width, height);
                *pixel = tracer.radiance(&ray, 0);
            }
        });
    image
}

struct Tracer<'a, I: ?Sized> {
    scene: &'a Scene,
    intersector: &'a I,
    passes: Passes,
    max_depth: u32,
}

impl<I: Intersector + ?Sized> Tracer<'_, I> {
    fn radiance(&self, ray: &Ray, depth: u32) -> Vec3 {
        let Some(hit) = self.intersector.intersect(ray) else {
            return Vec3::ZERO;
        };
        let surface = SurfacePoint::new(&self.scene.mesh, ray, &hit);
        let material = &self.scene.materials[surface.material as usize];
        let local = if self.passes.shading {
            self.direct_light(&surface)
        } else {
            material.kd
        };
        let mirrors = self.passes.reflection && material.mirror != Vec3::ZERO;
        if mirrors && depth < self.max_depth {
            let reflected = self.radiance(&surface.reflection_ray(), depth + 1);
            reflection::blend(local, material.mirror, reflected)
        } else {
            local
        }
    }

    fn direct_light(&self, surface: &SurfacePoint) -> Vec3 {
        let material = &self.scene.materials[surface.material as usize];
        let mut sum = shading::ambient(material);
        for light in &self.scene.lights {
            let position = light.representative_point();
            if self.passes.hard_shadows
                && !shadows::light_visible(self.intersector, surface, position)
            {
                continue;
            }
            let offset = position - surface.position;
            let irradiance = shading::inverse_square(light.mean_color(), offset.length_squared());
            sum += shading::phong(material, surface, offset.normalize_or_zero(), irradiance);
        }
        sum
    }
}
