//! The measurements of one scene for the report: each backend's build and
//! render (warmed up once, then medians of several runs), the images, and
//! the agreement of every backend on the compare ray sets.

use crate::backends::{self, BackendName, EMBREE_MEDIUM, EMBREE_ROBUST, OurBuilder};
use crate::bvh::Bvh;
use crate::bvh::wide::WideBvh;
use crate::check::layered::LayeredBackend;
use crate::perf::measure::Stat;
use crate::render::image::Image;
use crate::render::pipeline::Passes;
use crate::render::profile::{RenderProfile, profile};
use crate::render::{RenderSettings, render};
use crate::results::pixels::{PixelDifference, compare_renders};
use crate::results::{CompareSummary, compare_scene};
use crate::scene::Scene;
use raycheck_reference::Device;
use serde::Serialize;
use std::time::Instant;

/// The backends of the course table, in its order.
pub const COURSE_BACKENDS: [BackendName; 5] = [
    BackendName::Ours(OurBuilder::Wide),
    BackendName::Ours(OurBuilder::Sah),
    BackendName::Ours(OurBuilder::Median),
    BackendName::Embree(EMBREE_MEDIUM),
    BackendName::Embree(EMBREE_ROBUST),
];

/// The backends whose render time the report splits.
pub const PROFILED: [BackendName; 3] = [
    BackendName::Ours(OurBuilder::Wide),
    BackendName::Embree(EMBREE_MEDIUM),
    BackendName::Embree(EMBREE_ROBUST),
];

/// The backend whose render the report shows beside Embree's.
pub const OURS: BackendName = BackendName::Ours(OurBuilder::Wide);

/// The Embree configuration the report checks ours against.
pub const REFERENCE: BackendName = BackendName::Embree(EMBREE_ROBUST);

/// One backend's row of the course-report table.
#[derive(Clone, Debug, Serialize)]
pub struct BackendRow {
    pub backend: String,
    pub build_ms: Stat,
    pub render_ms: Stat,
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
    /// Runs timed per backend after the warm-up.
    pub runs: usize,
    pub backends: Vec<BackendRow>,
    /// Every course backend on the compare ray sets, judged exactly.
    pub agreement: CompareSummary,
    /// Our render against Embree's, pixel by pixel.
    pub pixels: PixelDifference,
    /// Where the render time of ours and of Embree (MEDIUM, and ROBUST)
    /// goes, after the timed runs.
    pub profiles: Vec<(String, RenderProfile)>,
    #[serde(skip)]
    pub ours_image: Image,
    #[serde(skip)]
    pub embree_image: Image,
    /// Where and how much the two renders differ (see
    /// [`compare_renders`]).
    #[serde(skip)]
    pub difference_image: Image,
}

impl SceneMeasurements {
    /// The row of the backend named `name`.
    pub fn backend(&self, name: &str) -> Option<&BackendRow> {
        self.backends.iter().find(|b| b.backend == name)
    }
}

/// Builds, renders and compares `scene` on every course backend: one
/// warm-up build and render each, then `runs` timed builds and renders,
/// backend after backend within each run.
pub fn measure_scene(
    scene: &Scene,
    device: &Device,
    resolution: u32,
    runs: usize,
    progress: &dyn Fn(&str),
) -> anyhow::Result<SceneMeasurements> {
    let settings = RenderSettings::square(resolution);
    let runs = runs.max(1);
    let (mut ours_image, mut embree_image) = (None, None);
    for name in COURSE_BACKENDS {
        progress(&format!("{name}: warm-up"));
        let backend = name.build(&scene.mesh, device)?;
        let image = render(scene, backend.as_ref(), &settings);
        if name == OURS {
            ours_image = Some(image);
        } else if name == REFERENCE {
            embree_image = Some(image);
        }
    }
    let (Some(ours_image), Some(embree_image)) = (ours_image, embree_image) else {
        anyhow::bail!("the course backends must include {OURS} and {REFERENCE}");
    };
    let mut build_ms = vec![Vec::new(); COURSE_BACKENDS.len()];
    let mut render_ms = vec![Vec::new(); COURSE_BACKENDS.len()];
    for run in 0..runs {
        progress(&format!("timed run {} of {runs}", run + 1));
        for (i, name) in COURSE_BACKENDS.iter().enumerate() {
            let backend = name.build(&scene.mesh, device)?;
            build_ms[i].push(backend.build_time().as_secs_f64() * 1e3);
            let start = Instant::now();
            std::hint::black_box(render(scene, backend.as_ref(), &settings));
            render_ms[i].push(start.elapsed().as_secs_f64() * 1e3);
        }
    }
    let mut backends = Vec::new();
    for (i, name) in COURSE_BACKENDS.iter().enumerate() {
        backends.push(BackendRow {
            build_ms: Stat::of(build_ms[i].clone()),
            render_ms: Stat::of(render_ms[i].clone()),
            ..tree_statistics(*name, scene)?
        });
    }
    progress("where render time goes");
    let mut profiles = Vec::new();
    for name in PROFILED {
        let backend = LayeredBackend::build(name, scene, device)?;
        let profile = profile(scene, &backend.intersectors(), &settings);
        profiles.push((name.to_string(), profile));
    }
    progress("agreement");
    let agreement = compare_scene(scene, &COURSE_BACKENDS, device, resolution)?;
    progress("ours against Embree, pixel by pixel");
    let ours = LayeredBackend::build(OURS, scene, device)?;
    let reference = LayeredBackend::build(REFERENCE, scene, device)?;
    let (pixels, difference_image) = compare_renders(
        scene,
        &ours.intersectors(),
        &reference.intersectors(),
        &settings,
    );
    Ok(SceneMeasurements {
        scene: scene.name.clone(),
        triangles: scene.mesh.triangle_count(),
        features: scene.features.iter().map(|f| f.to_string()).collect(),
        passes: Passes::for_scene(scene).to_string(),
        resolution,
        runs,
        backends,
        agreement,
        pixels,
        profiles,
        ours_image,
        embree_image,
        difference_image,
    })
}

/// The course table's tree columns of one backend, with empty timings;
/// "n/a" for a third-party crate, whose tree the harness does not read.
fn tree_statistics(name: BackendName, scene: &Scene) -> anyhow::Result<BackendRow> {
    let row = |levels, max_leaf_triangles: String, nodes, bytes, sah_cost| BackendRow {
        backend: name.to_string(),
        build_ms: Stat::default(),
        render_ms: Stat::default(),
        levels: Some(levels),
        max_leaf_triangles,
        nodes: Some(nodes as u64),
        bytes: Some(bytes as u64),
        sah_cost,
    };
    Ok(match name {
        BackendName::Ours(builder) => match builder.binary_options() {
            None => {
                let bvh = WideBvh::build(&scene.mesh);
                let stats = bvh.stats();
                let max_leaf = stats.max_leaf_triangles.to_string();
                row(stats.levels, max_leaf, stats.nodes, bvh.bytes(), None)
            }
            Some(options) => {
                let stats = *Bvh::build(&scene.mesh, &options).stats();
                let max_leaf = stats.max_leaf_triangles.to_string();
                row(
                    stats.levels,
                    max_leaf,
                    stats.nodes,
                    stats.bytes,
                    Some(stats.sah_cost),
                )
            }
        },
        BackendName::Embree(options) => {
            let threads = rayon::current_num_threads();
            let stats = backends::embree::bvh_statistics(Some(threads), &scene.mesh, options)?;
            let max_leaf = format!(
                "≤ {} ({})",
                4 * stats.leaf_histogram_percent.len(),
                stats.bvh_type
            );
            let nodes = stats.inner_nodes() + stats.leaf_nodes();
            row(
                stats.depth,
                max_leaf,
                nodes,
                stats.bytes,
                Some(stats.sah_cost),
            )
        }
        BackendName::Obvhs | BackendName::BvhCrate | BackendName::Parry3d => BackendRow {
            backend: name.to_string(),
            build_ms: Stat::default(),
            render_ms: Stat::default(),
            levels: None,
            max_leaf_triangles: "n/a".into(),
            nodes: None,
            bytes: None,
            sah_cost: None,
        },
    })
}
