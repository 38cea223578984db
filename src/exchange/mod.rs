//! Tracers in any language: rays out, hits in.
//!
//! `raycheck rays` writes a ray set ([`sets`]) in a documented binary
//! layout ([`files`]) with the exact f32 mesh it was made for ([`ply`]),
//! or a stability case as it is judged: a bundle of (mesh, rays) pairs
//! ([`bundle`]); another program traces them and writes hits files;
//! `raycheck judge` judges them exactly, beside built-in backends
//! ([`mod@judge`]), treating the files as one more backend ([`recorded`]).
//! `raycheck trace` writes the hits of any built-in backend, so the round
//! trip can be checked end to end. `docs/exchange.md` documents the layout
//! with a Python reader and writer.

pub mod bundle;
pub mod export;
pub mod files;
pub mod judge;
pub mod ply;
pub mod program;
pub mod recorded;
pub mod sets;

pub use bundle::{Bundle, is_bundle};
pub use export::{ExportRequest, export};
pub use files::{FileError, HitsFile, RaysFile};
pub use judge::{
    BundleSummary, judge, judge_bundle, judge_files, trace, trace_bundle, trace_files,
};
pub use sets::{Exported, SetName, case_batches, merged, scene_rays};
