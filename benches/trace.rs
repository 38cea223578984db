//! Ray throughput of our fast BVH and Embree (MEDIUM, and MEDIUM + ROBUST)
//! in one group per scene and ray kind, on the fixed ray sets of `raycheck
//! perf` (cached per scene, the same for every backend), each queried as
//! `perf` queries it (diffuse rays as incoherent). The primary rays are
//! also timed split into those ours hits and those it misses: a ray that
//! misses costs its set-up and a few nodes, one that hits its leaves and
//! the finish of its hit too, and a change can move one and not the other.
//! Criterion prints rays per second.

mod common;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use raycheck::backends::embree;
use raycheck::bvh::wide::WideBvh;
use raycheck::geometry::{Ray, TriangleMesh};
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

/// How a ray set is queried.
#[derive(Clone, Copy)]
enum Query {
    Closest,
    Incoherent,
    Occluded,
}

impl Query {
    fn answer(self, backend: &dyn Intersector, ray: &Ray) -> bool {
        match self {
            Query::Closest => backend.intersect(ray).is_some(),
            Query::Incoherent => backend.intersect_incoherent(ray).is_some(),
            Query::Occluded => backend.occluded(ray),
        }
    }
}

/// Queries `rays` on the pool's threads; returns how many hit.
fn trace_all(rays: &[Ray], backend: &(dyn Intersector + Sync), query: Query) -> usize {
    one_job_each(rays.par_chunks(1024))
        .map(|chunk| chunk.iter().filter(|r| query.answer(backend, r)).count())
        .sum()
}

fn trace(c: &mut Criterion) {
    let workers = common::workers();
    let (pool, device) = (workers.pool(), workers.device());
    let embree_scene = |mesh: &TriangleMesh, robust: bool| {
        let options = SceneOptions {
            quality: BuildQuality::Medium,
            robust,
        };
        embree::build_scene(device, mesh, options).expect("a scene")
    };
    for scene in common::scenes() {
        let bvh = pool.install(|| WideBvh::build(&scene.mesh));
        let medium = embree_scene(&scene.mesh, false);
        let robust = embree_scene(&scene.mesh, true);
        let rays = pool.install(|| RaySets::cached(&scene, resolution()));
        let (hits, misses): (Vec<Ray>, Vec<Ray>) = rays
            .primary
            .iter()
            .partition(|r| bvh.intersect(r).is_some());
        let backends: [(&str, &(dyn Intersector + Sync)); 3] = [
            ("ours-fast", &bvh),
            ("embree-medium", &medium),
            ("embree-medium-robust", &robust),
        ];
        for (kind, set, query) in [
            ("primary", &rays.primary, Query::Closest),
            ("primary-hits", &hits, Query::Closest),
            ("primary-misses", &misses, Query::Closest),
            ("shadow", &rays.shadow, Query::Occluded),
            ("diffuse", &rays.diffuse, Query::Incoherent),
        ] {
            let mut group = c.benchmark_group(format!("trace/{}/{kind}", scene.name));
            group.sample_size(10);
            group.throughput(Throughput::Elements(set.len() as u64));
            for (name, backend) in backends {
                group.bench_function(BenchmarkId::from_parameter(name), |b| {
                    b.iter(|| pool.install(|| black_box(trace_all(set, backend, query))))
                });
            }
            group.finish();
        }
    }
}

criterion_group!(benches, trace);
criterion_main!(benches);
