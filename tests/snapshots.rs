//! One pinned image per feature render (insta binary snapshots of the PNG,
//! stored beside the `.snap` files in `tests/snapshots/`). On a mismatch
//! the actual image and a difference image are written to
//! `target/snapshot-diffs/` before insta reports the failure.

use super::features::{FEATURE_SCENES, settings};
use image::ImageEncoder;
use raycheck::bvh::BuildOptions;
use raycheck::check::layered::build_bvhs;
use raycheck::parallel::thread_pool;
use raycheck::render::render_layers;
use raycheck::scene;
use std::path::{Path, PathBuf};

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
    let snapshot = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(format!("tests/snapshots/main__snapshots__{name}.snap.png"));
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
    let pool = thread_pool(None).unwrap();
    let settings = settings();
    for name in FEATURE_SCENES {
        let scene = scene::load(name).unwrap();
        let bvhs = build_bvhs(&scene, &BuildOptions::sah());
        let layers: Vec<&_> = bvhs.iter().collect();
        let image = pool.install(|| render_layers(&scene, &layers, &settings));
        let rgb = image.to_srgb8();
        if let Some(dir) = write_failure(name, image.width, image.height, &rgb) {
            eprintln!("{name}: actual and difference images in {}", dir.display());
        }
        insta::assert_binary_snapshot!(
            &format!("{name}.png"),
            png_bytes(image.width, image.height, &rgb)
        );
    }
}
