//! Where a render's time goes: tracing, shading and sampling, image work.
//!
//! The render is timed whole, in two parts: the radiance of every pixel
//! (tracing, shading and sampling together) and the image work after it
//! (bloom, and the conversion to the 8-bit sRGB a PNG holds). It is then
//! rendered once more through a recorder that keeps every query, and those
//! queries are replayed alone, in parallel, through the same intersectors:
//! their time is the tracing, and the rest of the radiance time is shading
//! and sampling. Replayed alone, the queries find warmer caches than among
//! the shading, so the tracing share is a lower bound.

use super::{RenderSettings, Renderer};
use crate::geometry::{Hit, Ray};
use crate::jobs::one_job_each;
use crate::scene::Scene;
use crate::trace::Intersector;
use rayon::prelude::*;
use serde::Serialize;
use std::sync::Mutex;
use std::time::Instant;

/// One render's time, split.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct RenderProfile {
    /// The whole render: radiance and image work.
    pub total_ms: f64,
    /// The render's own queries replayed alone.
    pub tracing_ms: f64,
    /// The rest of the radiance time.
    pub shading_ms: f64,
    /// Bloom and the conversion to 8-bit sRGB.
    pub image_ms: f64,
    /// Closest-hit and any-hit queries the render asked.
    pub queries: u64,
}

/// One query a render asked of one layer.
#[derive(Clone, Copy)]
enum Query {
    Closest(Ray),
    Any(Ray),
}

/// An intersector that keeps every query it answers.
struct Recorder<'a, I: ?Sized> {
    inner: &'a I,
    queries: Mutex<Vec<Query>>,
}

impl<I: Intersector + ?Sized> Intersector for Recorder<'_, I> {
    fn intersect(&self, ray: &Ray) -> Option<Hit> {
        self.push(Query::Closest(*ray));
        self.inner.intersect(ray)
    }

    fn occluded(&self, ray: &Ray) -> bool {
        self.push(Query::Any(*ray));
        self.inner.occluded(ray)
    }
}

impl<I: ?Sized> Recorder<'_, I> {
    fn push(&self, query: Query) {
        self.queries
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
            .push(query);
    }
}

impl RenderProfile {
    /// This render's time with its tracing swapped for `tracing_ms`:
    /// what another backend's render takes by its tracing alone, the
    /// shading, sampling and image work being the same code whichever
    /// backend answers the queries.
    pub fn with_tracing(&self, tracing_ms: f64) -> f64 {
        self.total_ms - self.tracing_ms + tracing_ms
    }
}

fn ms(start: Instant) -> f64 {
    start.elapsed().as_secs_f64() * 1e3
}

/// Renders `scene` through `layers` (one intersector per mesh layer) and
/// splits its time; run it inside the thread pool that should render.
pub fn profile<I: Intersector + ?Sized>(
    scene: &Scene,
    layers: &[&I],
    settings: &RenderSettings,
) -> RenderProfile {
    let renderer = Renderer::new(scene, layers, settings);
    let start = Instant::now();
    let radiance = renderer.render_radiance();
    let radiance_ms = ms(start);
    let start = Instant::now();
    std::hint::black_box(renderer.post_process(radiance).to_srgb8());
    let image_ms = ms(start);

    let recorders: Vec<Recorder<I>> = layers
        .iter()
        .map(|&inner| Recorder {
            inner,
            queries: Mutex::new(Vec::new()),
        })
        .collect();
    let recording: Vec<&Recorder<I>> = recorders.iter().collect();
    Renderer::new(scene, &recording, settings).render_radiance();
    let queries: Vec<(usize, Vec<Query>)> = recorders
        .into_iter()
        .enumerate()
        .map(|(layer, r)| {
            let queries = r
                .queries
                .into_inner()
                .unwrap_or_else(|poisoned| poisoned.into_inner());
            (layer, queries)
        })
        .collect();
    let start = Instant::now();
    let answered: usize = queries
        .iter()
        .map(|(layer, queries)| {
            let intersector = layers[*layer];
            one_job_each(queries.par_chunks(256))
                .map(|chunk| {
                    chunk
                        .iter()
                        .filter(|query| match query {
                            Query::Closest(ray) => intersector.intersect(ray).is_some(),
                            Query::Any(ray) => intersector.occluded(ray),
                        })
                        .count()
                })
                .sum::<usize>()
        })
        .sum();
    std::hint::black_box(answered);
    let tracing_ms = ms(start);
    RenderProfile {
        total_ms: radiance_ms + image_ms,
        tracing_ms,
        shading_ms: (radiance_ms - tracing_ms).max(0.0),
        image_ms,
        queries: queries.iter().map(|(_, q)| q.len() as u64).sum(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::wide::WideBvh;
    use std::sync::atomic::{AtomicU64, Ordering};

    /// Counts the queries it passes on.
    struct Counting<'a>(&'a WideBvh, AtomicU64);

    impl Intersector for Counting<'_> {
        fn intersect(&self, ray: &Ray) -> Option<Hit> {
            self.1.fetch_add(1, Ordering::Relaxed);
            self.0.intersect(ray)
        }
        fn occluded(&self, ray: &Ray) -> bool {
            self.1.fetch_add(1, Ordering::Relaxed);
            self.0.occluded(ray)
        }
    }

    #[test]
    fn another_backends_tracing_replaces_this_ones() {
        let profile = RenderProfile {
            total_ms: 50.0,
            tracing_ms: 20.0,
            shading_ms: 24.0,
            image_ms: 6.0,
            queries: 9,
        };
        assert_eq!(profile.with_tracing(15.0), 45.0);
        assert_eq!(profile.with_tracing(profile.tracing_ms), profile.total_ms);
    }

    #[test]
    fn every_query_of_the_render_is_replayed() {
        let scene = crate::scene::load("cornell").unwrap();
        let bvh = WideBvh::build(&scene.mesh);
        let settings = RenderSettings::square(32);
        let p = profile(&scene, &[&bvh], &settings);
        let counting = Counting(&bvh, AtomicU64::new(0));
        Renderer::new(&scene, &[&counting], &settings).render_radiance();
        assert_eq!(p.queries, counting.1.into_inner());
        assert!(p.queries > 32 * 32, "{p:?}");
        assert!(p.tracing_ms > 0.0 && p.total_ms > p.image_ms, "{p:?}");
    }
}
