//! The parallel top-down build of the 8-wide BVH.
//!
//! Each node is formed as in the collapse of Wald et al. 2008 and Dammertz
//! et al. ("Shallow Bounding Volume Hierarchies for Fast SIMD Ray Tracing of
//! Incoherent Rays", EGSR 2008): starting from the node's whole range, the
//! child with the largest surface area is split by the binned SAH (Wald
//! 2007, the readable builder's own `sah::partition`) until there are eight
//! children or none can be split. Close to the depth limit the split is at
//! the median instead, which halves the range, so every leaf fits in one
//! block. Children of more than
//! [`PARALLEL_THRESHOLD`] triangles are built on rayon's workers. Every
//! split depends only on its own range, so the tree is the same whatever
//! the thread count. Afterwards the nodes are laid out depth first and the
//! triangles copied into 4-wide blocks in leaf order.

use super::node::{BLOCK_WIDTH, Child, TriangleBlock, WIDTH, WideNode};
use crate::bvh::build::median;
use crate::bvh::build::sah::partition;
use crate::bvh::build::{BuildPrim, bounds_of, usable_corners};
use crate::bvh::stats::surface_area;
use crate::bvh::{BuildOptions, MAX_DEPTH};
use crate::geometry::{Aabb, TriangleMesh};
use rayon::prelude::*;

/// Ranges of at most this many triangles become leaves (one block).
pub const LEAF_SIZE: usize = BLOCK_WIDTH;

/// Subtrees with more triangles than this are built in parallel.
const PARALLEL_THRESHOLD: usize = 4096;

/// A built subtree before the nodes are laid out.
enum Subtree {
    /// Triangles `begin .. begin + len` of the build order.
    Leaf {
        begin: usize,
        len: usize,
    },
    Inner(Vec<(Aabb, Subtree)>),
}

/// A child range of the node being formed.
#[derive(Clone, Copy)]
struct Part {
    begin: usize,
    len: usize,
    bounds: Aabb,
    depth: u32,
}

impl Part {
    fn splittable(&self) -> bool {
        self.len > LEAF_SIZE
    }

    /// Whether the split must halve the range to reach leaves of
    /// [`LEAF_SIZE`] within [`MAX_DEPTH`] binary levels. Halving needs
    /// [`levels_to_leaves`] more levels; a split that halves keeps that
    /// within the levels left, and one that does not is allowed only while
    /// two spare levels remain, so the root's range, needing at most 30
    /// levels, always ends in leaves in time.
    fn must_halve(&self) -> bool {
        levels_to_leaves(self.len) + 2 > MAX_DEPTH - self.depth
    }
}

/// How many levels of halving bring `len` triangles to leaves of at most
/// [`LEAF_SIZE`].
fn levels_to_leaves(len: usize) -> u32 {
    len.div_ceil(LEAF_SIZE).next_power_of_two().trailing_zeros()
}

/// The tree's nodes (root first, depth first) and triangle blocks, and the
/// number of mesh triangles left out.
pub(super) fn build(mesh: &TriangleMesh) -> (Vec<WideNode>, Vec<TriangleBlock>, usize) {
    let mut prims: Vec<BuildPrim> = (0..mesh.indices.len())
        .into_par_iter()
        .filter_map(|prim| Some(BuildPrim::new(prim as u32, usable_corners(mesh, prim)?)))
        .collect();
    let skipped = mesh.indices.len() - prims.len();
    if prims.is_empty() {
        return (Vec::new(), Vec::new(), skipped);
    }
    let bounds = bounds_of(&prims);
    let root = node_children(&mut prims, 0, bounds, 0);
    let mut nodes = Vec::with_capacity(prims.len() / 2);
    let mut blocks = Vec::with_capacity(prims.len() / 2);
    lay_out(root, &prims, mesh, &mut nodes, &mut blocks);
    (nodes, blocks, skipped)
}

/// Forms the children of the node over `prims` (whose first triangle is
/// number `offset` of the build order) and builds their subtrees.
fn node_children(
    prims: &mut [BuildPrim],
    offset: usize,
    bounds: Aabb,
    depth: u32,
) -> Vec<(Aabb, Subtree)> {
    let bins = BuildOptions::sah().sah_bins as usize;
    let mut parts = vec![Part {
        begin: 0,
        len: prims.len(),
        bounds,
        depth,
    }];
    while parts.len() < WIDTH {
        // The largest splittable child; ties go to the first.
        let widest = parts
            .iter()
            .enumerate()
            .filter(|(_, p)| p.splittable())
            .fold(None::<(usize, f64)>, |best, (i, p)| {
                let area = surface_area(&p.bounds);
                match best {
                    Some((_, a)) if a >= area => best,
                    _ => Some((i, area)),
                }
            });
        let Some((i, _)) = widest else { break };
        let part = parts[i];
        let range = &mut prims[part.begin..part.begin + part.len];
        let mid = if part.must_halve() {
            median::partition(range)
        } else {
            partition(range, part.bounds, bins, true)
                .expect("a forced split of two or more triangles")
        };
        let (left, right) = range.split_at(mid);
        let child = |begin: usize, side: &[BuildPrim]| Part {
            begin,
            len: side.len(),
            bounds: bounds_of(side),
            depth: part.depth + 1,
        };
        let halves = [child(part.begin, left), child(part.begin + mid, right)];
        parts.splice(i..=i, halves);
    }

    // `parts` covers `prims` in order, so it can be cut into disjoint slices.
    let mut rest = prims;
    let mut jobs = Vec::with_capacity(parts.len());
    for part in &parts {
        let (range, tail) = rest.split_at_mut(part.len);
        rest = tail;
        jobs.push((*part, range));
    }
    let build_child = |(part, range): (Part, &mut [BuildPrim])| {
        let subtree = if part.splittable() {
            Subtree::Inner(node_children(
                range,
                offset + part.begin,
                part.bounds,
                part.depth,
            ))
        } else {
            Subtree::Leaf {
                begin: offset + part.begin,
                len: part.len,
            }
        };
        (part.bounds, subtree)
    };
    if prims_len(&parts) > PARALLEL_THRESHOLD {
        jobs.into_par_iter().map(build_child).collect()
    } else {
        jobs.into_iter().map(build_child).collect()
    }
}

fn prims_len(parts: &[Part]) -> usize {
    parts.iter().map(|p| p.len).sum()
}

/// Appends the node with `children` and its subtree, depth first; returns
/// its index.
fn lay_out(
    children: Vec<(Aabb, Subtree)>,
    prims: &[BuildPrim],
    mesh: &TriangleMesh,
    nodes: &mut Vec<WideNode>,
    blocks: &mut Vec<TriangleBlock>,
) -> usize {
    let index = nodes.len();
    nodes.push(WideNode::new(&[]));
    let slots: Vec<(Aabb, Child)> = children
        .into_iter()
        .map(|(bounds, subtree)| {
            let child = match subtree {
                Subtree::Leaf { begin, len } => {
                    blocks.push(TriangleBlock::new(
                        prims[begin..begin + len]
                            .iter()
                            .map(|p| (p.prim, mesh.triangle(p.prim as usize))),
                    ));
                    Child::Leaf(blocks.len() - 1)
                }
                Subtree::Inner(grandchildren) => {
                    Child::Inner(lay_out(grandchildren, prims, mesh, nodes, blocks))
                }
            };
            (bounds, child)
        })
        .collect();
    nodes[index] = WideNode::new(&slots);
    index
}
