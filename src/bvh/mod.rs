//! Binary bounding volume hierarchies over a triangle mesh: a median-split
//! builder as in a classic course tracer, a binned-SAH builder (Wald 2007),
//! near-child-first traversal, statistics and an invariant checker.
//!
//! ```
//! use glam::Vec3;
//! use raycheck::bvh::{BuildOptions, Bvh};
//! use raycheck::geometry::{Ray, TriangleMesh};
//! use raycheck::trace::Intersector;
//!
//! let mesh = TriangleMesh {
//!     positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
//!     indices: vec![[0, 1, 2]],
//!     materials: vec![0],
//!     ..Default::default()
//! };
//! let bvh = Bvh::build(&mesh, &BuildOptions::sah());
//! bvh.validate(&mesh).unwrap();
//! let hit = bvh.intersect(&Ray::new(Vec3::new(0.25, 0.25, 1.0), Vec3::NEG_Z)).unwrap();
//! assert_eq!((hit.t, hit.u, hit.v, hit.prim), (1.0, 0.25, 0.25, 0));
//! ```

mod build;
mod capacity;
#[cfg(test)]
mod measure;
mod node;
mod ray_box;
mod stats;
#[cfg(test)]
mod test_meshes;
mod traverse;
mod validate;
mod view;
pub mod wide;

pub use build::MAX_COORDINATE;
pub use capacity::{CapacityError, available_memory};
pub use node::Node;
pub use stats::{BvhStats, INTERSECTION_COST, TRAVERSAL_COST};
pub use validate::ValidationError;
pub use view::BvhView;

use glam::Vec3;

/// The deepest a tree may be (root at depth 0). Options asking for more are
/// clamped to it; it sizes the fixed traversal stack.
pub const MAX_DEPTH: u32 = 64;

/// The most SAH bins a build uses; options asking for more are clamped.
pub const MAX_SAH_BINS: u32 = 256;

/// How a node's triangles are split in two.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Builder {
    /// At the median centroid along the longest axis of the centroid bounds.
    Median,
    /// At the cheapest of the binned surface-area-heuristic candidates.
    Sah,
}

/// What to build and the limits the tree must respect.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BuildOptions {
    pub builder: Builder,
    /// Deepest leaf depth (root = 0), at most [`MAX_DEPTH`]. A leaf at this
    /// depth may exceed `max_leaf_size`.
    pub max_depth: u32,
    /// Most triangles in a leaf (at least 1).
    pub max_leaf_size: u32,
    /// Bins per axis of the SAH builder (2 ..= [`MAX_SAH_BINS`]).
    pub sah_bins: u32,
}

impl BuildOptions {
    /// Median split with up to 4 triangles per leaf.
    pub fn median() -> Self {
        Self {
            builder: Builder::Median,
            max_depth: MAX_DEPTH,
            max_leaf_size: 4,
            sah_bins: 16,
        }
    }

    /// Binned SAH with 16 bins; leaves of up to 8 triangles, each kept only
    /// where the SAH finds no cheaper split.
    pub fn sah() -> Self {
        Self {
            builder: Builder::Sah,
            max_depth: MAX_DEPTH,
            max_leaf_size: 8,
            sah_bins: 16,
        }
    }

    /// The options with every limit brought into its valid range.
    pub fn clamped(&self) -> Self {
        Self {
            builder: self.builder,
            max_depth: self.max_depth.min(MAX_DEPTH),
            max_leaf_size: self.max_leaf_size.max(1),
            sah_bins: self.sah_bins.clamp(2, MAX_SAH_BINS),
        }
    }
}

impl Default for BuildOptions {
    fn default() -> Self {
        Self::sah()
    }
}

/// A BVH over one mesh's triangles.
///
/// Nodes live in one flat array with the root first and siblings adjacent.
/// The BVH keeps its own copy of the triangles' corners in leaf order, with
/// the mesh's triangle index per slot, so leaves need no index lookup.
#[derive(Clone, Debug)]
pub struct Bvh {
    nodes: Vec<Node>,
    triangles: Vec<[Vec3; 3]>,
    prim_ids: Vec<u32>,
    options: BuildOptions,
    stats: BvhStats,
}

impl Bvh {
    /// The nodes, root first; empty for a mesh with no usable triangle.
    pub fn nodes(&self) -> &[Node] {
        &self.nodes
    }

    /// The triangles' corners in leaf order.
    pub fn triangles(&self) -> &[[Vec3; 3]] {
        &self.triangles
    }

    /// The mesh triangle index of each slot of [`Bvh::triangles`].
    pub fn prim_ids(&self) -> &[u32] {
        &self.prim_ids
    }

    /// The options the tree was built with, after [`BuildOptions::clamped`].
    pub fn options(&self) -> &BuildOptions {
        &self.options
    }

    pub fn stats(&self) -> &BvhStats {
        &self.stats
    }
}
