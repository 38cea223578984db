//! Renders whose right answer is known in closed form.

use glam::Vec3;
use raycheck::bvh::{BuildOptions, Bvh};
use raycheck::fit::fit_log_log;
use raycheck::geometry::TriangleMesh;
use raycheck::render::area_lights;
use raycheck::render::sampling::{SampleStream, Sampler};
use raycheck::render::shading::{self, AMBIENT};
use raycheck::render::surface::SurfacePoint;
use raycheck::render::{RenderSettings, render};
use raycheck::scene::{self, Camera, Feature, Light, Material, RenderParams, Scene};
use raycheck::sweep::analytic::analytic_image;
use raycheck::sweep::metrics::{REL_MSE_EPSILON, rel_mse};
use raycheck::trace::Intersector;

/// A square in the plane y = 0 of half-size `half`, facing +y.
fn plane(half: f32, y: f32, material: u32) -> TriangleMesh {
    TriangleMesh {
        positions: vec![
            Vec3::new(-half, y, -half),
            Vec3::new(half, y, -half),
            Vec3::new(half, y, half),
            Vec3::new(-half, y, half),
        ],
        indices: vec![[0, 2, 1], [0, 3, 2]],
        materials: vec![material; 2],
        ..Default::default()
    }
}

fn scene(mesh: TriangleMesh, materials: Vec<Material>, light: Light, camera: Camera) -> Scene {
    Scene {
        name: "known".into(),
        description: String::new(),
        mesh,
        materials,
        camera,
        lights: vec![light],
        features: vec![Feature::Shading, Feature::HardShadows, Feature::Reflection],
        source: Default::default(),
        moving: Vec::new(),
        textures: Vec::new(),
        params: RenderParams::default(),
    }
}

#[test]
fn a_diffuse_plane_under_a_point_light_follows_the_phong_formula() {
    let kd = Vec3::new(0.6, 0.5, 0.4);
    let light_position = Vec3::new(0.3, 2.0, -0.2);
    let color = Vec3::new(3.0, 2.5, 2.0);
    let camera = Camera {
        eye: Vec3::new(0.0, 5.0, 0.0),
        look_at: Vec3::ZERO,
        up: Vec3::Z,
        fov_y_deg: 40.0,
    };
    let material = Material {
        kd,
        ..Material::default()
    };
    let s = scene(
        plane(10.0, 0.0, 0),
        vec![material],
        Light::Point {
            position: light_position,
            color,
        },
        camera,
    );
    let settings = RenderSettings::square(24);
    let image = render(&s, &Bvh::build(&s.mesh, &BuildOptions::sah()), &settings);
    for y in 0..24 {
        for x in 0..24 {
            let ray = camera.ray(x as f32 + 0.5, y as f32 + 0.5, 24, 24);
            let t = -ray.origin.y / ray.dir.y;
            let p = ray.at(t);
            let to_light = light_position - p;
            let cos = to_light.normalize().y;
            let expected = AMBIENT * kd + kd * cos * color / to_light.length_squared();
            let got = image.get(x, y);
            let error = ((got - expected) / expected).abs().max_element();
            assert!(error < 1e-4, "pixel ({x}, {y}): {got} vs {expected}");
        }
    }
}

#[test]
fn a_perfect_mirror_shows_the_colour_it_faces() {
    // A camera looks straight down at a perfect mirror; above the camera
    // hangs an unlit red plane, seen in the mirror. With shading off every
    // surface shows its diffuse colour, so the mirror shows pure red.
    let camera = Camera {
        eye: Vec3::new(0.0, 1.0, 0.0),
        look_at: Vec3::ZERO,
        up: Vec3::Z,
        fov_y_deg: 30.0,
    };
    let mirror = Material {
        kd: Vec3::ZERO,
        mirror: Vec3::ONE,
        ..Material::default()
    };
    let red = Material {
        kd: Vec3::X,
        ..Material::default()
    };
    let mut mesh = plane(5.0, 0.0, 0);
    // The red plane faces down; it lies behind the camera, so only the
    // mirror shows it.
    mesh.append(&plane(5.0, 3.0, 0), 1);
    let mut s = scene(
        mesh,
        vec![mirror, red],
        Light::Point {
            position: Vec3::new(0.0, 2.0, 0.0),
            color: Vec3::ONE,
        },
        camera,
    );
    s.features = vec![Feature::Reflection];
    let image = render(
        &s,
        &Bvh::build(&s.mesh, &BuildOptions::sah()),
        &RenderSettings::square(16),
    );
    assert!(
        image.pixels.iter().all(|&p| p == Vec3::X),
        "{:?}",
        &image.pixels[..4]
    );
}

#[test]
fn the_visible_fraction_of_an_area_light_converges_to_the_analytic_value() {
    // A unit square light at height 2 over the origin; a blocker at height 1
    // covers x < 0.1 at height 1. From the origin, the ray to the light
    // point (x, z) crosses height 1 at (x/2, z/2), so it is blocked exactly
    // when x < 0.2: the visible fraction is (0.5 - 0.2) / 1 = 0.3.
    let light = Light::Parallelogram {
        corner: Vec3::new(-0.5, 2.0, -0.5),
        edge_u: Vec3::X,
        edge_v: Vec3::Z,
        colors: [Vec3::ONE; 4],
        two_sided: false,
    };
    let blocker = TriangleMesh {
        positions: vec![
            Vec3::new(-5.0, 1.0, -5.0),
            Vec3::new(0.1, 1.0, -5.0),
            Vec3::new(0.1, 1.0, 5.0),
            Vec3::new(-5.0, 1.0, 5.0),
        ],
        indices: vec![[0, 1, 2], [0, 2, 3]],
        materials: vec![0; 2],
        ..Default::default()
    };
    let bvh = Bvh::build(&blocker, &BuildOptions::sah());
    let origin = Vec3::ZERO;
    let fraction = |n: u32, seed: u64| {
        let mut stream = SampleStream::new(seed, 0, 0);
        let visible = (0..n)
            .filter(|&i| {
                let p =
                    area_lights::sample(&light, i, n, Sampler::Stratified, &mut stream).position;
                !bvh.occluded(&raycheck::geometry::Ray::segment(
                    origin,
                    p - origin,
                    0.0,
                    1.0,
                ))
            })
            .count();
        visible as f64 / n as f64
    };
    let mean_error = |n: u32| {
        (0..8)
            .map(|seed| (fraction(n, seed) - 0.3).abs())
            .sum::<f64>()
            / 8.0
    };
    let (coarse, fine) = (mean_error(16), mean_error(1024));
    assert!(fine < 0.01, "1024 samples: error {fine}");
    assert!(
        fine < coarse,
        "error grows with samples: {coarse} -> {fine}"
    );
}

#[test]
fn with_the_light_facing_down_the_ceiling_gets_no_direct_light() {
    // cornell-area's light hangs 0.8 mm under the ceiling and 0.3 mm under
    // the ceiling's light quad, emitting downwards. Looking up at it from
    // above the blocks, every pixel is ceiling or light quad: both are above
    // the light's plane, so each shows its ambient term alone, bit for bit.
    let mut scene = scene::load("cornell-area").unwrap();
    scene.camera = Camera {
        eye: Vec3::new(278.0, 500.0, 279.5),
        look_at: Vec3::new(278.0, 548.8, 279.5),
        up: Vec3::Z,
        fov_y_deg: 120.0,
    };
    let ambient = |name: &str| {
        let material = scene.materials.iter().find(|m| m.name == name).unwrap();
        shading::ambient(material.kd)
    };
    let (ceiling, quad) = (ambient("white"), ambient("light"));
    let bvh = Bvh::build(&scene.mesh, &BuildOptions::sah());
    // One (jittered) camera sample per pixel: no pixel mixes two surfaces.
    let settings = RenderSettings {
        samples_per_pixel: Some(1),
        ..RenderSettings::square(32)
    };
    let image = render(&scene, &bvh, &settings);
    let on_quad = image.pixels.iter().filter(|&&p| p == quad).count();
    assert!(
        image.pixels.iter().all(|&p| p == ceiling || p == quad),
        "{:?}",
        image.pixels.iter().find(|&&p| p != ceiling && p != quad)
    );
    assert!(
        on_quad > 32 * 32 / 10 && on_quad < 32 * 32 * 9 / 10,
        "{on_quad}"
    );
    // Made two-sided, the same light lights the ceiling and the quad from
    // below: most pixels get direct light (the ceiling's are at grazing
    // angles, and the quad shadows some of them from the light).
    if let Light::Parallelogram { two_sided, .. } = &mut scene.lights[0] {
        *two_sided = true;
    }
    let flooded = render(&scene, &bvh, &settings);
    let lit = (0..image.pixels.len())
        .filter(|&i| flooded.pixels[i].x > image.pixels[i].x)
        .count();
    assert!(lit > 32 * 32 / 2, "only {lit} pixels lit from below");
}

/// A bound on the expected relMSE of a render of the analytic scene with
/// `n` light samples per pixel against its exact image `exact`, from the
/// geometry alone.
///
/// A pixel is `ambient + kd·(1/n)·Σⱼ g(yⱼ)`, with `g(y) = L·A·cos θ·cos θ'/r²`
/// for the light point y (uniform over the light: its expectation is the
/// exact pixel), so its variance is `kd²/n²·Σⱼ Var g(yⱼ)`. With w = y − x,
/// `g = L·A·(n·w)(−n'·w)/|w|⁴`, whose gradient in y is at most
/// `L·A·(1 + 1 + 4)/|w|³ ≤ 6·L·A/d³`, d the point's distance to the light's
/// plane. Any two points of a stratum of the k×k grid are joined by a path
/// of length `(|u| + |v|)/k` (along each edge in turn), so g spans at most
/// `6·L·A·(|u| + |v|)/(k·d³)` on it, and a variable confined to a range w has
/// variance at most w²/4 (Popoviciu). Stratified (k = √n, one sample per
/// stratum) that gives `Var ≤ kd²·G²/(4n²)` with G = 6·L·A·(|u| + |v|)/d³;
/// independent samples (k = 1 each) give `kd²·G²/(4n)`. The expected relMSE
/// is at most the mean over pixels and channels of `Var/(R² + 0.01)`.
fn rel_mse_bound(
    scene: &Scene,
    bvh: &Bvh,
    exact: &raycheck::render::image::Image,
    n: u32,
    sampler: Sampler,
) -> f64 {
    let Light::Parallelogram {
        corner,
        edge_u,
        edge_v,
        colors,
        ..
    } = &scene.lights[0]
    else {
        panic!("the analytic scene has one parallelogram light");
    };
    let light_normal = edge_u.cross(*edge_v).normalize().as_dvec3();
    let (radiance, area) = (colors[0].x as f64, scene.lights[0].area() as f64);
    let path = (edge_u.length() + edge_v.length()) as f64;
    let strata = match sampler {
        Sampler::Stratified => n as f64,
        Sampler::Independent => 1.0,
    };
    let mut sum = 0.0;
    for y in 0..exact.height {
        for x in 0..exact.width {
            let ray = scene
                .camera
                .ray(x as f32 + 0.5, y as f32 + 0.5, exact.width, exact.height);
            let hit = bvh.intersect(&ray).unwrap();
            let surface = SurfacePoint::new(&scene.mesh, &ray, &hit);
            let kd = scene.materials[surface.material as usize].kd.x as f64;
            let d = (surface.position.as_dvec3() - corner.as_dvec3())
                .dot(light_normal)
                .abs();
            let gradient_span = 6.0 * radiance * area * path / d.powi(3);
            let variance = kd * kd * gradient_span.powi(2) / (4.0 * n as f64 * strata);
            for r in exact.get(x, y).to_array() {
                sum += variance / ((r as f64).powi(2) + REL_MSE_EPSILON);
            }
        }
    }
    sum / (3 * exact.pixels.len()) as f64
}

#[test]
fn the_analytic_scene_converges_to_its_exact_image_without_a_bias_floor() {
    let scene = scene::load("analytic-area").unwrap();
    let bvh = Bvh::build(&scene.mesh, &BuildOptions::sah());
    let settings = RenderSettings::square(32);
    let exact = analytic_image(&scene, &bvh, &settings).unwrap();
    let counts = [1u32, 4, 16, 64, 256, 1024];
    let seeds = 0..4u64;
    for sampler in [Sampler::Stratified, Sampler::Independent] {
        let mut points = Vec::new();
        let mut means = Vec::new();
        for &n in &counts {
            let mut sampled = scene.clone();
            sampled.params.light_samples = n;
            let errors: Vec<f64> = seeds
                .clone()
                .map(|seed| {
                    let settings = RenderSettings {
                        seed,
                        sampler,
                        ..settings
                    };
                    rel_mse(&render(&sampled, &bvh, &settings), &exact).unwrap()
                })
                .collect();
            points.extend(errors.iter().map(|&e| (n as f64, e)));
            means.push(errors.iter().sum::<f64>() / errors.len() as f64);
            let bound = rel_mse_bound(&scene, &bvh, &exact, n, sampler);
            assert!(
                means[means.len() - 1] < bound,
                "{sampler:?}, {n} samples: relMSE {} above the bound {bound}",
                means[means.len() - 1]
            );
        }
        eprintln!("{sampler:?}: relMSE {means:?}");
        assert!(
            means.windows(2).all(|w| w[1] < w[0]),
            "{sampler:?}: the error does not fall with every count: {means:?}"
        );
        let fit = fit_log_log(&points, 0.95).unwrap();
        eprintln!("{sampler:?}: {fit:?}");
        match sampler {
            // Independent samples: the variance of a mean of n is exactly
            // σ²/n, so the expected relMSE goes as n⁻¹.
            Sampler::Independent => {
                assert!(fit.slope_low <= -1.0 && -1.0 <= fit.slope_high, "{fit:?}")
            }
            // Jittered samples of a smooth integrand: n⁻² (the bound above);
            // at the smallest counts the strata are still coarse.
            Sampler::Stratified => assert!(fit.slope_high < -1.5, "{fit:?}"),
        }
    }
}
