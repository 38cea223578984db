//! Every tracer the harness can check, behind one trait and one registry.
//!
//! A [`Backend`] is an [`Intersector`] built over one triangle mesh that
//! also says who it is, which parts of an answer it gives ([`Answers`]),
//! how long its build took and how much memory it holds. A [`Kind`] is a
//! backend `--backends` can name: its name, its [`Group`], one line about
//! it and how it builds. Each backend's file defines its kinds, and
//! [`registry`] lists them, one line per file: names, help text, error
//! text and the groups every command and the report read come from there.
//!
//! - `ours` (the fast wide BVH), `ours-sah`, `ours-median`: [`ours`];
//! - `embree`, `embree-robust`, `embree-low`, `embree-high[-robust]`, …:
//!   Embree 4.4 through `raycheck_reference` ([`embree`]);
//! - `obvhs`, `bvh`, `parry3d`: third-party crates ([`obvhs`],
//!   [`bvh_crate`], [`parry3d`]).

pub mod bvh_crate;
pub mod embree;
mod guard;
pub mod obvhs;
pub mod ours;
pub mod parry3d;
pub mod program;
pub mod registry;
mod third_party;

pub use program::ProgramKind;
pub use registry::{BackendName, DEFAULT_BACKENDS, Registry, UnknownBackend};

use crate::bvh::BvhView;
use crate::bvh::wide::Kernel;
use crate::geometry::TriangleMesh;
use crate::trace::Intersector;
use raycheck_reference::Device;
use serde::Serialize;
use std::time::Duration;

/// Which parts of an answer a backend gives. Every backend gives a hit's
/// distance `t` and triangle index, and answers any-hit queries (natively
/// or through its closest hit, as its adapter documents). The referee
/// judges the parts given; tables print "n/a" for the others, never
/// counting them right or wrong.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Answers {
    /// Barycentric `u`, `v` of a hit, in Embree's convention (`u` weights
    /// the second vertex, `v` the third).
    pub uv: bool,
    /// The geometric normal of the hit triangle.
    pub normal: bool,
}

impl Answers {
    /// Everything: `t`, triangle, `u`, `v` and the normal.
    pub const ALL: Answers = Answers {
        uv: true,
        normal: true,
    };
}

/// A tracer built over one mesh, ready to answer queries.
pub trait Backend: Intersector + Send {
    /// The name `--backends` takes for it, e.g. `ours` or `embree-robust`.
    fn name(&self) -> String;
    /// Which parts of an answer it gives.
    fn answers(&self) -> Answers;
    /// Wall time of its build.
    fn build_time(&self) -> Duration;
    /// Bytes its acceleration structure holds, where that can be known.
    fn bytes(&self) -> Option<usize>;
}

/// Who wrote a backend: how the report and the commands group them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Group {
    /// Our BVHs.
    Ours,
    /// Embree 4.4, the reference.
    Embree,
    /// Third-party Rust crates, linked in.
    Crate,
    /// Tracers in other languages, run as programs that read a mesh and a
    /// rays file and write a hits file.
    Program,
}

impl Group {
    /// Not ours and not Embree: a tracer the harness checks on a user's
    /// behalf, whose build may fail on meshes it cannot handle.
    pub fn is_third_party(self) -> bool {
        matches!(self, Group::Crate | Group::Program)
    }

    /// How help and `raycheck backends` head the group.
    pub fn title(self) -> &'static str {
        match self {
            Group::Ours => "our BVHs",
            Group::Embree => "Embree 4.4",
            Group::Crate => "third-party crates",
            Group::Program => "programs",
        }
    }
}

/// What a backend's build may use from the run: the Embree device its
/// scenes go on, and the kernel our wide BVH traverses with.
#[derive(Clone, Copy)]
pub struct BuildContext<'a> {
    pub device: &'a Device,
    pub kernel: Kernel,
}

/// The shape of a backend's tree, for the report's course table, where
/// the harness can read it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TreeShape {
    /// Depth of the deepest leaf plus one.
    pub levels: u32,
    /// The most triangles a leaf holds (for Embree an upper bound, said as
    /// such).
    pub max_leaf_triangles: String,
    pub nodes: u64,
    pub bytes: u64,
    /// The tree's SAH cost where its builder reports one.
    pub sah_cost: Option<f64>,
}

/// How a kind is named and described.
#[derive(Clone, Copy, Debug)]
pub struct Label<'a> {
    /// The name `--backends` takes for it.
    pub name: &'a str,
    /// Other spellings of the same backend (`embree-medium` for `embree`).
    pub aliases: &'static [&'static str],
    /// One line for help and `raycheck backends`: what it is.
    pub about: &'a str,
}

/// A backend `--backends` can name. Each backend's file defines its kinds
/// as statics; [`registry`] lists them.
pub trait Kind: Sync {
    /// Its name, other spellings and one line about it.
    fn label(&self) -> Label<'_>;
    fn group(&self) -> Group;
    /// Builds it over `mesh`.
    fn build(&self, mesh: &TriangleMesh, context: BuildContext)
    -> anyhow::Result<Box<dyn Backend>>;
    /// The shape of the tree it builds over `mesh`, where the harness can
    /// read it (ours and Embree); `None` for a tree it cannot.
    fn tree_shape(
        &self,
        _mesh: &TriangleMesh,
        _context: BuildContext,
    ) -> Option<anyhow::Result<TreeShape>> {
        None
    }
    /// The program it runs, for a tracer run as a program: such a kind
    /// answers through files, in batches, not from a build.
    fn program(&self) -> Option<&ProgramKind> {
        None
    }
    /// Its tree over `mesh` as the debug views that draw BVH nodes read it,
    /// where the harness can (ours); `None` otherwise.
    fn bvh_view(&self, _mesh: &TriangleMesh) -> Option<anyhow::Result<Box<dyn BvhView>>> {
        None
    }
}
