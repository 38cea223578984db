//! Every feature scene renders on our BVH and on Embree through the same
//! code: every query is checked, the two images agree, and the render is the
//! same for any thread count; each render is pinned by an insta binary
//! snapshot of its PNG (beside the `.snap` files in `tests/snapshots/`). On
//! a mismatch the actual image and a difference image are written to
//! `target/snapshot-diffs/` before insta reports the failure.

use crate::support::workers;
use image::ImageEncoder;
use raycheck::backends::ours::OURS;
use raycheck::check::layered::{LayeredBackend, render_checked};
use raycheck::render::RenderSettings;
use raycheck::render::image::Image;
use raycheck::render::pipeline::Passes;
use raycheck::report::gallery::gallery_views;
use raycheck::report::measure::REFERENCE;
use raycheck::results::Verdicts;
use raycheck::results::pixels::compare_renders;
use raycheck::scene::{self, Scene};
use std::path::{Path, PathBuf};

/// The scenes that exercise the features beyond the plain ones: those
/// of the report's gallery.
fn feature_scenes() -> Vec<&'static str> {
    gallery_views(48).map(|(name, _)| name).to_vec()
}

/// Small enough for the suite, large enough to show every feature.
fn settings() -> RenderSettings {
    RenderSettings {
        seed: 1,
        ..RenderSettings::square(48)
    }
}

#[test]
fn every_feature_render_is_checked_and_agrees_with_embree() {
    let pool = workers(None);
    let settings = settings();
    for name in feature_scenes() {
        let scene = scene::load(name).unwrap();
        let backends = [OURS, REFERENCE]
            .map(|backend| LayeredBackend::build(&backend, &scene, pool.build_context()).unwrap());
        let [ours_backend, embree_backend] = &backends;
        let checked = pool.install(|| render_checked(&scene, &backends, &settings));
        let v = Verdicts::judge_layers(&scene, &checked.logs);
        let ours_tally = &v.backends[0];
        assert_eq!(ours_tally.wrong, 0, "{name}: {v:?}");
        assert_eq!(ours_tally.t_off, 0, "{name}: {v:?}");
        let queries: u64 = checked.logs.iter().map(|l| l.intersect_queries).sum();
        assert!(queries >= 48 * 48, "{name}: only {queries} queries");
        let lit = checked
            .image
            .pixels
            .iter()
            .filter(|p| p.max_element() > 0.02);
        assert!(lit.count() > 48 * 48 / 10, "{name} is mostly black");

        // A pixel may differ beyond the f32 bound only where one of its
        // own rays was answered differently and the referee found both
        // answers admissible.
        let (ours_layers, embree_layers) =
            (ours_backend.intersectors(), embree_backend.intersectors());
        let (difference, _) =
            pool.install(|| compare_renders(&scene, &ours_layers, &embree_layers, &settings));
        assert_eq!(
            (difference.first_wrong, difference.unexplained),
            (0, 0),
            "{name}: {difference:?}"
        );
        assert!(
            difference.beyond_bound <= 48 * 48 / 100,
            "{name}: {difference:?}"
        );
    }
}

/// Our tracer over every layer of `scene`.
fn ours(scene: &Scene) -> LayeredBackend {
    LayeredBackend::build(&OURS, scene, workers(Some(1)).build_context()).unwrap()
}

fn bits(img: &Image) -> Vec<u32> {
    img.pixels
        .iter()
        .flat_map(|p| p.to_array().map(f32::to_bits))
        .collect()
}

#[test]
fn feature_renders_are_identical_on_one_and_two_threads() {
    let settings = settings();
    for name in feature_scenes() {
        let scene = scene::load(name).unwrap();
        let ours = ours(&scene);
        let [one, two] =
            [1, 2].map(|threads| workers(Some(threads)).install(|| ours.render(&scene, &settings)));
        assert_eq!(bits(&one), bits(&two), "{name}");
        let other_seed = RenderSettings {
            seed: 2,
            ..settings
        };
        let reseeded = workers(Some(2)).install(|| ours.render(&scene, &other_seed));
        let sampled = Passes::for_scene(&scene);
        let random = sampled.samples_per_pixel > 1 || sampled.area_lights || sampled.glossy;
        assert_eq!(bits(&one) != bits(&reseeded), random, "{name}: seed use");
    }
}

fn png_bytes(width: u32, height: u32, rgb: &[u8]) -> Vec<u8> {
    let mut bytes = Vec::new();
    image::codecs::png::PngEncoder::new(&mut bytes)
        .write_image(rgb, width, height, image::ExtendedColorType::Rgb8)
        .unwrap();
    bytes
}

/// Writes the actual image and |actual - expected| (amplified 8×) when the
/// committed snapshot differs; returns where.
fn write_failure(name: &str, width: u32, height: u32, actual: &[u8]) -> Option<PathBuf> {
    let snapshot =
        Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("tests/snapshots/{name}.snap.png"));
    let expected = image::open(&snapshot).ok()?.to_rgb8();
    if expected.dimensions() == (width, height) && expected.as_raw() == actual {
        return None;
    }
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/snapshot-diffs");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join(format!("{name}.actual.png")),
        png_bytes(width, height, actual),
    )
    .unwrap();
    if expected.dimensions() == (width, height) {
        let diff: Vec<u8> = actual
            .iter()
            .zip(expected.as_raw())
            .map(|(&a, &e)| a.abs_diff(e).saturating_mul(8))
            .collect();
        std::fs::write(
            dir.join(format!("{name}.diff.png")),
            png_bytes(width, height, &diff),
        )
        .unwrap();
    }
    Some(dir)
}

#[test]
fn feature_renders_match_their_snapshots() {
    let pool = workers(None);
    let settings = settings();
    for name in feature_scenes() {
        let scene = scene::load(name).unwrap();
        let image = pool.install(|| ours(&scene).render(&scene, &settings));
        assert_png_snapshot(name, &image);
    }
}

/// Pins `image`'s PNG as the insta binary snapshot `tests/snapshots/{name}.snap.png`,
/// writing the actual and difference images first when it differs.
pub fn assert_png_snapshot(name: &str, image: &Image) {
    let rgb = image.to_srgb8();
    if let Some(dir) = write_failure(name, image.width, image.height, &rgb) {
        eprintln!("{name}: actual and difference images in {}", dir.display());
    }
    // The same names whether this file runs inside `main` or alone.
    let mut snapshot_settings = insta::Settings::clone_current();
    snapshot_settings.set_prepend_module_to_snapshot(false);
    snapshot_settings.bind(|| {
        insta::assert_binary_snapshot!(
            &format!("{name}.png"),
            png_bytes(image.width, image.height, &rgb)
        )
    });
}
