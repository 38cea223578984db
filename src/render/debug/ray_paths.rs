//! One pixel's rays drawn into the render: the renderer records every ray
//! the pixel traces (see [`crate::render::Renderer::pixel_rays`]), and each
//! is drawn from its origin to its hit, or out of the scene, as the camera
//! sees it. Primary rays, and the transmitted rays that continue them, run
//! along the line of sight, so each also gets a cross at its hit. Primary
//! rays are yellow, reflected ones magenta, transmitted ones cyan,
//! shadow rays green when the light is visible and red when blocked. The
//! render underneath is dimmed so that the rays stand out.

use super::{DebugImage, display, draw};
use crate::geometry::{Aabb, Ray};
use crate::render::Renderer;
use crate::render::image::Image;
use crate::render::surface::{SHADOW_RAY_END, SurfacePoint};
use crate::trace::Intersector;
use glam::Vec3;

/// Why a ray was traced.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RayKind {
    Primary,
    Reflected,
    Transmitted,
    /// Towards a point on a light; `blocked` when something is in the way.
    Shadow {
        blocked: bool,
    },
}

/// One traced ray, from its origin to where it stopped.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RaySegment {
    pub kind: RayKind,
    pub origin: Vec3,
    /// The hit point, the light sample point for a shadow ray, or `None`
    /// for a ray that left the scene.
    pub end: Option<Vec3>,
    /// The unit direction.
    pub dir: Vec3,
}

impl RaySegment {
    /// A closest-hit ray that hit at `t`, or nothing.
    pub fn traced(kind: RayKind, ray: &Ray, t: Option<f32>) -> Self {
        Self {
            kind,
            origin: ray.origin,
            end: t.map(|t| ray.at(t)),
            dir: ray.dir.normalize_or_zero(),
        }
    }

    /// The shadow ray from `surface` towards `light`.
    pub fn shadow(surface: &SurfacePoint, light: Vec3, blocked: bool) -> Self {
        let ray = surface.shadow_ray(light);
        Self {
            kind: RayKind::Shadow { blocked },
            origin: ray.origin,
            end: Some(ray.at(SHADOW_RAY_END)),
            dir: ray.dir.normalize_or_zero(),
        }
    }

    /// The display colour of the segment's kind.
    pub fn colour(&self) -> Vec3 {
        match self.kind {
            RayKind::Primary => Vec3::new(1.0, 1.0, 0.0),
            RayKind::Reflected => Vec3::new(1.0, 0.0, 1.0),
            RayKind::Transmitted => Vec3::new(0.0, 1.0, 1.0),
            RayKind::Shadow { blocked: false } => Vec3::new(0.0, 1.0, 0.0),
            RayKind::Shadow { blocked: true } => Vec3::new(1.0, 0.0, 0.0),
        }
    }
}

/// How much of the render's brightness shows under the rays.
const DIMMING: f32 = 0.35;
/// Arm of the cross marking a primary or transmitted ray's end, pixels.
const CROSS_ARM: f32 = 2.0;

/// `render`, dimmed, with every ray of pixel (`x`, `y`) drawn on it.
pub fn draw<I: Intersector + ?Sized>(
    renderer: &Renderer<I>,
    render: Image,
    x: u32,
    y: u32,
) -> anyhow::Result<DebugImage> {
    let (width, height) = (render.width, render.height);
    if x >= width || y >= height {
        anyhow::bail!("pixel ({x}, {y}) is outside the {width}×{height} image");
    }
    let scene = renderer.scene;
    let rays = renderer.pixel_rays(x, y);
    // Rays that leave the scene are drawn as far as its diagonal.
    let bounds = scene
        .meshes()
        .iter()
        .fold(Aabb::EMPTY, |b, m| b.union(m.bounds()));
    let escape = bounds.extent().length();
    let mut image = Image {
        pixels: render.pixels.iter().map(|&c| DIMMING * c).collect(),
        ..render
    };
    // Shadow rays first, so the paths they start from stay visible.
    let mut ordered = rays.clone();
    ordered.sort_by_key(|r| !matches!(r.kind, RayKind::Shadow { .. }));
    for ray in &ordered {
        let colour = display(ray.colour());
        let end = ray.end.unwrap_or(ray.origin + escape * ray.dir);
        draw::segment(&mut image, &scene.camera, ray.origin, end, colour);
        let at = scene.camera.to_view(end);
        if matches!(ray.kind, RayKind::Primary | RayKind::Transmitted) && at.z > 0.0 {
            let centre = scene.camera.raster(at, width, height);
            draw::cross(&mut image, centre, CROSS_ARM, colour);
        }
    }
    let count = |kind: RayKind| rays.iter().filter(|r| r.kind == kind).count();
    Ok(DebugImage {
        image,
        legend: format!(
            "the rays of pixel ({x}, {y}): {} primary (yellow), {} reflected (magenta), \
             {} transmitted (cyan), crosses where rays along the line of sight end; \
             shadow rays {} unblocked (green), {} blocked (red)",
            count(RayKind::Primary),
            count(RayKind::Reflected),
            count(RayKind::Transmitted),
            count(RayKind::Shadow { blocked: false }),
            count(RayKind::Shadow { blocked: true }),
        ),
    })
}
