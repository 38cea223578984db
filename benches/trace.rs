//! Ray throughput of our fast BVH and Embree (MEDIUM, ROBUST) in one group
//! per scene and ray kind, on the fixed ray sets of `raycheck perf` (cached
//! per scene, the same for both backends). Criterion prints rays per second.

mod common;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use raycheck::backends::embree;
use raycheck::bvh::wide::WideBvh;
use raycheck::geometry::Ray;
use raycheck::jobs::one_job_each;
use raycheck::perf::rays::RaySets;
use raycheck::trace::Intersector;
use raycheck_reference::{BuildQuality, SceneOptions};
use rayon::prelude::*;
use std::hint::black_box;

/// Primary rays per side of the view (fewer under `--test`).
fn resolution() -> u32 {
    if common::test_mode() { 32 } else { 512 }
}

/// Traces `rays` on the pool's threads; returns the hit count.
fn trace_all(rays: &[Ray], query: &(dyn Fn(&Ray) -> bool + Sync)) -> usize {
    one_job_each(rays.par_chunks(1024))
        .map(|chunk| chunk.iter().filter(|r| query(r)).count())
        .sum()
}

fn trace(c: &mut Criterion) {
    let workers = common::workers();
    let (pool, device) = (workers.pool(), workers.device());
    let options = SceneOptions {
        quality: BuildQuality::Medium,
        robust: true,
    };
    for scene in common::scenes() {
        let bvh = pool.install(|| WideBvh::build(&scene.mesh));
        let reference = embree::build_scene(device, &scene.mesh, options).expect("a scene");
        let rays = pool.install(|| RaySets::cached(&scene, resolution()));
        let backends: [(&str, &(dyn Intersector + Sync)); 2] =
            [("ours-fast", &bvh), ("embree-medium-robust", &reference)];
        for (kind, set) in [
            ("primary", &rays.primary),
            ("shadow", &rays.shadow),
            ("diffuse", &rays.diffuse),
        ] {
            let mut group = c.benchmark_group(format!("trace/{}/{kind}", scene.name));
            group.sample_size(10);
            group.throughput(Throughput::Elements(set.len() as u64));
            for (name, backend) in backends {
                group.bench_function(BenchmarkId::from_parameter(name), |b| {
                    b.iter(|| {
                        pool.install(|| {
                            if kind == "shadow" {
                                black_box(trace_all(set, &|r| backend.occluded(r)))
                            } else {
                                black_box(trace_all(set, &|r| backend.intersect(r).is_some()))
                            }
                        })
                    })
                });
            }
            group.finish();
        }
    }
}

criterion_group!(benches, trace);
criterion_main!(benches);
