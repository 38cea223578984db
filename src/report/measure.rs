//! The measurements of one scene for the report: each backend's build and
//! render (warmed up once, then medians of several runs), the images, and
//! the agreement of every backend on the compare ray sets.

use crate::backends::embree::{EMBREE, EMBREE_ROBUST};
use crate::backends::ours::OURS;
use crate::backends::{BackendName, Group};
use crate::check::layered::LayeredBackend;
use crate::parallel::Workers;
use crate::perf::measure::{Stat, median};
use crate::render::image::Image;
use crate::render::pipeline::Passes;
use crate::render::profile::{RenderProfile, profile};
use crate::render::{RenderSettings, render};
use crate::results::meta::load_average;
use crate::results::pixels::{PixelDifference, compare_renders};
use crate::results::{CompareSummary, compare_scene};
use crate::scene::Scene;
use serde::Serialize;
use std::time::Instant;

/// The backends of the course table, in its order: our trees, then
/// Embree default and robust.
pub fn course_backends() -> Vec<BackendName> {
    let mut names = BackendName::in_group(Group::Ours);
    names.extend([EMBREE, EMBREE_ROBUST]);
    names
}

/// The Embree configuration the report checks ours against.
pub const REFERENCE: BackendName = EMBREE_ROBUST;

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
    /// Renders per backend whose split each part of `profiles` is the
    /// median of.
    pub split_renders: usize,
    pub backends: Vec<BackendRow>,
    /// Every course backend on the compare ray sets, judged exactly.
    pub agreement: CompareSummary,
    /// Our render against Embree's, pixel by pixel.
    pub pixels: PixelDifference,
    /// Where the render time of ours and of Embree (MEDIUM, and ROBUST)
    /// goes, after the timed runs.
    pub profiles: Vec<(String, RenderProfile)>,
    /// The load averages as the split's renders ended, where the system
    /// tells. The workers hold one minute's near their count; a core or
    /// more above it, other work shared the cores, which slows queries
    /// timed among the shading more than the same queries replayed alone.
    pub split_load_average: Option<[f64; 3]>,
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
/// warm-up build and render each, then `runs.timed` timed builds and
/// renders, backend after backend within each run; then `runs.split`
/// renders of each default backend split into where their time goes, the
/// backends taking turns.
pub fn measure_scene(
    scene: &Scene,
    workers: &Workers,
    resolution: u32,
    runs: Runs,
    progress: &(dyn Fn(&str) + Sync),
) -> anyhow::Result<SceneMeasurements> {
    workers.install(|| measure_on_workers(scene, workers, resolution, runs, progress))
}

/// How many times a scene's renders are measured.
#[derive(Clone, Copy, Debug)]
pub struct Runs {
    /// Timed builds and renders per backend.
    pub timed: usize,
    /// Renders per backend split into where their time goes.
    pub split: usize,
}

fn measure_on_workers(
    scene: &Scene,
    workers: &Workers,
    resolution: u32,
    runs: Runs,
    progress: &(dyn Fn(&str) + Sync),
) -> anyhow::Result<SceneMeasurements> {
    let context = workers.build_context();
    let course = course_backends();
    let settings = RenderSettings::square(resolution);
    let (split_renders, runs) = (runs.split.max(1), runs.timed.max(1));
    let (mut ours_image, mut embree_image) = (None, None);
    for name in &course {
        progress(&format!("{name}: warm-up"));
        let backend = name.build(&scene.mesh, context)?;
        let image = render(scene, backend.as_ref(), &settings);
        if *name == OURS {
            ours_image = Some(image);
        } else if *name == REFERENCE {
            embree_image = Some(image);
        }
    }
    let (Some(ours_image), Some(embree_image)) = (ours_image, embree_image) else {
        anyhow::bail!("the course backends must include {OURS} and {REFERENCE}");
    };
    let mut build_ms = vec![Vec::new(); course.len()];
    let mut render_ms = vec![Vec::new(); course.len()];
    for run in 0..runs {
        progress(&format!("timed run {} of {runs}", run + 1));
        for (i, name) in course.iter().enumerate() {
            let backend = name.build(&scene.mesh, context)?;
            build_ms[i].push(backend.build_time().as_secs_f64() * 1e3);
            let start = Instant::now();
            std::hint::black_box(render(scene, backend.as_ref(), &settings));
            render_ms[i].push(start.elapsed().as_secs_f64() * 1e3);
        }
    }
    let mut backends = Vec::new();
    for (i, name) in course.iter().enumerate() {
        backends.push(BackendRow {
            build_ms: Stat::of(build_ms[i].clone()),
            render_ms: Stat::of(render_ms[i].clone()),
            ..tree_statistics(name, scene, workers)?
        });
    }
    progress("where render time goes");
    let names = BackendName::defaults();
    let profiled = names
        .iter()
        .map(|name| LayeredBackend::build(name, scene, context))
        .collect::<anyhow::Result<Vec<_>>>()?;
    // The backends take turns, as in the timed runs.
    let mut splits = vec![Vec::new(); profiled.len()];
    for _ in 0..split_renders {
        for (backend, split) in profiled.iter().zip(&mut splits) {
            split.push(profile(scene, &backend.intersectors(), &settings));
        }
    }
    let split_load_average = load_average();
    let profiles = names
        .iter()
        .zip(&splits)
        .map(|(name, runs)| (name.to_string(), median_split(runs)))
        .collect();
    progress("agreement");
    let agreement = compare_scene(scene, &course, workers, resolution)?;
    progress("ours against Embree, pixel by pixel");
    let ours = LayeredBackend::build(&OURS, scene, context)?;
    let reference = LayeredBackend::build(&REFERENCE, scene, context)?;
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
        split_renders,
        backends,
        agreement,
        pixels,
        profiles,
        split_load_average,
        ours_image,
        embree_image,
        difference_image,
    })
}

/// Each part's median over several splits of the same render: one
/// render's split moves by several percent from run to run.
fn median_split(runs: &[RenderProfile]) -> RenderProfile {
    let part = |of: fn(&RenderProfile) -> f64| median(runs.iter().map(of).collect());
    RenderProfile {
        total_ms: part(|p| p.total_ms),
        tracing_ms: part(|p| p.tracing_ms),
        shading_ms: part(|p| p.shading_ms),
        image_ms: part(|p| p.image_ms),
        queries: runs.first().map_or(0, |p| p.queries),
    }
}

/// The course table's tree columns of one backend, with empty timings;
/// "n/a" for a tree the harness does not read (a third-party crate's).
fn tree_statistics(
    name: &BackendName,
    scene: &Scene,
    workers: &Workers,
) -> anyhow::Result<BackendRow> {
    let shape = name
        .tree_shape(&scene.mesh, workers.build_context())
        .transpose()?;
    Ok(BackendRow {
        backend: name.to_string(),
        build_ms: Stat::default(),
        render_ms: Stat::default(),
        levels: shape.as_ref().map(|s| s.levels),
        max_leaf_triangles: shape
            .as_ref()
            .map_or_else(|| "n/a".into(), |s| s.max_leaf_triangles.clone()),
        nodes: shape.as_ref().map(|s| s.nodes),
        bytes: shape.as_ref().map(|s| s.bytes),
        sah_cost: shape.and_then(|s| s.sah_cost),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn split(total_ms: f64, tracing_ms: f64, image_ms: f64) -> RenderProfile {
        RenderProfile {
            total_ms,
            tracing_ms,
            shading_ms: total_ms - image_ms - tracing_ms,
            image_ms,
            queries: 42,
        }
    }

    #[test]
    fn a_median_split_takes_each_part_from_its_own_middle_run() {
        let runs = [
            split(100.0, 40.0, 10.0),
            split(130.0, 35.0, 12.0),
            split(90.0, 50.0, 11.0),
        ];
        let median = median_split(&runs);
        assert_eq!(median.total_ms, 100.0);
        assert_eq!(median.tracing_ms, 40.0);
        assert_eq!(median.image_ms, 11.0);
        // Shading per run: 50, 83, 29.
        assert_eq!(median.shading_ms, 50.0);
        assert_eq!(median.queries, 42);
    }
}
