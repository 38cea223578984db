//! raycheck: a harness that checks BVH ray tracers hit by hit against
//! Embree 4 and an exact referee, times them side by side, probes their
//! numerical stability and measures render error against run time.
//!
//! The layers, each depending only on those above it:
//!
//! - [`exact`]: exact predicates on f32 inputs (Shewchuk 1997 expansions);
//! - [`geometry`]: rays, hits, boxes, meshes, the watertight triangle test;
//! - [`random`]: the one seeded mixing function;
//! - [`adapters`]: tracers that are not Rust crates, run as programs, and
//!   their set-up in the cache (Python environments, a compiled C++
//!   template); it depends on nothing else in raycheck;
//! - [`trace`]: the [`trace::Intersector`] trait every tracer implements;
//! - [`bvh`]: our median-split, SAH and wide BVHs and their traversal;
//! - [`backends`]: every tracer behind one trait and one factory: ours,
//!   Embree, obvhs, bvh, parry3d;
//! - [`parallel`]: the worker threads, in the floating-point mode Embree asks for;
//! - [`scene`]: manifests, mesh loaders, assets, cameras, lights, materials;
//! - [`render`]: the renderer, generic over any intersector;
//! - [`check`]: every backend asked at once, and the exact referee;
//! - [`sweep`]: error metrics, fits and samplers' tests for sampled renders;
//! - [`results`]: run metadata, tables, the verdicts per backend;
//! - [`perf`], [`stability`]: timing every backend, the stability catalogue;
//! - [`exchange`]: rays out, hits in, for tracers in any language;
//! - [`report`]: the page of `raycheck report`.

pub mod adapters;
pub mod backends;
pub mod bvh;
pub mod check;
pub mod exact;
pub mod exchange;
pub mod geometry;
pub mod parallel;
pub mod perf;
pub mod random;
pub mod render;
pub mod report;
pub mod results;
pub mod scene;
pub mod stability;
pub mod sweep;
pub mod trace;
