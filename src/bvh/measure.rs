//! Build and trace measurements on million-triangle meshes, run on demand
//! (release build):
//! `cargo test --release --lib bvh::measure -- --ignored --nocapture`.

use super::test_meshes::{Rng, random_rays, random_soup, sphere};
use super::{BuildOptions, Bvh};
use crate::trace::Intersector;
use glam::Vec3;
use std::time::Instant;

#[test]
#[ignore = "a measurement, not a check: takes seconds in release"]
fn million_triangle_builds() {
    let mut rng = Rng(40);
    let meshes = [
        ("random soup", random_soup(1_000_000, 0.01, &mut rng)),
        ("sphere", sphere(Vec3::ZERO, 1.0, 500, 1001)),
    ];
    let rays = random_rays(1_000_000, &mut rng);
    for (name, mesh) in &meshes {
        for options in [BuildOptions::median(), BuildOptions::sah()] {
            let bvh = Bvh::build(mesh, &options);
            bvh.validate(mesh).unwrap();
            let started = Instant::now();
            let hits = rays.iter().filter(|r| bvh.intersect(r).is_some()).count();
            let seconds = started.elapsed().as_secs_f64();
            println!("{name}, {:?}: {}", options.builder, bvh.stats());
            println!(
                "  closest hit, 1 thread: {:.2} Mrays/s ({hits} of {} rays hit)",
                rays.len() as f64 / seconds / 1e6,
                rays.len()
            );
        }
    }
}
