//! The top-down build shared by both builders: gather the usable triangles,
//! split node ranges until the builder says "leaf", then store the triangles
//! in leaf order.

mod median;
pub(super) mod sah;

use super::capacity::{CapacityError, Needs};
use super::stats::BvhStats;
use super::{BuildOptions, Builder, Bvh, Node};
use crate::geometry::triangle::geometric_normal;
use crate::geometry::{Aabb, TriangleMesh};
use glam::Vec3;
use std::time::Instant;

/// The largest vertex coordinate magnitude Embree accepts; triangles with a
/// vertex beyond it (or not finite) are dropped at commit, and so here.
pub const MAX_COORDINATE: f32 = 1.844e18;

/// One triangle as the builders see it.
#[derive(Clone, Copy, Debug)]
pub(super) struct BuildPrim {
    pub(super) bounds: Aabb,
    centroid: Vec3,
    pub(super) prim: u32,
}

impl BuildPrim {
    pub(super) fn new(prim: u32, corners: [Vec3; 3]) -> Self {
        let bounds = Aabb::from_points(&corners);
        Self {
            bounds,
            // Halving first cannot overflow.
            centroid: 0.5 * bounds.min + 0.5 * bounds.max,
            prim,
        }
    }
}

pub(super) fn bounds_of(prims: &[BuildPrim]) -> Aabb {
    prims.iter().fold(Aabb::EMPTY, |b, p| b.union(p.bounds))
}

fn centroid_bounds(prims: &[BuildPrim]) -> Aabb {
    prims.iter().fold(Aabb::EMPTY, |b, p| b.grow(p.centroid))
}

/// The corners of triangle `prim`, or `None` when an index is out of range,
/// a coordinate is not finite or beyond [`MAX_COORDINATE`], or the
/// triangle's [`geometric_normal`] is zero: the watertight test never hits
/// such a triangle
/// ([`intersect_in`](crate::geometry::triangle::WatertightRay::intersect_in)),
/// so no tree stores it, and the traversals finish candidates without
/// testing the normal
/// ([`hit_within_edges`](crate::geometry::triangle::WatertightRay::hit_within_edges)).
///
/// Inlined: called from the wide build's first pass, it returned the
/// corners through memory and the pass stalled reading them back (the
/// monkey's one-thread build, medians of six alternating `perf` runs
/// each, Xeon: 0.835 ms called, 0.792 ms inlined). Always: with the
/// normal's test a plain `#[inline]` no longer inlined it, and that pass
/// took 4% of the monkey's build instead of 1.5% (AMD EPYC).
#[inline(always)]
pub(super) fn usable_corners(mesh: &TriangleMesh, prim: usize) -> Option<[Vec3; 3]> {
    let [a, b, c] = mesh.indices[prim];
    let corner = |i: u32| mesh.positions.get(i as usize).copied();
    let corners = [corner(a)?, corner(b)?, corner(c)?];
    let within = |p: &Vec3| p.abs().cmple(Vec3::splat(MAX_COORDINATE)).all();
    let [p0, p1, p2] = corners;
    (corners.iter().all(within) && geometric_normal(p0, p1, p2) != Vec3::ZERO).then_some(corners)
}

/// A node whose triangle range is still to be split.
struct Task {
    node: usize,
    begin: usize,
    end: usize,
    depth: u32,
}

/// What the binary BVH indexes and needs to build: node counts (up to
/// twice the triangles) and triangle slots in 32 bits, and about 40 bytes
/// per triangle of working copy and 56 of tree, 128 with room.
const NEEDS: Needs = Needs {
    tree: "binary BVH",
    max_triangles: (1 << 31) - 1,
    bytes_per_triangle: 128,
};

impl Bvh {
    /// Builds a BVH over `mesh`'s usable triangles (see [`MAX_COORDINATE`];
    /// out-of-range indices are dropped too), after checking that the mesh
    /// fits the tree's indices and the memory available. Empty and
    /// one-triangle meshes give a tree with 0 and 1 nodes.
    pub fn try_build(mesh: &TriangleMesh, options: &BuildOptions) -> Result<Bvh, CapacityError> {
        NEEDS.check(mesh.indices.len())?;
        Ok(Self::build_checked(mesh, options))
    }

    /// [`Bvh::try_build`] for meshes known to fit.
    ///
    /// # Panics
    /// When `try_build` would fail; use it for meshes from outside.
    pub fn build(mesh: &TriangleMesh, options: &BuildOptions) -> Bvh {
        Self::try_build(mesh, options).unwrap_or_else(|error| panic!("{error}"))
    }

    fn build_checked(mesh: &TriangleMesh, options: &BuildOptions) -> Bvh {
        let started = Instant::now();
        let options = options.clamped();
        let mut prims: Vec<BuildPrim> = (0..mesh.indices.len())
            .filter_map(|prim| Some(BuildPrim::new(prim as u32, usable_corners(mesh, prim)?)))
            .collect();
        let skipped = mesh.indices.len() - prims.len();

        let mut nodes = Vec::new();
        if !prims.is_empty() {
            nodes.reserve(2 * prims.len().div_ceil(options.max_leaf_size as usize));
            nodes.push(Node::leaf(bounds_of(&prims), 0, prims.len() as u32));
            let mut tasks = vec![Task {
                node: 0,
                begin: 0,
                end: prims.len(),
                depth: 0,
            }];
            while let Some(task) = tasks.pop() {
                split_node(&mut nodes, &mut prims, &mut tasks, task, &options);
            }
        }

        let triangles: Vec<[Vec3; 3]> = prims
            .iter()
            .map(|p| mesh.triangle(p.prim as usize))
            .collect();
        let prim_ids = prims.iter().map(|p| p.prim).collect();
        let stats = BvhStats::measure(&nodes, triangles.len(), skipped, started.elapsed());
        Bvh {
            nodes,
            triangles,
            prim_ids,
            options,
            stats,
        }
    }
}

/// Turns `task`'s leaf into an inner node with two new leaf children when
/// the builder finds a split, queueing the children.
fn split_node(
    nodes: &mut Vec<Node>,
    prims: &mut [BuildPrim],
    tasks: &mut Vec<Task>,
    task: Task,
    options: &BuildOptions,
) {
    let range = &mut prims[task.begin..task.end];
    if range.len() <= 1 || task.depth >= options.max_depth {
        return;
    }
    let must_split = range.len() > options.max_leaf_size as usize;
    let mid = match options.builder {
        Builder::Median => must_split.then(|| median::partition(range)),
        Builder::Sah => sah::partition(
            range,
            nodes[task.node].bounds(),
            options.sah_bins as usize,
            must_split,
        ),
    };
    let Some(mid) = mid else { return };
    let (left, right) = range.split_at(mid);
    let first_child = nodes.len();
    nodes.push(Node::leaf(
        bounds_of(left),
        task.begin as u32,
        left.len() as u32,
    ));
    nodes.push(Node::leaf(
        bounds_of(right),
        (task.begin + mid) as u32,
        right.len() as u32,
    ));
    nodes[task.node] = Node::inner(nodes[task.node].bounds(), first_child as u32);
    let depth = task.depth + 1;
    tasks.push(Task {
        node: first_child + 1,
        begin: task.begin + mid,
        end: task.end,
        depth,
    });
    tasks.push(Task {
        node: first_child,
        begin: task.begin,
        end: task.begin + mid,
        depth,
    });
}
