//! The 800×800 Phong-and-shadows render of each scene on each backend: our
//! SAH binary BVH, our fast BVH and Embree (MEDIUM, ROBUST).

mod common;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use raycheck::backends::embree;
use raycheck::bvh::wide::WideBvh;
use raycheck::bvh::{BuildOptions, Bvh};
use raycheck::render::{RenderSettings, render};
use raycheck::trace::Intersector;
use raycheck_reference::{BuildQuality, SceneOptions};
use std::hint::black_box;

fn render_scenes(c: &mut Criterion) {
    let workers = common::workers();
    let (pool, device) = (workers.pool(), workers.device());
    let settings = RenderSettings::square(if common::test_mode() { 32 } else { 800 });
    let options = SceneOptions {
        quality: BuildQuality::Medium,
        robust: true,
    };
    for scene in common::scenes() {
        let sah = Bvh::build(&scene.mesh, &BuildOptions::sah());
        let fast = pool.install(|| WideBvh::build(&scene.mesh));
        let reference = embree::build_scene(device, &scene.mesh, options).expect("a scene");
        let backends: [(&str, &(dyn Intersector + Sync)); 3] = [
            ("ours-sah", &sah),
            ("ours-fast", &fast),
            ("embree-medium-robust", &reference),
        ];
        let mut group = c.benchmark_group(format!("render/{}", scene.name));
        group.sample_size(10);
        for (name, backend) in backends {
            group.bench_function(BenchmarkId::from_parameter(name), |b| {
                b.iter(|| pool.install(|| black_box(render(&scene, backend, &settings))))
            });
        }
        group.finish();
    }
}

criterion_group!(benches, render_scenes);
criterion_main!(benches);
