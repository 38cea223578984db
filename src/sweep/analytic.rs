//! The exact image of a scene whose answer has a closed form: one uniform
//! parallelogram light over purely diffuse surfaces that lie in one plane,
//! so nothing shadows anything. Each pixel is then what the renderer
//! converges to as the light samples grow: the ambient term plus
//! `kd × radiance × E`, where `E` is the light's irradiance per unit
//! radiance at the pixel's primary hit, which Lambert's formula gives for
//! any polygon (Lambert 1760; in the vector form of Arvo 1995, "The
//! irradiance Jacobian for partially occluded polyhedral sources"):
//!
//! ```text
//! E = ½ |Σᵢ Θᵢ (Γᵢ · n)|
//! ```
//!
//! over the polygon's edges, where Θᵢ is the angle edge i subtends at the
//! point and Γᵢ the unit normal of the plane through the point and the
//! edge. It holds while the whole polygon is above the point's horizon;
//! otherwise it would have to be clipped first, which this module refuses
//! to do.

use crate::geometry::Ray;
use crate::render::image::Image;
use crate::render::pipeline::Passes;
use crate::render::surface::SurfacePoint;
use crate::render::{RenderSettings, shading};
use crate::scene::{Light, Scene};
use crate::trace::Intersector;
use anyhow::{bail, ensure};
use glam::{DVec3, Vec3};

/// The irradiance at `point`, on a surface of unit normal `normal`, from
/// the polygon `vertices` (in order around it) of unit radiance, by
/// Lambert's formula. Every vertex must be above the point's horizon.
pub fn polygon_irradiance(vertices: &[DVec3], point: DVec3, normal: DVec3) -> f64 {
    let sum: f64 = vertices
        .iter()
        .zip(vertices.iter().cycle().skip(1))
        .map(|(a, b)| {
            let (a, b) = ((*a - point).normalize(), (*b - point).normalize());
            let cross = a.cross(b);
            // Θ·Γ = atan2(|a × b|, a · b) · (a × b)/|a × b|, well-conditioned
            // for small angles too.
            let sin = cross.length();
            if sin == 0.0 {
                return 0.0;
            }
            sin.atan2(a.dot(b)) / sin * cross.dot(normal)
        })
        .sum();
    0.5 * sum.abs()
}

/// The exact image of `scene` at `settings`' size (the seed and sample
/// counts do not matter: the answer is the limit), with primary hits from
/// `intersector`.
///
/// # Errors
/// When the closed form does not hold: the render is not direct light at
/// pixel centres (multisampling, motion blur, reflection, transparency,
/// textures, bloom or interpolated normals), the scene has another light
/// than one parallelogram of one colour, a material with a highlight, or
/// surfaces in more than one plane, or a visible point does not see the
/// whole emitting side of the light above its horizon.
pub fn analytic_image<I: Intersector + ?Sized>(
    scene: &Scene,
    intersector: &I,
    settings: &RenderSettings,
) -> anyhow::Result<Image> {
    let name = &scene.name;
    let passes = Passes::for_render(scene, settings.samples_per_pixel);
    let extra = [
        (passes.multisample, "multisampling"),
        (passes.motion_blur, "motion blur"),
        (passes.reflection, "reflection"),
        (passes.transparency, "transparency"),
        (passes.textures, "textures"),
        (passes.bloom, "bloom"),
        (passes.normal_interpolation, "interpolated normals"),
    ];
    if let Some((_, what)) = extra.iter().find(|(on, _)| *on) {
        bail!("{name}: no closed form with {what}, only for direct light at pixel centres");
    }
    ensure!(
        passes.shading && passes.area_lights,
        "{name}: no closed form unless the scene is shaded and samples its area light"
    );
    let light = uniform_parallelogram(scene)?;
    if let Some(m) = scene.materials.iter().find(|m| m.ks != Vec3::ZERO) {
        bail!(
            "{name}: material {:?} has a highlight; the closed form is for diffuse surfaces",
            m.name
        );
    }
    one_plane(scene)?;
    let mut image = Image::new(settings.width, settings.height);
    for y in 0..settings.height {
        for x in 0..settings.width {
            let ray = scene.camera.ray(
                x as f32 + 0.5,
                y as f32 + 0.5,
                settings.width,
                settings.height,
            );
            image.pixels[(y * settings.width + x) as usize] =
                exact_pixel(scene, intersector, &light, &ray)
                    .map_err(|message| anyhow::anyhow!("{name}: pixel ({x}, {y}): {message}"))?;
        }
    }
    Ok(image)
}

/// The scene's one light, as a uniform one-colour parallelogram.
struct UniformLight {
    vertices: [DVec3; 4],
    normal: DVec3,
    two_sided: bool,
    radiance: Vec3,
}

fn uniform_parallelogram(scene: &Scene) -> anyhow::Result<UniformLight> {
    let name = &scene.name;
    let [light] = scene.lights.as_slice() else {
        bail!(
            "{name}: the closed form is for one light, the scene has {}",
            scene.lights.len()
        );
    };
    let Light::Parallelogram {
        corner,
        edge_u,
        edge_v,
        colors,
        two_sided,
    } = light
    else {
        bail!("{name}: the closed form is for a parallelogram light");
    };
    ensure!(
        colors.iter().all(|c| c == &colors[0]),
        "{name}: the closed form is for a light of one colour, not {colors:?}"
    );
    let (c, u, v) = (corner.as_dvec3(), edge_u.as_dvec3(), edge_v.as_dvec3());
    Ok(UniformLight {
        vertices: [c, c + u, c + u + v, c + v],
        normal: u.cross(v).normalize(),
        two_sided: *two_sided,
        radiance: colors[0],
    })
}

/// Checks that every vertex of the scene lies in the plane of its first
/// triangle, so that no surface can shadow another.
fn one_plane(scene: &Scene) -> anyhow::Result<()> {
    let mesh = &scene.mesh;
    ensure!(scene.moving.is_empty(), "{}: nothing may move", scene.name);
    let [a, b, c] = mesh.triangle(0).map(Vec3::as_dvec3);
    let normal = (b - a).cross(c - a).normalize();
    let extent = mesh.bounds().extent().length() as f64;
    let off = mesh
        .positions
        .iter()
        .map(|p| (p.as_dvec3() - a).dot(normal).abs())
        .fold(0.0, f64::max);
    ensure!(
        off <= 1e-6 * extent,
        "{}: the surfaces are not in one plane (a vertex is {off} off it), so they could shadow each other",
        scene.name
    );
    Ok(())
}

/// The converged value of the pixel whose camera ray is `ray`.
fn exact_pixel<I: Intersector + ?Sized>(
    scene: &Scene,
    intersector: &I,
    light: &UniformLight,
    ray: &Ray,
) -> Result<Vec3, String> {
    let Some(hit) = intersector.intersect(ray) else {
        return Ok(Vec3::ZERO);
    };
    let surface = SurfacePoint::new(&scene.mesh, ray, &hit);
    let kd = scene.materials[surface.material as usize].kd;
    let (point, normal) = (surface.position.as_dvec3(), surface.normal.as_dvec3());
    if light
        .vertices
        .iter()
        .any(|v| (*v - point).dot(normal) <= 0.0)
    {
        return Err("the light is not wholly above the surface's horizon".into());
    }
    let facing = (point - light.vertices[0]).dot(light.normal);
    if !(facing > 0.0 || light.two_sided && facing < 0.0) {
        return Err("the point is not in front of the light's emitting side".into());
    }
    let irradiance = polygon_irradiance(&light.vertices, point, normal);
    Ok(shading::ambient(kd) + kd * light.radiance * irradiance as f32)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::{BuildOptions, Bvh};

    /// The same integral by brute force: the midpoint rule over the
    /// parallelogram of `∫ cos θ cos θ' / r² dA`.
    fn quadrature(corner: DVec3, u: DVec3, v: DVec3, point: DVec3, normal: DVec3) -> f64 {
        let steps = 1000;
        let light_normal = u.cross(v).normalize();
        let area = u.cross(v).length();
        let mut sum = 0.0;
        for i in 0..steps {
            for j in 0..steps {
                let s = (i as f64 + 0.5) / steps as f64;
                let t = (j as f64 + 0.5) / steps as f64;
                let d = corner + s * u + t * v - point;
                let r2 = d.length_squared();
                let cos = d.dot(normal) / r2.sqrt();
                let cos_light = (-d).dot(light_normal).abs() / r2.sqrt();
                sum += cos * cos_light / r2;
            }
        }
        sum * area / (steps * steps) as f64
    }

    #[test]
    fn a_rectangle_over_a_corner_gives_the_textbook_configuration_factor() {
        // A differential area under one corner of a parallel a × b rectangle
        // at height c (Howell's catalogue of configuration factors): with
        // X = a/c, Y = b/c, F = (1/2π)[X/√(1+X²)·atan(Y/√(1+X²)) +
        // Y/√(1+Y²)·atan(X/√(1+Y²))], and E = π·F per unit radiance.
        let (a, b, c) = (0.7, 1.9, 1.3);
        let (x, y) = (a / c, b / c);
        let (sx, sy) = ((1.0f64 + x * x).sqrt(), (1.0f64 + y * y).sqrt());
        let factor = (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / std::f64::consts::TAU;
        let rectangle = [
            DVec3::new(0.0, 0.0, c),
            DVec3::new(a, 0.0, c),
            DVec3::new(a, b, c),
            DVec3::new(0.0, b, c),
        ];
        let e = polygon_irradiance(&rectangle, DVec3::ZERO, DVec3::Z);
        assert!((e - std::f64::consts::PI * factor).abs() < 1e-12, "{e}");
        // The order of the vertices does not matter.
        let mut reversed = rectangle;
        reversed.reverse();
        assert_eq!(polygon_irradiance(&reversed, DVec3::ZERO, DVec3::Z), e);
    }

    #[test]
    fn the_whole_sky_gives_pi_and_a_tilted_light_matches_quadrature() {
        let huge = 1e7;
        let sky = [
            DVec3::new(-huge, -huge, 1.0),
            DVec3::new(huge, -huge, 1.0),
            DVec3::new(huge, huge, 1.0),
            DVec3::new(-huge, huge, 1.0),
        ];
        let e = polygon_irradiance(&sky, DVec3::ZERO, DVec3::Z);
        assert!((e - std::f64::consts::PI).abs() < 1e-6, "{e}");
        // The analytic scene's light, seen from a point off to the side on
        // a slightly tilted surface.
        let (corner, u, v) = (
            DVec3::new(-0.5, -0.25, 1.0),
            DVec3::new(0.0, 0.5, 0.0),
            DVec3::new(1.0, 0.0, 0.2),
        );
        let (point, normal) = (
            DVec3::new(0.8, -0.6, 0.0),
            DVec3::new(0.1, 0.05, 1.0).normalize(),
        );
        let quad = [corner, corner + u, corner + u + v, corner + v];
        let exact = polygon_irradiance(&quad, point, normal);
        let brute = quadrature(corner, u, v, point, normal);
        // The midpoint rule's error falls as steps⁻²: about 1e-6 relative here.
        assert!(((exact - brute) / exact).abs() < 1e-5, "{exact} vs {brute}");
    }

    #[test]
    fn scenes_without_a_closed_form_are_refused() {
        let analytic = crate::scene::load("analytic-area").unwrap();
        let bvh = Bvh::build(&analytic.mesh, &BuildOptions::sah());
        let settings = RenderSettings::square(8);
        assert!(analytic_image(&analytic, &bvh, &settings).is_ok());
        let refused = |scene: &Scene| {
            let bvh = Bvh::build(&scene.mesh, &BuildOptions::sah());
            analytic_image(scene, &bvh, &settings)
                .unwrap_err()
                .to_string()
        };
        let multisampled = RenderSettings {
            samples_per_pixel: Some(4),
            ..settings
        };
        let error = analytic_image(&analytic, &bvh, &multisampled).unwrap_err();
        assert!(error.to_string().contains("with multisampling"), "{error}");
        let cornell = crate::scene::load("cornell-area").unwrap();
        assert!(refused(&cornell).contains("with multisampling"));
        let mut coloured = analytic.clone();
        if let Light::Parallelogram { colors, .. } = &mut coloured.lights[0] {
            colors[2] = Vec3::ONE;
        }
        assert!(refused(&coloured).contains("a light of one colour"));
        let mut glossy = analytic.clone();
        glossy.materials[0].ks = Vec3::splat(0.5);
        assert!(refused(&glossy).contains("has a highlight"));
        // A light that dips below the plane: no longer above every horizon.
        let mut low = analytic.clone();
        if let Light::Parallelogram { corner, .. } = &mut low.lights[0] {
            corner.z = -0.1;
        }
        assert!(
            refused(&low).contains("not wholly above"),
            "{}",
            refused(&low)
        );
        // Facing away from the plane.
        let mut away = analytic.clone();
        if let Light::Parallelogram { edge_u, edge_v, .. } = &mut away.lights[0] {
            std::mem::swap(edge_u, edge_v);
        }
        assert!(refused(&away).contains("emitting side"));
    }
}
