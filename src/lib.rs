//! raycheck: a harness that checks BVH ray tracers hit by hit against
//! Embree 4 and an exact referee, times them side by side, probes their
//! numerical stability and measures render error against run time.
//!
//! A backend built over a mesh, a ray asked of it and of Embree, and both
//! answers judged exactly:
//!
//! ```
//! use glam::Vec3;
//! use raycheck::backends::{embree::EMBREE_ROBUST, ours::OURS};
//! use raycheck::check::{Answer, Judgement, Referee};
//! use raycheck::geometry::{Ray, TriangleMesh};
//! use raycheck::parallel::{InstructionSets, Workers};
//!
//! // A unit square of two triangles, and a ray down through their shared
//! // edge: a watertight tracer hits one of them.
//! let mesh = TriangleMesh::soup(&[
//!     [Vec3::ZERO, Vec3::X, Vec3::Y],
//!     [Vec3::X, Vec3::ONE.with_z(0.0), Vec3::Y],
//! ]);
//! let workers = Workers::new(Some(1), InstructionSets::default())?;
//! let ray = Ray::new(Vec3::new(0.5, 0.5, 1.0), Vec3::NEG_Z);
//! let referee = Referee::new(&mesh);
//! for name in [OURS, EMBREE_ROBUST] {
//!     let backend = name.build(&mesh, workers.build_context())?;
//!     let hit = backend.intersect(&ray).expect("the edge is hit");
//!     assert_eq!(hit.t, 1.0);
//!     let judgement = referee.judge(&ray, Answer::Closest(Some(hit)));
//!     assert!(judgement.is_admissible(), "{name}: {judgement:?}");
//! }
//! // A miss there would be wrong.
//! assert_eq!(referee.judge(&ray, Answer::Closest(None)), Judgement::Wrong);
//! # anyhow::Ok(())
//! ```
//!
//! The layers, each depending only on those before it in this list:
//!
//! - [`exact`]: exact predicates on f32 inputs (Shewchuk 1997 expansions);
//! - [`geometry`]: rays, hits, boxes, meshes, the watertight triangle test;
//! - [`random`]: the one seeded mixing function; [`fit`]: least-squares
//!   power laws;
//! - [`adapters`]: the tracers of `adapters/`, run as programs, and their
//!   set-up in the cache (Python environments, a compiled C++ template);
//!   it depends on nothing else in raycheck;
//! - [`trace`]: the [`trace::Intersector`] trait every tracer implements;
//! - [`bvh`]: our median-split, SAH and wide BVHs and their traversal;
//! - [`backends`]: every tracer behind one trait and one registry: ours,
//!   Embree, obvhs, bvh, parry3d;
//! - [`parallel`]: the worker threads, in the floating-point mode Embree
//!   asks for, and Embree's device on as many threads;
//! - [`scene`]: manifests, mesh loaders, assets, cameras, lights, materials;
//! - [`render`]: the renderer, generic over any intersector;
//! - [`check`]: every backend asked at once, and the exact referee;
//! - [`results`]: run metadata, tables, the verdicts per backend;
//! - [`run`]: the run every command works in, made once;
//! - [`perf`], [`stability`], [`sweep`]: timing every backend, the
//!   stability catalogue, error against run time;
//! - [`exchange`]: rays out, hits in, for tracers in any language;
//! - [`report`]: the page of `raycheck report`.

pub mod adapters;
pub mod backends;
pub mod bvh;
pub mod check;
pub mod exact;
pub mod exchange;
pub mod fit;
pub mod geometry;
pub mod jobs;
pub mod parallel;
pub mod perf;
pub mod random;
pub mod render;
pub mod report;
pub mod results;
pub mod run;
pub mod scene;
pub mod stability;
pub mod sweep;
pub mod trace;
