//! Build and trace measurements on million-triangle meshes, run on demand
//! (release build):
//! `cargo test --release --lib bvh::measure -- --ignored --nocapture`.

use super::test_meshes::{Rng, random_rays, random_soup, sphere};
use super::{BuildOptions, Bvh};
use crate::geometry::Ray;
use crate::trace::Intersector;
use glam::Vec3;
use std::time::Instant;

#[test]
#[ignore = "a measurement, not a check: takes seconds in release"]
fn million_triangle_builds() {
    let mut rng = Rng::new(40);
    let meshes = [
        ("random soup", random_soup(1_000_000, 0.01, &mut rng)),
        ("sphere", sphere(Vec3::ZERO, 1.0, 500, 1001)),
    ];
    let random = random_rays(1_000_000, &mut rng);
    // 1024² pinhole rays from (0, 0, 3) over a 45° square view of the origin.
    let camera: Vec<Ray> = (0..1024 * 1024)
        .map(|i| {
            let pixel = |k: usize| ((k as f32 + 0.5) / 1024.0 - 0.5) * 0.83;
            Ray::new(
                Vec3::new(0.0, 0.0, 3.0),
                Vec3::new(pixel(i % 1024), pixel(i / 1024), -1.0),
            )
        })
        .collect();
    for (name, mesh) in &meshes {
        for options in [BuildOptions::median(), BuildOptions::sah()] {
            let bvh = Bvh::build(mesh, &options);
            bvh.validate(mesh).unwrap();
            println!("{name}, {:?}: {}", options.builder, bvh.stats());
            for (kind, rays) in [("random", &random), ("camera", &camera)] {
                let started = Instant::now();
                let hits = rays.iter().filter(|r| bvh.intersect(r).is_some()).count();
                let seconds = started.elapsed().as_secs_f64();
                println!(
                    "  closest hit, {kind} rays, 1 thread: {:.2} Mrays/s ({hits} of {} hit)",
                    rays.len() as f64 / seconds / 1e6,
                    rays.len()
                );
            }
        }
    }
}
