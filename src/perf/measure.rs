//! One scene on one thread count: our fast BVH and one Embree configuration
//! built and traced in turn, run by run, on the same rays; medians over runs.

use super::rays::RaySets;
use crate::backends::embree;
use crate::bvh::wide::WideBvh;
use crate::geometry::Ray;
use crate::scene::Scene;
use crate::trace::Intersector;
use raycheck_reference::{BuildQuality, Device, DeviceConfig, SceneOptions};
use rayon::ThreadPool;
use rayon::prelude::*;
use serde::Serialize;
use std::time::{Duration, Instant};

/// The Embree configurations every scene is measured against.
pub const EMBREE_CONFIGS: [(&str, SceneOptions); 2] = [
    (
        "MEDIUM",
        SceneOptions {
            quality: BuildQuality::Medium,
            robust: false,
        },
    ),
    (
        "MEDIUM, ROBUST",
        SceneOptions {
            quality: BuildQuality::Medium,
            robust: true,
        },
    ),
];

/// Our fast BVH against one Embree configuration on one scene and thread
/// count; the JSON of `raycheck perf`.
#[derive(Clone, Debug, Serialize)]
pub struct PerfRow {
    pub scene: String,
    pub triangles: usize,
    pub threads: usize,
    /// The Embree configuration, e.g. `MEDIUM, ROBUST`.
    pub embree: String,
    pub runs: usize,
    pub primary_rays: usize,
    pub shadow_rays: usize,
    pub diffuse_rays: usize,
    pub build_ms: f64,
    pub embree_build_ms: f64,
    pub mrays_primary: f64,
    pub embree_mrays_primary: f64,
    pub mrays_shadow: f64,
    pub embree_mrays_shadow: f64,
    pub mrays_diffuse: f64,
    pub embree_mrays_diffuse: f64,
    /// Our nodes and triangle blocks per triangle.
    pub bytes_per_tri: f64,
    /// What Embree's memory monitor saw the scene allocate (its copies of
    /// the vertex and index buffers included) per triangle.
    pub embree_bytes_per_tri: f64,
}

impl PerfRow {
    /// Ours over Embree: build time (lower is better), then primary, shadow
    /// and diffuse throughput and bytes per triangle.
    pub fn ratios(&self) -> [f64; 5] {
        [
            self.build_ms / self.embree_build_ms,
            self.mrays_primary / self.embree_mrays_primary,
            self.mrays_shadow / self.embree_mrays_shadow,
            self.mrays_diffuse / self.embree_mrays_diffuse,
            self.bytes_per_tri / self.embree_bytes_per_tri,
        ]
    }
}

/// Measures `scene` with `runs` interleaved runs on `pool`'s threads.
pub fn measure(
    scene: &Scene,
    rays: &RaySets,
    pool: &ThreadPool,
    embree_config: (&str, SceneOptions),
    runs: usize,
) -> anyhow::Result<PerfRow> {
    let threads = pool.current_num_threads();
    let device = Device::new(&DeviceConfig {
        threads: Some(threads),
        verbose: 0,
    })?;
    let (label, options) = embree_config;
    let (mut ours_ms, mut embree_ms) = (Vec::new(), Vec::new());
    let mut built = None;
    for _ in 0..runs.max(1) {
        let bvh = pool.install(|| WideBvh::build(&scene.mesh));
        ours_ms.push(bvh.build_time().as_secs_f64() * 1e3);
        let reference = embree::build_scene(&device, &scene.mesh, options)?;
        embree_ms.push(reference.build_time().as_secs_f64() * 1e3);
        built = Some((bvh, reference));
    }
    let (bvh, reference) = built.expect("at least one run");
    let pass = |query: &(dyn Fn(&Ray) -> bool + Sync), set: &[Ray]| throughput(pool, set, query);
    let [primary, diffuse] = [&rays.primary, &rays.diffuse].map(|set| {
        interleaved(
            || pass(&|r| bvh.intersect(r).is_some(), set),
            || pass(&|r| Intersector::intersect(&reference, r).is_some(), set),
            runs,
        )
    });
    let shadow = interleaved(
        || pass(&|r| bvh.occluded(r), &rays.shadow),
        || pass(&|r| Intersector::occluded(&reference, r), &rays.shadow),
        runs,
    );
    let per_tri = |bytes: usize| bytes as f64 / scene.mesh.triangle_count().max(1) as f64;
    Ok(PerfRow {
        scene: scene.name.clone(),
        triangles: scene.mesh.triangle_count(),
        threads,
        embree: label.to_string(),
        runs,
        primary_rays: rays.primary.len(),
        shadow_rays: rays.shadow.len(),
        diffuse_rays: rays.diffuse.len(),
        build_ms: median(ours_ms),
        embree_build_ms: median(embree_ms),
        mrays_primary: primary.0,
        embree_mrays_primary: primary.1,
        mrays_shadow: shadow.0,
        embree_mrays_shadow: shadow.1,
        mrays_diffuse: diffuse.0,
        embree_mrays_diffuse: diffuse.1,
        bytes_per_tri: per_tri(bvh.bytes()),
        embree_bytes_per_tri: per_tri(reference.bytes()),
    })
}

/// Median Mrays/s of `ours` and `theirs`, each timed once per run, in turn.
fn interleaved(ours: impl Fn() -> f64, theirs: impl Fn() -> f64, runs: usize) -> (f64, f64) {
    let (mut a, mut b) = (Vec::new(), Vec::new());
    for _ in 0..runs.max(1) {
        a.push(ours());
        b.push(theirs());
    }
    (median(a), median(b))
}

/// Mrays/s of one pass of `query` over `rays` on `pool`.
fn throughput(pool: &ThreadPool, rays: &[Ray], query: &(dyn Fn(&Ray) -> bool + Sync)) -> f64 {
    let elapsed = pool.install(|| {
        let start = Instant::now();
        let hits: usize = rays
            .par_chunks(1024)
            .map(|chunk| chunk.iter().filter(|r| query(r)).count())
            .sum();
        std::hint::black_box(hits);
        start.elapsed()
    });
    rays.len() as f64 / elapsed.max(Duration::from_nanos(1)).as_secs_f64() / 1e6
}

/// The median (the mean of the middle two for an even count).
pub fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    match n {
        0 => f64::NAN,
        _ if n % 2 == 1 => values[n / 2],
        _ => 0.5 * (values[n / 2 - 1] + values[n / 2]),
    }
}
