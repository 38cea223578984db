//! One scene on one thread count: every backend built and traced in turn,
//! run by run, on the same rays; medians over runs with their range.

use super::memory::peak_during;
use super::rays::RaySets;
use crate::backends::{Backend, BackendName};
use crate::geometry::Ray;
use crate::scene::Scene;
use raycheck_reference::Isa;
use rayon::ThreadPool;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::time::{Duration, Instant};

/// A measurement repeated over runs: the median, the range and every run.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Stat {
    pub median: f64,
    pub min: f64,
    pub max: f64,
    /// Every run's value, in the order measured.
    pub runs: Vec<f64>,
}

impl Stat {
    pub fn of(runs: Vec<f64>) -> Self {
        let mut sorted = runs.clone();
        sorted.sort_by(f64::total_cmp);
        Self {
            median: median(runs.clone()),
            min: sorted.first().copied().unwrap_or(f64::NAN),
            max: sorted.last().copied().unwrap_or(f64::NAN),
            runs,
        }
    }
}

/// One backend on one scene and thread count; the JSON of `raycheck perf`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PerfRow {
    pub scene: String,
    pub triangles: usize,
    pub threads: usize,
    /// The backend's `--backends` name.
    pub backend: String,
    pub primary_rays: usize,
    pub shadow_rays: usize,
    pub diffuse_rays: usize,
    /// Build wall time, ms.
    pub build_ms: Stat,
    /// Throughput of each ray set, Mrays/s.
    pub mrays_primary: Stat,
    pub mrays_shadow: Stat,
    pub mrays_diffuse: Stat,
    /// The most the process's resident memory rose during a build, MiB,
    /// where the system can tell (median over the builds).
    pub peak_build_mib: Option<f64>,
    /// Bytes of the acceleration structure per triangle, where the backend
    /// can tell (for Embree: what its memory monitor saw the scene
    /// allocate, its copies of the vertex and index buffers included).
    pub bytes_per_tri: Option<f64>,
}

impl PerfRow {
    /// This row over `baseline`'s, each as a speed ratio (above 1 is
    /// faster): build time theirs/ours, then throughput ours/theirs for
    /// primary, shadow and diffuse rays, then bytes per triangle ours/theirs
    /// (below 1 is smaller).
    pub fn ratios(&self, baseline: &PerfRow) -> [f64; 5] {
        let bytes = match (self.bytes_per_tri, baseline.bytes_per_tri) {
            (Some(a), Some(b)) => a / b,
            _ => f64::NAN,
        };
        [
            baseline.build_ms.median / self.build_ms.median,
            self.mrays_primary.median / baseline.mrays_primary.median,
            self.mrays_shadow.median / baseline.mrays_shadow.median,
            self.mrays_diffuse.median / baseline.mrays_diffuse.median,
            bytes,
        ]
    }
}

/// Measures every backend of `names` on `scene` with `runs` interleaved
/// runs on `pool`'s threads, Embree's limited to `embree_isa`: one build of each backend to warm up (the
/// first build on a device starts Embree's thread pool), then each run
/// builds every backend in turn, then each ray set is traced by every
/// backend in turn, run by run.
pub fn measure(
    scene: &Scene,
    rays: &RaySets,
    pool: &ThreadPool,
    names: &[BackendName],
    runs: usize,
    embree_isa: Isa,
) -> anyhow::Result<Vec<PerfRow>> {
    let threads = pool.current_num_threads();
    let device = crate::backends::embree_device_with_isa(threads, embree_isa)?;
    let runs = runs.max(1);
    let mut build_ms = vec![Vec::new(); names.len()];
    let mut peak_mib = vec![Vec::new(); names.len()];
    let mut built: Vec<Option<Box<dyn Backend>>> = names.iter().map(|_| None).collect();
    for name in names {
        drop(pool.install(|| name.build(&scene.mesh, &device))?);
    }
    for _ in 0..runs {
        for (i, name) in names.iter().enumerate() {
            // Drop the previous build first, so only one is alive per backend.
            built[i] = None;
            let (backend, peak) = peak_during(|| pool.install(|| name.build(&scene.mesh, &device)));
            let backend = backend?;
            build_ms[i].push(backend.build_time().as_secs_f64() * 1e3);
            if let Some(peak) = peak {
                peak_mib[i].push(peak as f64 / (1u64 << 20) as f64);
            }
            built[i] = Some(backend);
        }
    }
    let backends: Vec<Box<dyn Backend>> = built.into_iter().flatten().collect();
    let pass = |set: &[Ray], query: &(dyn Fn(&dyn Backend, &Ray) -> bool + Sync)| {
        let mut mrays = vec![Vec::new(); backends.len()];
        for _ in 0..runs {
            for (i, backend) in backends.iter().enumerate() {
                mrays[i].push(throughput(pool, set, &|r| query(backend.as_ref(), r)));
            }
        }
        mrays
    };
    let primary = pass(&rays.primary, &|b, r| b.intersect(r).is_some());
    let shadow = pass(&rays.shadow, &|b, r| b.occluded(r));
    let diffuse = pass(&rays.diffuse, &|b, r| b.intersect(r).is_some());
    let per_tri = |bytes: usize| bytes as f64 / scene.mesh.triangle_count().max(1) as f64;
    Ok(backends
        .iter()
        .enumerate()
        .map(|(i, backend)| PerfRow {
            scene: scene.name.clone(),
            triangles: scene.mesh.triangle_count(),
            threads,
            backend: names[i].to_string(),
            primary_rays: rays.primary.len(),
            shadow_rays: rays.shadow.len(),
            diffuse_rays: rays.diffuse.len(),
            build_ms: Stat::of(build_ms[i].clone()),
            mrays_primary: Stat::of(primary[i].clone()),
            mrays_shadow: Stat::of(shadow[i].clone()),
            mrays_diffuse: Stat::of(diffuse[i].clone()),
            peak_build_mib: (!peak_mib[i].is_empty()).then(|| median(peak_mib[i].clone())),
            bytes_per_tri: backend.bytes().map(per_tri),
        })
        .collect())
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
