//! Build time of every builder: our median and SAH binary BVHs, the fast
//! 8-wide BVH, and Embree at LOW, MEDIUM and HIGH quality.

mod common;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use raycheck::backends::embree;
use raycheck::bvh::wide::WideBvh;
use raycheck::bvh::{BuildOptions, Bvh};
use raycheck_reference::{BuildQuality, SceneOptions};
use std::hint::black_box;

fn build(c: &mut Criterion) {
    let workers = common::workers();
    let (pool, device) = (workers.pool(), workers.device());
    for scene in common::scenes() {
        let mesh = &scene.mesh;
        let mut group = c.benchmark_group(format!("build/{}", scene.name));
        group.sample_size(10);
        group.throughput(Throughput::Elements(mesh.triangle_count() as u64));
        for (name, options) in [
            ("median", BuildOptions::median()),
            ("sah", BuildOptions::sah()),
        ] {
            group.bench_function(BenchmarkId::from_parameter(name), |b| {
                b.iter(|| pool.install(|| black_box(Bvh::build(mesh, &options))))
            });
        }
        group.bench_function(BenchmarkId::from_parameter("fast"), |b| {
            b.iter(|| pool.install(|| black_box(WideBvh::build(mesh))))
        });
        for (name, quality) in [
            ("embree-low", BuildQuality::Low),
            ("embree-medium", BuildQuality::Medium),
            ("embree-high", BuildQuality::High),
        ] {
            let options = SceneOptions {
                quality,
                robust: true,
            };
            group.bench_function(BenchmarkId::from_parameter(name), |b| {
                b.iter(|| black_box(embree::build_scene(device, mesh, options).expect("a scene")))
            });
        }
        group.finish();
    }
}

criterion_group!(benches, build);
criterion_main!(benches);
