//! The plain Cornell box runs only its own passes: one camera ray per
//! pixel, one shadow ray per shaded point the light is in front of, mirror
//! rays and nothing else.

use raycheck::bvh::{BuildOptions, Bvh};
use raycheck::geometry::{Hit, Ray};
use raycheck::render::pipeline::Passes;
use raycheck::render::surface::SurfacePoint;
use raycheck::render::{RenderSettings, render};
use raycheck::scene::{self, Scene};
use raycheck::trace::Intersector;
use std::sync::atomic::{AtomicU64, Ordering};

/// Counts the queries, the hits it passes on and those of them that face
/// the scene's one light.
struct Counting<'a> {
    inner: &'a Bvh,
    scene: &'a Scene,
    intersects: AtomicU64,
    hits: AtomicU64,
    lit_hits: AtomicU64,
    occludeds: AtomicU64,
}

impl Intersector for Counting<'_> {
    fn intersect(&self, ray: &Ray) -> Option<Hit> {
        self.intersects.fetch_add(1, Ordering::Relaxed);
        let hit = self.inner.intersect(ray);
        if let Some(hit) = &hit {
            self.hits.fetch_add(1, Ordering::Relaxed);
            let surface = SurfacePoint::new(&self.scene.mesh, ray, hit);
            let light = self.scene.lights[0].representative_point();
            let to_light = (light - surface.position).normalize_or_zero();
            let faces_light = surface.normal.dot(to_light) > 0.0;
            self.lit_hits
                .fetch_add(faces_light as u64, Ordering::Relaxed);
        }
        hit
    }

    fn occluded(&self, ray: &Ray) -> bool {
        self.occludeds.fetch_add(1, Ordering::Relaxed);
        self.inner.occluded(ray)
    }
}

#[test]
fn plain_cornell_does_no_other_work() {
    let scene = scene::load("cornell").unwrap();
    let passes = Passes::for_scene(&scene);
    assert!(passes.shading && passes.hard_shadows && passes.reflection);
    assert!(
        !(passes.area_lights
            || passes.normal_interpolation
            || passes.textures
            || passes.motion_blur
            || passes.bloom
            || passes.multisample
            || passes.glossy
            || passes.transparency),
        "{passes:?}"
    );
    assert_eq!(passes.samples_per_pixel, 1);
    let bvh = Bvh::build(&scene.mesh, &BuildOptions::sah());
    let counting = Counting {
        inner: &bvh,
        scene: &scene,
        intersects: AtomicU64::new(0),
        hits: AtomicU64::new(0),
        lit_hits: AtomicU64::new(0),
        occludeds: AtomicU64::new(0),
    };
    let settings = RenderSettings::square(32);
    render(&scene, &counting, &settings);
    assert_eq!(scene.lights.len(), 1);
    let (intersects, hits, lit_hits, occludeds) = (
        counting.intersects.into_inner(),
        counting.hits.into_inner(),
        counting.lit_hits.into_inner(),
        counting.occludeds.into_inner(),
    );
    // Every pixel's camera ray, plus mirror rays only: the mirror block
    // covers a part of the image, and mirror rays may hit mirrors again.
    assert!(
        intersects > 32 * 32 && intersects < 2 * 32 * 32,
        "{intersects}"
    );
    // Exactly one shadow ray per hit that faces the light: one point light,
    // no sampling, and none where the light is behind the surface (the
    // camera sees such faces on the blocks).
    assert_eq!(occludeds, lit_hits);
    assert!(lit_hits < hits, "{lit_hits} of {hits}");
}
