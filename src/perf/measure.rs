//! One scene on one thread count: every backend built and traced in turn,
//! run by run, on the same rays; medians over runs with their range.

use super::memory::peak_during;
use super::rays::RaySets;
use crate::backends::{Backend, BackendName};
use crate::geometry::Ray;
use crate::jobs::one_job_each;
use crate::parallel::Workers;
use crate::scene::Scene;
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
    /// Build wall time, ms: each run's the median of its builds.
    pub build_ms: Stat,
    /// Builds timed in each run ([`builds_per_run`]; one in runs saved
    /// before they were repeated).
    #[serde(default = "one_build")]
    pub builds_per_run: usize,
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

fn one_build() -> usize {
    1
}

/// How many times each run builds every backend on a scene of
/// `triangles`. A build under a millisecond swings with what the machine
/// did just before: on the 2-core Xeon VM the monkey's seven two-thread
/// builds in one run spread over 0.51-0.74 ms (ours) and 0.54-0.61 ms
/// (Embree), as a worker thread woke in time or not and its pages were
/// fresh or reused, and the median of seven put our build at 0.93-1.27 of
/// Embree's speed from run to run. Five rounds make each run's time the
/// median of five builds; above a million triangles a build takes long
/// enough that one a run keeps `perf` short.
pub fn builds_per_run(triangles: usize) -> usize {
    if triangles <= REPEATED_BUILDS_UP_TO {
        5
    } else {
        1
    }
}

/// Scenes of up to this many triangles are built more than once a run
/// ([`builds_per_run`]).
pub const REPEATED_BUILDS_UP_TO: usize = 1_000_000;

/// A ray query of a backend: whether the ray hits (primary and diffuse
/// rays, the diffuse ones asked as incoherent,
/// [`crate::trace::Intersector::intersect_incoherent`]) or is blocked (shadow rays).
type Query = dyn Fn(&dyn Backend, &Ray) -> bool + Sync;

/// Measures every backend of `names` on `scene` with `runs` interleaved
/// runs on `workers`: one build of each backend to warm up (the first
/// build on a device starts Embree's thread pool), then each run builds
/// every backend ([`builds_per_run`] rounds, each backend in turn, the
/// run's build time the median of its rounds), traces the primary rays
/// once with each untimed, and times each ray set with every backend in
/// turn, on the last round's builds.
///
/// Each run traces its own builds because where a build lands in memory
/// moves its speed: six builds of the same trees in one process gave
/// per-build medians of our shadow rays over Embree's from 0.87 to 0.99 on
/// dragon-871k (Xeon, one thread), as far apart as whole runs of `perf`.
/// Traced on one build, the runs share its placement, and their spread,
/// on which `--baseline` judges a change, leaves it out. Each run starts
/// with the next backend, so that none always builds first into the heap
/// the last run freed (dragon-14m: ours built in 4.4 s first and 6.0 s
/// after Embree's), and the untimed pass leaves every timed one a
/// traversal's caches, not a build's (timed straight after the builds,
/// the first backend's primary rays read 2-6% slower).
pub fn measure(
    scene: &Scene,
    rays: &RaySets,
    workers: &Workers,
    names: &[BackendName],
    runs: usize,
) -> anyhow::Result<Vec<PerfRow>> {
    let threads = workers.threads();
    let (pool, context) = (workers.pool(), workers.build_context());
    let runs = runs.max(1);
    let rounds = builds_per_run(scene.mesh.triangle_count());
    let mut build_ms = vec![Vec::new(); names.len()];
    let mut peak_mib = vec![Vec::new(); names.len()];
    let mut mrays = [(); 3].map(|_| vec![Vec::new(); names.len()]);
    let mut bytes = vec![None; names.len()];
    for name in names {
        drop(pool.install(|| name.build(&scene.mesh, context))?);
    }
    let sets: [(&[Ray], &Query); 3] = [
        (&rays.primary, &|b, r| b.intersect(r).is_some()),
        (&rays.shadow, &|b, r| b.occluded(r)),
        (&rays.diffuse, &|b, r| b.intersect_incoherent(r).is_some()),
    ];
    for run in 0..runs {
        let order: Vec<usize> = (0..names.len()).map(|k| (run + k) % names.len()).collect();
        // The previous run's builds were dropped with it: one build per
        // backend is alive at a time, as many as tracing needs.
        let mut built: Vec<Option<Box<dyn Backend>>> = names.iter().map(|_| None).collect();
        let mut run_build_ms = vec![Vec::new(); names.len()];
        for round in (0..rounds).rev() {
            for &i in &order {
                let (backend, peak) =
                    peak_during(|| pool.install(|| names[i].build(&scene.mesh, context)));
                let backend = backend?;
                run_build_ms[i].push(backend.build_time().as_secs_f64() * 1e3);
                if let Some(peak) = peak {
                    peak_mib[i].push(peak as f64 / (1u64 << 20) as f64);
                }
                // Earlier rounds' builds are dropped as soon as timed.
                if round == 0 {
                    bytes[i] = backend.bytes();
                    built[i] = Some(backend);
                }
            }
        }
        for (all, run) in build_ms.iter_mut().zip(run_build_ms) {
            all.push(median(run));
        }
        let built: Vec<Box<dyn Backend>> = built.into_iter().flatten().collect();
        let (warm_up, query) = sets[0];
        for &i in &order {
            throughput(pool, warm_up, &|r| query(built[i].as_ref(), r));
        }
        for ((set, query), mrays) in sets.iter().zip(&mut mrays) {
            for &i in &order {
                mrays[i].push(throughput(pool, set, &|r| query(built[i].as_ref(), r)));
            }
        }
    }
    let per_tri = |bytes: usize| bytes as f64 / scene.mesh.triangle_count().max(1) as f64;
    let [primary, shadow, diffuse] = mrays;
    Ok(names
        .iter()
        .enumerate()
        .map(|(i, name)| PerfRow {
            scene: scene.name.clone(),
            triangles: scene.mesh.triangle_count(),
            threads,
            backend: name.to_string(),
            primary_rays: rays.primary.len(),
            shadow_rays: rays.shadow.len(),
            diffuse_rays: rays.diffuse.len(),
            build_ms: Stat::of(build_ms[i].clone()),
            builds_per_run: rounds,
            mrays_primary: Stat::of(primary[i].clone()),
            mrays_shadow: Stat::of(shadow[i].clone()),
            mrays_diffuse: Stat::of(diffuse[i].clone()),
            peak_build_mib: (!peak_mib[i].is_empty()).then(|| median(peak_mib[i].clone())),
            bytes_per_tri: bytes[i].map(per_tri),
        })
        .collect())
}

/// Mrays/s of one pass of `query` over `rays` on `pool`.
fn throughput(pool: &ThreadPool, rays: &[Ray], query: &(dyn Fn(&Ray) -> bool + Sync)) -> f64 {
    let elapsed = pool.install(|| {
        let start = Instant::now();
        let hits: usize = one_job_each(rays.par_chunks(1024))
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
