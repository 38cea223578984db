//! The fast path: an 8-wide BVH answering exactly as the binary BVHs do.
//!
//! Built in parallel with the binned SAH (Wald 2007) and formed 8-wide as in
//! Wald et al. 2008 and Dammertz et al. 2008; nodes keep their children's
//! boxes as a structure of arrays and each leaf is one block of up to eight
//! triangles stored the same way, copied in leaf order so a leaf needs no
//! index lookup. The traversal tests eight boxes or eight triangles at a
//! time with SIMD when the CPU has it (chosen at run time, see [`Kernel`]),
//! and has a separate any-hit loop. Whatever kernel runs, each hit is the one the binary BVH
//! and [`crate::bvh::Bvh::intersect_brute_force`] give, bit for bit.
//!
//! ```
//! use glam::Vec3;
//! use raycheck::bvh::wide::WideBvh;
//! use raycheck::geometry::{Ray, TriangleMesh};
//! use raycheck::trace::Intersector;
//!
//! let mesh = TriangleMesh {
//!     positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
//!     indices: vec![[0, 1, 2]],
//!     materials: vec![0],
//!     ..Default::default()
//! };
//! let bvh = WideBvh::build(&mesh);
//! bvh.validate(&mesh).unwrap();
//! let hit = bvh.intersect(&Ray::new(Vec3::new(0.25, 0.25, 1.0), Vec3::NEG_Z)).unwrap();
//! assert_eq!((hit.t, hit.u, hit.v, hit.prim), (1.0, 0.25, 0.25, 0));
//! ```

#[cfg(target_arch = "x86_64")]
mod avx512;
mod awake;
#[cfg(target_arch = "x86_64")]
mod behind;
mod binning;
mod build;
#[cfg(target_arch = "x86_64")]
mod candidates;
mod cluster;
mod core_cache;
mod crossings;
mod huge_pages;
mod kernel;
mod lanes;
mod leaf_fill;
mod node;
mod prefetch;
#[cfg(target_arch = "x86_64")]
mod simd;
mod stats;
mod traverse;
mod validate;
#[cfg(target_arch = "x86_64")]
mod vector;

#[cfg(test)]
mod tests;

pub use build::LEAF_SIZE;
pub use kernel::{Kernel, KernelChoice, UnknownKernel, UnsupportedKernel};
pub use node::{BLOCK_WIDTH, Child, MAX_INDEX, TriangleBlock, WIDTH, WideNode};
pub use stats::WideStats;
pub use validate::WideValidationError;

use crate::bvh::capacity::{CapacityError, Needs};
use crate::bvh::traverse::{NodeVisits, Uncounted};
use crate::geometry::{Aabb, Hit, Ray, TriangleMesh};
use crate::trace::Intersector;
use node::EdgeNorms;
use prefetch::Prefetch;
use std::time::{Duration, Instant};

/// An 8-wide BVH over one mesh's usable triangles (the same triangles as
/// [`crate::bvh::Bvh`] keeps).
#[derive(Clone, Debug)]
pub struct WideBvh {
    nodes: Vec<WideNode>,
    blocks: Vec<TriangleBlock>,
    /// Each block's edge norms, for the any-hit filter.
    edge_norms: Vec<EdgeNorms>,
    /// The root's box: every stored corner lies in it.
    bounds: Aabb,
    triangles: usize,
    skipped_triangles: usize,
    build_time: Duration,
    kernel: Kernel,
    /// Which children the traversal prefetches, by the tree's size
    /// against the caches.
    prefetch: Prefetch,
    /// Whether the leaves leave most of their boxes empty, so that
    /// incoherent rays filter them first (`leaf_fill`).
    sparse_leaves: bool,
}

/// What the 8-wide BVH indexes and needs to build: node and block
/// indices below [`MAX_INDEX`] (each at most one per triangle), and about
/// 32 bytes per triangle of working copy and 65 of tree, 128 with room.
const NEEDS: Needs = Needs {
    tree: "8-wide BVH",
    max_triangles: MAX_INDEX,
    bytes_per_triangle: 128,
};

impl WideBvh {
    /// Builds the tree on the current rayon pool, traversed with
    /// [`Kernel::detect`], after checking that the mesh fits the tree's
    /// indices and the memory available. An empty mesh gives an empty tree.
    pub fn try_build(mesh: &TriangleMesh) -> Result<WideBvh, CapacityError> {
        NEEDS.check(mesh.indices.len())?;
        Ok(Self::build_checked(mesh))
    }

    /// [`WideBvh::try_build`] for meshes known to fit.
    ///
    /// # Panics
    /// When `try_build` would fail; use it for meshes from outside.
    pub fn build(mesh: &TriangleMesh) -> WideBvh {
        Self::try_build(mesh).unwrap_or_else(|error| panic!("{error}"))
    }

    fn build_checked(mesh: &TriangleMesh) -> WideBvh {
        let started = Instant::now();
        let build::Built {
            nodes,
            blocks,
            edge_norms,
            skipped_triangles,
            sparse_leaves,
        } = build::build(mesh);
        let mut bvh = WideBvh {
            bounds: nodes.first().map_or(Aabb::EMPTY, WideNode::bounds),
            triangles: mesh.indices.len() - skipped_triangles,
            nodes,
            blocks,
            edge_norms,
            skipped_triangles,
            build_time: started.elapsed(),
            kernel: Kernel::detect(),
            prefetch: Prefetch::Nothing,
            sparse_leaves,
        };
        bvh.prefetch = Prefetch::for_tree(bvh.bytes());
        bvh
    }

    /// The same tree traversed with `kernel`, or `None` if this CPU cannot
    /// run it.
    pub fn with_kernel(self, kernel: Kernel) -> Option<WideBvh> {
        kernel.is_supported().then_some(WideBvh { kernel, ..self })
    }

    pub fn kernel(&self) -> Kernel {
        self.kernel
    }

    /// The nodes, root first; empty for a mesh with no usable triangle.
    pub fn nodes(&self) -> &[WideNode] {
        &self.nodes
    }

    /// The triangle blocks in leaf order.
    pub fn blocks(&self) -> &[TriangleBlock] {
        &self.blocks
    }

    /// Triangles in the tree.
    pub fn triangles(&self) -> usize {
        self.triangles
    }

    /// Mesh triangles left out (see [`crate::bvh::MAX_COORDINATE`]).
    pub fn skipped_triangles(&self) -> usize {
        self.skipped_triangles
    }

    pub fn build_time(&self) -> Duration {
        self.build_time
    }

    /// Memory held by the nodes, the triangle blocks and their edge norms.
    pub fn bytes(&self) -> usize {
        std::mem::size_of_val(self.nodes.as_slice())
            + std::mem::size_of_val(self.blocks.as_slice())
            + std::mem::size_of_val(self.edge_norms.as_slice())
    }
}

impl WideBvh {
    /// The closest hit, as [`Intersector::intersect`], counting every node
    /// and leaf block visited into `visits` (the same count with every
    /// kernel: they visit the same nodes).
    pub fn intersect_counted(&self, ray: &Ray, visits: &mut impl NodeVisits) -> Option<Hit> {
        self.closest::<false>(ray, visits)
    }

    /// The closest hit; with `FILTER_LEAVES`, each leaf goes through the
    /// any-hit filter before the kernel (the same answer).
    #[inline(always)]
    fn closest<const FILTER_LEAVES: bool>(
        &self,
        ray: &Ray,
        visits: &mut impl NodeVisits,
    ) -> Option<Hit> {
        match self.kernel {
            Kernel::Scalar => scalar::intersect::<FILTER_LEAVES>(self, ray, visits),
            // SAFETY: `kernel` names a SIMD kernel only when the CPU has
            // its features (`with_kernel` and `detect` check `is_supported`).
            #[cfg(target_arch = "x86_64")]
            Kernel::Avx2 => unsafe { x86::avx2_intersect::<FILTER_LEAVES>(self, ray, visits) },
            // SAFETY: as above.
            #[cfg(target_arch = "x86_64")]
            Kernel::Avx512 => unsafe {
                x86::avx512_intersect::<false, FILTER_LEAVES>(self, ray, visits)
            },
            // SAFETY: as above.
            #[cfg(target_arch = "x86_64")]
            Kernel::Avx512Zmm => unsafe {
                x86::avx512_intersect::<true, FILTER_LEAVES>(self, ray, visits)
            },
            #[cfg(not(target_arch = "x86_64"))]
            Kernel::Avx2 | Kernel::Avx512 | Kernel::Avx512Zmm => {
                unreachable!("SIMD kernels run only on x86-64")
            }
        }
    }
}

impl Intersector for WideBvh {
    fn intersect(&self, ray: &Ray) -> Option<Hit> {
        self.closest::<false>(ray, &mut Uncounted)
    }

    /// Filters each leaf first where the leaves are sparse (`leaf_fill`).
    fn intersect_incoherent(&self, ray: &Ray) -> Option<Hit> {
        if self.sparse_leaves {
            self.closest::<true>(ray, &mut Uncounted)
        } else {
            self.closest::<false>(ray, &mut Uncounted)
        }
    }

    fn occluded(&self, ray: &Ray) -> bool {
        match self.kernel {
            Kernel::Scalar => scalar::occluded(self, ray),
            // SAFETY: as in `closest`.
            #[cfg(target_arch = "x86_64")]
            Kernel::Avx2 => unsafe { x86::avx2_occluded(self, ray) },
            // SAFETY: as in `closest`. Any-hit rays test one leaf at a
            // time with either AVX-512 kernel.
            #[cfg(target_arch = "x86_64")]
            Kernel::Avx512 | Kernel::Avx512Zmm => unsafe { x86::avx512_occluded(self, ray) },
            #[cfg(not(target_arch = "x86_64"))]
            Kernel::Avx2 | Kernel::Avx512 | Kernel::Avx512Zmm => {
                unreachable!("SIMD kernels run only on x86-64")
            }
        }
    }
}

/// The traversals with the scalar kernel, out of line like the SIMD ones.
/// Inlined into the dispatch, the any-hit one's frame (a traversal stack
/// of 5 KiB, aligned to a cache line) was set up on every query whatever
/// kernel answered it: 18 of the 524 instructions of a Cornell box shadow
/// ray (AVX2 kernel, callgrind).
mod scalar {
    use super::{WideBvh, lanes::Scalar, traverse};
    use crate::bvh::traverse::NodeVisits;
    use crate::geometry::{Hit, Ray};

    #[inline(never)]
    pub(super) fn intersect<const FILTER_LEAVES: bool>(
        bvh: &WideBvh,
        ray: &Ray,
        visits: &mut impl NodeVisits,
    ) -> Option<Hit> {
        traverse::intersect::<Scalar, FILTER_LEAVES>(bvh, ray, visits)
    }

    #[inline(never)]
    pub(super) fn occluded(bvh: &WideBvh, ray: &Ray) -> bool {
        traverse::occluded::<Scalar>(bvh, ray)
    }
}

/// The traversals with the SIMD kernels inlined, each compiled for its
/// instruction set (with FMA for the any-hit filter, and BMI1's `tzcnt`
/// and POPCNT's `popcnt` for the lane masks).
#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::{WideBvh, avx512::Avx512, simd::Avx2, traverse};
    use crate::bvh::traverse::NodeVisits;
    use crate::geometry::{Hit, Ray};

    #[target_feature(enable = "avx2,fma,bmi1,popcnt")]
    pub(super) fn avx2_intersect<const FILTER_LEAVES: bool>(
        bvh: &WideBvh,
        ray: &Ray,
        visits: &mut impl NodeVisits,
    ) -> Option<Hit> {
        traverse::intersect::<Avx2, FILTER_LEAVES>(bvh, ray, visits)
    }

    #[target_feature(enable = "avx2,fma,bmi1,popcnt")]
    pub(super) fn avx2_occluded(bvh: &WideBvh, ray: &Ray) -> bool {
        traverse::occluded::<Avx2>(bvh, ray)
    }

    #[target_feature(enable = "avx512f,avx512vl,avx512dq,avx2,fma,bmi1,popcnt")]
    pub(super) fn avx512_intersect<const PAIRS: bool, const FILTER_LEAVES: bool>(
        bvh: &WideBvh,
        ray: &Ray,
        visits: &mut impl NodeVisits,
    ) -> Option<Hit> {
        traverse::intersect::<Avx512<PAIRS>, FILTER_LEAVES>(bvh, ray, visits)
    }

    #[target_feature(enable = "avx512f,avx512vl,avx512dq,avx2,fma,bmi1,popcnt")]
    pub(super) fn avx512_occluded(bvh: &WideBvh, ray: &Ray) -> bool {
        traverse::occluded::<Avx512<false>>(bvh, ray)
    }
}
