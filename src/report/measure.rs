//! The measurements of one scene for the report: each backend's build and
//! render, the images, and the agreement of each of our builders with Embree.

use crate::backends::embree;
use crate::bvh::wide::WideBvh;
use crate::bvh::{BuildOptions, Bvh};
use crate::check::compare::{CompareSummary, compare};
use crate::render::image::Image;
use crate::render::pipeline::Passes;
use crate::render::{RenderSettings, render};
use crate::scene::Scene;
use crate::trace::Intersector;
use raycheck_reference::{BuildQuality, Device, Scene as EmbreeScene, SceneOptions};
use serde::Serialize;
use std::time::Instant;

/// One backend's row of the course-report table.
#[derive(Clone, Debug, Serialize)]
pub struct BackendRow {
    pub backend: String,
    pub build_ms: f64,
    pub render_ms: f64,
    pub levels: Option<u32>,
    /// Exact for ours; for Embree an upper bound: its leaves hold up to a
    /// number of 4-triangle blocks.
    pub max_leaf_triangles: String,
    pub nodes: Option<u64>,
    pub bytes: Option<u64>,
    pub sah_cost: Option<f64>,
}

/// Everything the report says about one scene.
#[derive(Clone, Debug, Serialize)]
pub struct SceneMeasurements {
    pub scene: String,
    pub triangles: usize,
    pub features: Vec<String>,
    /// The render passes the scene runs (see `render::pipeline`).
    pub passes: String,
    pub resolution: u32,
    pub backends: Vec<BackendRow>,
    /// Agreement of each of our builders with Embree (ROBUST, MEDIUM).
    pub agreement: Vec<(String, CompareSummary)>,
    /// Pixels of our SAH render and Embree's render that differ at all.
    pub differing_pixels: usize,
    /// Largest per-channel difference between those two renders (linear).
    pub max_pixel_difference: f32,
    #[serde(skip)]
    pub ours_image: Image,
    #[serde(skip)]
    pub embree_image: Image,
}

impl SceneMeasurements {
    /// The row of the backend labelled `label`.
    pub fn backend(&self, label: &str) -> Option<&BackendRow> {
        self.backends.iter().find(|b| b.backend == label)
    }
}

/// The Embree configuration the report compares against.
pub const REFERENCE_OPTIONS: SceneOptions = SceneOptions {
    quality: BuildQuality::Medium,
    robust: true,
};

/// Embree's default configuration, timed beside the reference one.
pub const MEDIUM_OPTIONS: SceneOptions = SceneOptions {
    quality: BuildQuality::Medium,
    robust: false,
};

/// The backend label of our fast path, [`WideBvh`].
pub const FAST: &str = "ours, fast (4-wide)";

/// Builds, renders and compares `scene` on our two builders and on Embree.
pub fn measure_scene(
    scene: &Scene,
    device: &Device,
    resolution: u32,
    progress: &dyn Fn(&str),
) -> anyhow::Result<SceneMeasurements> {
    let settings = RenderSettings::square(resolution);
    let mut backends = Vec::new();
    let mut agreement = Vec::new();

    progress("Embree build");
    let reference = embree::build_scene(device, &scene.mesh, REFERENCE_OPTIONS)?;
    progress("Embree render");
    let (embree_image, row) = embree_row(scene, &reference, REFERENCE_OPTIONS, &settings)?;
    backends.push(row);
    progress("Embree MEDIUM");
    let medium = embree::build_scene(device, &scene.mesh, MEDIUM_OPTIONS)?;
    backends.push(embree_row(scene, &medium, MEDIUM_OPTIONS, &settings)?.1);
    drop(medium);

    let mut ours_image = Image::new(0, 0);
    for (label, options) in [
        ("median", BuildOptions::median()),
        ("SAH", BuildOptions::sah()),
    ] {
        progress(&format!("{label} build"));
        let bvh = Bvh::build(&scene.mesh, &options);
        let stats = bvh.stats();
        progress(&format!("{label} render"));
        let (image, render_ms) = timed_render(scene, &bvh, &settings);
        backends.push(BackendRow {
            backend: format!("ours, {label}"),
            build_ms: stats.build_time.as_secs_f64() * 1e3,
            render_ms,
            levels: Some(stats.levels),
            max_leaf_triangles: stats.max_leaf_triangles.to_string(),
            nodes: Some(stats.nodes as u64),
            bytes: Some(stats.bytes as u64),
            sah_cost: Some(stats.sah_cost),
        });
        progress(&format!("{label} check"));
        agreement.push((
            label.to_string(),
            compare(scene, &bvh, &reference, resolution),
        ));
        ours_image = image;
    }

    progress("fast build and render");
    let fast = WideBvh::build(&scene.mesh);
    let stats = fast.stats();
    let (_, render_ms) = timed_render(scene, &fast, &settings);
    backends.push(BackendRow {
        backend: FAST.into(),
        build_ms: fast.build_time().as_secs_f64() * 1e3,
        render_ms,
        levels: Some(stats.levels),
        max_leaf_triangles: stats.max_leaf_triangles.to_string(),
        nodes: Some(stats.nodes as u64),
        bytes: Some(fast.bytes() as u64),
        sah_cost: None,
    });

    let (differing_pixels, max_pixel_difference) = image_difference(&ours_image, &embree_image);
    Ok(SceneMeasurements {
        scene: scene.name.clone(),
        triangles: scene.mesh.triangle_count(),
        features: scene.features.iter().map(|f| f.to_string()).collect(),
        passes: Passes::for_scene(scene).to_string(),
        resolution,
        backends,
        agreement,
        differing_pixels,
        max_pixel_difference,
        ours_image,
        embree_image,
    })
}

/// The row of one Embree scene, and its render.
fn embree_row(
    scene: &Scene,
    reference: &EmbreeScene,
    options: SceneOptions,
    settings: &RenderSettings,
) -> anyhow::Result<(Image, BackendRow)> {
    let threads = rayon::current_num_threads();
    let stats = embree::bvh_statistics(Some(threads), &scene.mesh, options)?;
    let (image, render_ms) = timed_render(scene, reference, settings);
    let row = BackendRow {
        backend: embree_label(options),
        build_ms: reference.build_time().as_secs_f64() * 1e3,
        render_ms,
        levels: Some(stats.depth),
        max_leaf_triangles: format!(
            "≤ {} ({})",
            4 * stats.leaf_histogram_percent.len(),
            stats.bvh_type
        ),
        nodes: Some((stats.inner_nodes() + stats.leaf_nodes()) as u64),
        bytes: Some(stats.bytes as u64),
        sah_cost: Some(stats.sah_cost),
    };
    Ok((image, row))
}

/// The backend label of Embree with `options`, e.g.
/// `Embree 4.4 (MEDIUM, ROBUST)`.
pub fn embree_label(options: SceneOptions) -> String {
    let quality = format!("{:?}", options.quality).to_uppercase();
    let robust = if options.robust { ", ROBUST" } else { "" };
    format!("Embree 4.4 ({quality}{robust})")
}

fn timed_render<I: Intersector + ?Sized>(
    scene: &Scene,
    intersector: &I,
    settings: &RenderSettings,
) -> (Image, f64) {
    let start = Instant::now();
    let image = render(scene, intersector, settings);
    (image, start.elapsed().as_secs_f64() * 1e3)
}

/// How many pixels differ, and by how much at most (per channel).
pub fn image_difference(a: &Image, b: &Image) -> (usize, f32) {
    a.pixels
        .iter()
        .zip(&b.pixels)
        .map(|(p, q)| (*p - *q).abs().max_element())
        .filter(|d| *d > 0.0)
        .fold((0, 0.0f32), |(n, m), d| (n + 1, m.max(d)))
}
