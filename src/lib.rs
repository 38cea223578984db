//! raycheck: a BVH ray tracer checked hit by hit against Embree 4.
//!
//! The layers, each depending only on those above it:
//!
//! - [`exact`]: exact predicates on f32 inputs (Shewchuk 1997 expansions);
//! - [`geometry`]: rays, hits, boxes, meshes, the watertight triangle test;
//! - [`trace`]: the [`trace::Intersector`] trait every backend implements;
//! - [`bvh`]: our median-split and SAH BVHs and their traversal;
//! - [`scene`]: manifests, mesh loaders, assets, cameras, lights, materials;
//! - [`render`]: the renderer, generic over any intersector;
//! - [`check`]: Embree as an intersector, the checked pair and the referee;
//! - [`report`]: the tables, images and page of `raycheck report`;
//! - [`parallel`]: the worker threads, in the floating-point mode Embree asks for;
//! - [`perf`]: our fast BVH ([`bvh::wide`]) and Embree timed side by side.

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
