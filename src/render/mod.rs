//! The renderer: generic over any [`Intersector`], so the same code renders
//! on our BVH, on Embree, or on both at once (checked).
//!
//! One file per feature: [`shading`] (Phong), [`shadows`] (hard shadows),
//! [`reflection`] (mirrors), [`area_lights`], [`normal_interpolation`],
//! [`textures`], [`motion_blur`], [`bloom`], [`multisample`], [`glossy`],
//! [`transparency`]; [`direct_light`] sums the lights at a point,
//! [`pipeline`] decides which of them a scene needs,
//! [`batch`] traces an image's camera rays a batch at a time,
//! [`sampling`] gives the random numbers, [`surface`] resolves hits,
//! [`image`] holds and writes the result; [`debug`] draws what the tracer
//! did (BVH boxes, node visits, surface attributes, bloom mask, a pixel's
//! rays).

pub mod area_lights;
pub mod batch;
pub mod bloom;
pub mod debug;
pub mod direct_light;
pub mod glossy;
pub mod image;
pub mod motion_blur;
pub mod multisample;
pub mod normal_interpolation;
pub mod pipeline;
pub mod profile;
pub mod reflection;
pub mod sampling;
pub mod shading;
pub mod shadows;
pub mod surface;
pub mod textures;
pub mod transparency;

use crate::geometry::{Ray, TriangleMesh};
use crate::scene::Scene;
use crate::scene::camera::CameraRays;
use crate::trace::Intersector;
use debug::ray_paths::{RayKind, RaySegment};
use glam::{Vec2, Vec3};
use image::Image;
use motion_blur::LayerHit;
use pipeline::Passes;
use sampling::{SampleStream, Sampler};
use surface::SurfacePoint;

/// The version of what the renderer outputs. Increase it in the same
/// change as anything that alters a rendered pixel (sampling, shading, a
/// light's units, the random streams, a pass's order): images cached from
/// an older renderer, such as the sweep's converged references
/// (`sweep::reference`), are keyed by it and rendered again rather than
/// compared against.
pub const RENDER_VERSION: u32 = 1;

/// How big an image to render, with how many samples, placed how, and
/// which seed.
#[derive(Clone, Copy, Debug)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    /// Camera samples per pixel instead of the scene's own count.
    pub samples_per_pixel: Option<u32>,
    /// The seed of every random number of the render.
    pub seed: u64,
    /// How the samples of each estimate are placed: camera samples in the
    /// pixel and in the shutter, shadow rays over an area light, glossy
    /// rays over the lobe.
    pub sampler: Sampler,
}

impl RenderSettings {
    pub fn square(resolution: u32) -> Self {
        Self {
            width: resolution,
            height: resolution,
            samples_per_pixel: None,
            seed: 0,
            sampler: Sampler::Stratified,
        }
    }

    /// The image size `N` (square) or `WxH`, each side 1 to 16384.
    pub fn of_size(text: &str) -> anyhow::Result<Self> {
        let side = |s: &str| {
            s.parse::<u32>()
                .ok()
                .filter(|v| (1..=16384).contains(v))
                .ok_or_else(|| {
                    anyhow::anyhow!("bad resolution '{text}': expected N or WxH, 1 to 16384")
                })
        };
        let (width, height) = match text.split_once(['x', 'X']) {
            Some((w, h)) => (side(w)?, side(h)?),
            None => (side(text)?, side(text)?),
        };
        Ok(Self {
            width,
            height,
            ..Self::square(width)
        })
    }
}

/// Renders a scene without moving meshes through `intersector`.
pub fn render<I: Intersector + ?Sized>(
    scene: &Scene,
    intersector: &I,
    settings: &RenderSettings,
) -> Image {
    render_layers(scene, &[intersector], settings)
}

/// Renders `scene` with one intersector per mesh layer (see
/// [`Scene::meshes`]). Every pixel depends only on its coordinates and the
/// seed, so the image is the same for any thread count; run it inside
/// [`crate::parallel::thread_pool`] to choose the count.
pub fn render_layers<I: Intersector + ?Sized>(
    scene: &Scene,
    layers: &[&I],
    settings: &RenderSettings,
) -> Image {
    let renderer = Renderer::new(scene, layers, settings);
    renderer.post_process(renderer.render_radiance())
}

/// A render in progress: the scene, its intersectors and its passes.
pub struct Renderer<'a, I: ?Sized> {
    pub scene: &'a Scene,
    pub layers: &'a [&'a I],
    pub passes: Passes,
    pub settings: RenderSettings,
    /// The camera's rays through this image's pixels.
    camera_rays: CameraRays,
}

/// The state one camera sample carries along its rays.
struct PathState {
    stream: SampleStream,
    time: f32,
    /// Every ray traced, when a debug view asks for them.
    log: Option<Vec<RaySegment>>,
}

impl<'a, I: Intersector + ?Sized> Renderer<'a, I> {
    /// # Panics
    /// If `layers` does not hold one intersector per mesh of the scene.
    pub fn new(scene: &'a Scene, layers: &'a [&'a I], settings: &RenderSettings) -> Self {
        assert_eq!(
            layers.len(),
            scene.meshes().len(),
            "one intersector per mesh layer of {}",
            scene.name
        );
        Self {
            scene,
            layers,
            passes: Passes::for_render(scene, settings.samples_per_pixel),
            settings: *settings,
            camera_rays: scene.camera.rays(settings.width, settings.height),
        }
    }

    /// The image work after the radiance: bloom, where the scene asks.
    pub fn post_process(&self, radiance: Image) -> Image {
        if self.passes.bloom {
            bloom::apply(&radiance, &self.scene.params.bloom)
        } else {
            radiance
        }
    }

    /// The image before post-processing (bloom), its rows in parallel and
    /// each row's camera rays a [`batch`] at a time: the same pixels as
    /// [`Renderer::pixel`] gives one by one.
    pub fn render_radiance(&self) -> Image {
        Image::par_from_rows(self.settings.width, self.settings.height, |y, row| {
            self.fill_row(y, row)
        })
    }

    /// The mean radiance of pixel (`x`, `y`) over its camera samples,
    /// each traced to its end before the next: the same bits as
    /// [`Renderer::render_radiance`] gives it.
    pub fn pixel(&self, x: u32, y: u32) -> Vec3 {
        let count = self.passes.samples_per_pixel;
        let sum: Vec3 = (0..count)
            .map(|sample| {
                let (ray, mut state) = self.camera_sample(x, y, sample);
                self.radiance(&ray, RayKind::Primary, 0, &mut state)
            })
            .sum();
        sum / count as f32
    }

    /// Every ray pixel (`x`, `y`) traces over its camera samples, in order.
    pub fn pixel_rays(&self, x: u32, y: u32) -> Vec<RaySegment> {
        let mut rays = Vec::new();
        for sample in 0..self.passes.samples_per_pixel {
            let (ray, mut state) = self.camera_sample(x, y, sample);
            state.log = Some(rays);
            self.radiance(&ray, RayKind::Primary, 0, &mut state);
            rays = state.log.unwrap_or_default();
        }
        rays
    }

    /// The camera ray of one sample of a pixel, and the sample's state.
    fn camera_sample(&self, x: u32, y: u32, sample: u32) -> (Ray, PathState) {
        let width = self.settings.width;
        let count = self.passes.samples_per_pixel;
        let sampler = self.settings.sampler;
        let mut stream = SampleStream::new(self.settings.seed, y * width + x, sample);
        let offset = if self.passes.multisample {
            multisample::subpixel_offset(sample, count, sampler, &mut stream)
        } else {
            Vec2::splat(0.5)
        };
        let time = if self.passes.motion_blur {
            motion_blur::shutter_time(sample, count, sampler, &mut stream)
        } else {
            0.0
        };
        let ray = self
            .camera_rays
            .ray(x as f32 + offset.x, y as f32 + offset.y);
        (
            ray,
            PathState {
                stream,
                time,
                log: None,
            },
        )
    }

    /// The closest hit over every layer at the sample's time.
    fn closest_hit(&self, ray: &Ray, time: f32) -> Option<LayerHit> {
        motion_blur::intersect(self.scene, self.layers, ray, time)
    }

    /// The surface a hit lands on, in the scene's frame.
    fn surface(&self, ray: &Ray, hit: &LayerHit) -> (SurfacePoint, &TriangleMesh) {
        let mesh = self.scene.layer_mesh(hit.layer);
        let mut surface = SurfacePoint::new(mesh, ray, &hit.hit);
        surface.position += hit.shift;
        if self.passes.normal_interpolation
            && let Some(n) = normal_interpolation::shading_normal(
                mesh,
                surface.prim,
                surface.u,
                surface.v,
                surface.geometric_normal,
            )
        {
            surface.normal = n;
        }
        (surface, mesh)
    }

    fn radiance(&self, ray: &Ray, kind: RayKind, depth: u32, state: &mut PathState) -> Vec3 {
        let hit = self.closest_hit(ray, state.time);
        self.shade(ray, hit, kind, depth, state)
    }

    /// The radiance `ray` brings back, given its closest hit.
    fn shade(
        &self,
        ray: &Ray,
        hit: Option<LayerHit>,
        kind: RayKind,
        depth: u32,
        state: &mut PathState,
    ) -> Vec3 {
        if let Some(log) = &mut state.log {
            log.push(RaySegment::traced(kind, ray, hit.map(|h| h.hit.t)));
        }
        let Some(hit) = hit else {
            return Vec3::ZERO;
        };
        let (surface, diffuse) = self.lit_surface(ray, &hit);
        let color = if self.passes.shading {
            self.direct_light(&surface, diffuse, state)
        } else {
            diffuse
        };
        self.beyond(&surface, color, depth, state)
    }

    /// The surface a hit lands on and its diffuse colour.
    #[inline(always)]
    fn lit_surface(&self, ray: &Ray, hit: &LayerHit) -> (SurfacePoint, Vec3) {
        let (surface, mesh) = self.surface(ray, hit);
        let diffuse = self.diffuse(mesh, &surface);
        (surface, diffuse)
    }

    /// `color`, the light a surface sends back itself, blended with what
    /// its mirror reflects and what shows through it.
    #[inline(always)]
    fn beyond(
        &self,
        surface: &SurfacePoint,
        color: Vec3,
        depth: u32,
        state: &mut PathState,
    ) -> Vec3 {
        let material = &self.scene.materials[surface.material as usize];
        let mut color = color;
        let deeper = depth < self.passes.max_depth;
        if self.passes.reflection && material.mirror.max_element() > 0.0 && deeper {
            let reflected = if self.passes.glossy && material.roughness > 0.0 {
                self.glossy_reflection(surface, material.roughness, depth, state)
            } else {
                let ray = surface.reflection_ray();
                self.radiance(&ray, RayKind::Reflected, depth + 1, state)
            };
            color = reflection::blend(color, material.mirror, reflected);
        }
        if self.passes.transparency && material.opacity < 1.0 && deeper {
            let ray = transparency::continuation_ray(surface);
            let behind = self.radiance(&ray, RayKind::Transmitted, depth + 1, state);
            color = transparency::blend(material.opacity, color, behind);
        }
        color
    }

    /// The material's diffuse colour, or its texture's at the hit.
    fn diffuse(&self, mesh: &TriangleMesh, surface: &SurfacePoint) -> Vec3 {
        let material = &self.scene.materials[surface.material as usize];
        if self.passes.textures
            && let Some(texture) = &self.scene.textures[surface.material as usize]
            && let Some(uv) = textures::texcoord(mesh, surface.prim, surface.u, surface.v)
        {
            return textures::lookup(texture, material.texture_filter, uv);
        }
        material.kd
    }

    /// The mean of `glossy_samples` reflection rays in the lobe (one below
    /// the primary hit, so the ray count stays linear in the depth); a
    /// sample below the surface adds nothing (see [`glossy`]).
    fn glossy_reflection(
        &self,
        surface: &SurfacePoint,
        roughness: f32,
        depth: u32,
        state: &mut PathState,
    ) -> Vec3 {
        let count = if depth == 0 {
            self.passes.glossy_samples
        } else {
            1
        };
        let exponent = glossy::phong_exponent(roughness);
        let mirror = surface.mirror_direction();
        let sampler = self.settings.sampler;
        let mut sum = Vec3::ZERO;
        for index in 0..count {
            let xi = sampler.sample_2d(index, count, &mut state.stream);
            if let Some(dir) = glossy::reflect(mirror, surface.geometric_normal, exponent, xi) {
                let ray = Ray::new(surface.spawn_origin(), dir);
                sum += self.radiance(&ray, RayKind::Reflected, depth + 1, state);
            }
        }
        sum / count as f32
    }
}
