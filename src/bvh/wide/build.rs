//! The parallel top-down build of the 8-wide BVH.
//!
//! Each node is formed as in the collapse of Wald et al. 2008 and Dammertz
//! et al. ("Shallow Bounding Volume Hierarchies for Fast SIMD Ray Tracing of
//! Incoherent Rays", EGSR 2008), the way Embree's wide builders do: starting
//! from the node's whole range, the child with the largest surface area is
//! split by the binned SAH ([`binning`](super::binning)) until there are
//! eight children or none has more than a block of triangles. Close to the
//! depth limit the split is at the median instead, which halves the range,
//! so every leaf fits in one block.
//!
//! Nodes and leaf blocks are written depth first as the build goes, into
//! one pair of arrays per task: subtrees of more than
//! [`PARALLEL_THRESHOLD`] triangles are built on rayon's workers into
//! arrays of their own, appended in child order with their indices moved.
//! Every split depends only on its own range and the layout only on the
//! tree, so the result is the same whatever the thread count.

use super::binning::{Prim, RangeBounds, split};
use super::node::{BLOCK_WIDTH, Child, TriangleBlock, WIDTH, WideNode};
use crate::bvh::MAX_DEPTH;
use crate::bvh::build::usable_corners;
use crate::geometry::{Aabb, TriangleMesh};
use rayon::prelude::*;

/// Ranges of at most this many triangles become leaves (one block).
pub const LEAF_SIZE: usize = BLOCK_WIDTH;

/// Subtrees with more triangles than this are built in parallel.
const PARALLEL_THRESHOLD: usize = 1 << 16;

/// A child range of the node being formed, relative to the node's range.
#[derive(Clone, Copy)]
struct Part {
    begin: usize,
    end: usize,
    bounds: RangeBounds,
    depth: u32,
}

impl Part {
    fn len(&self) -> usize {
        self.end - self.begin
    }

    fn is_leaf(&self) -> bool {
        self.len() <= LEAF_SIZE
    }

    /// Whether the split must halve the range to reach leaves of
    /// [`LEAF_SIZE`] within [`MAX_DEPTH`] binary levels. Halving needs
    /// [`levels_to_leaves`] more levels; a split that halves keeps that
    /// within the levels left, and one that does not is allowed only while
    /// two spare levels remain, so the root's range, needing at most 30
    /// levels, always ends in leaves in time.
    fn must_halve(&self) -> bool {
        levels_to_leaves(self.len()) + 2 > MAX_DEPTH - self.depth
    }
}

/// How many levels of halving bring `len` triangles to leaves of at most
/// [`LEAF_SIZE`].
fn levels_to_leaves(len: usize) -> u32 {
    len.div_ceil(LEAF_SIZE).next_power_of_two().trailing_zeros()
}

/// The nodes (root first, depth first) and leaf blocks of a subtree.
struct Tree {
    nodes: Vec<WideNode>,
    blocks: Vec<TriangleBlock>,
}

impl Tree {
    /// An empty tree with room for the nodes and blocks of `triangles`
    /// triangles in a typical build.
    fn with_capacity(triangles: usize) -> Self {
        Tree {
            nodes: Vec::with_capacity(triangles / 8),
            blocks: Vec::with_capacity(triangles / 3),
        }
    }

    /// Appends `subtree`, moving its indices past what is here; returns
    /// the index of its root.
    fn append(&mut self, subtree: Tree) -> usize {
        let (node_offset, block_offset) = (self.nodes.len(), self.blocks.len());
        self.nodes.extend(
            subtree
                .nodes
                .into_iter()
                .map(|node| node.moved(node_offset, block_offset)),
        );
        self.blocks.extend(subtree.blocks);
        node_offset
    }

    /// Stores `prims` (at most [`LEAF_SIZE`]) as a leaf.
    fn leaf(&mut self, prims: &[Prim], mesh: &TriangleMesh) -> Child {
        self.blocks.push(TriangleBlock::new(
            prims
                .iter()
                .map(|p| (p.prim(), mesh.triangle(p.prim() as usize))),
        ));
        Child::Leaf(self.blocks.len() - 1)
    }
}

/// The tree's nodes (root first, depth first) and triangle blocks, and the
/// number of mesh triangles left out.
pub(super) fn build(mesh: &TriangleMesh) -> (Vec<WideNode>, Vec<TriangleBlock>, usize) {
    let mut prims: Vec<Prim> = (0..mesh.indices.len())
        .into_par_iter()
        .filter_map(|prim| Some(Prim::new(prim as u32, usable_corners(mesh, prim)?)))
        .collect();
    let skipped = mesh.indices.len() - prims.len();
    if prims.is_empty() {
        return (Vec::new(), Vec::new(), skipped);
    }
    let bounds = prims
        .par_chunks(PARALLEL_THRESHOLD)
        .map(RangeBounds::of)
        .reduce(|| RangeBounds::EMPTY, RangeBounds::union);
    let mut tree = Tree::with_capacity(prims.len());
    build_node(&mut prims, bounds, 0, mesh, &mut tree);
    (tree.nodes, tree.blocks, skipped)
}

/// Forms the node over `prims` (with bounds `bounds`, at binary depth
/// `depth`) and its subtree, appending them to `tree`; returns its index.
fn build_node(
    prims: &mut [Prim],
    bounds: RangeBounds,
    depth: u32,
    mesh: &TriangleMesh,
    tree: &mut Tree,
) -> usize {
    let index = tree.nodes.len();
    tree.nodes.push(WideNode::new(&[]));
    let (parts, count) = children(prims, bounds, depth);
    let parts = &parts[..count];

    // Above the threshold, the inner children are built in parallel, each
    // into a tree of its own.
    let mut subtrees: Vec<Option<Tree>> = Vec::new();
    if prims.len() > PARALLEL_THRESHOLD {
        let mut rest = &mut *prims;
        let mut jobs = Vec::with_capacity(count);
        for part in parts {
            let (range, tail) = rest.split_at_mut(part.len());
            rest = tail;
            jobs.push((*part, range));
        }
        subtrees = jobs
            .into_par_iter()
            .map(|(part, range)| {
                (!part.is_leaf()).then(|| {
                    let mut subtree = Tree::with_capacity(part.len());
                    build_node(range, part.bounds, part.depth, mesh, &mut subtree);
                    subtree
                })
            })
            .collect();
    }

    let mut children: [(Aabb, Child); WIDTH] = std::array::from_fn(|_| (Aabb::EMPTY, Child::Empty));
    for (slot, part) in parts.iter().enumerate() {
        let range = &mut prims[part.begin..part.end];
        let child = if part.is_leaf() {
            tree.leaf(range, mesh)
        } else if let Some(subtree) = subtrees.get_mut(slot).and_then(Option::take) {
            Child::Inner(tree.append(subtree))
        } else {
            Child::Inner(build_node(range, part.bounds, part.depth, mesh, tree))
        };
        let boxes = &part.bounds.boxes;
        children[slot] = (
            Aabb {
                min: boxes.lower(),
                max: boxes.upper(),
            },
            child,
        );
    }
    tree.nodes[index] = WideNode::new(&children[..count]);
    index
}

/// Splits `prims` into at most [`WIDTH`] children by splitting the child
/// of largest surface area that is not a leaf (ties to the first) until
/// there are [`WIDTH`] or all are leaves; returns them in order with their
/// count.
fn children(prims: &mut [Prim], bounds: RangeBounds, depth: u32) -> ([Part; WIDTH], usize) {
    let whole = Part {
        begin: 0,
        end: prims.len(),
        bounds,
        depth,
    };
    let mut parts = [whole; WIDTH];
    let mut count = 1;
    while count < WIDTH {
        let widest = parts[..count]
            .iter()
            .enumerate()
            .filter(|(_, p)| !p.is_leaf())
            .fold(None::<(usize, f32)>, |best, (i, p)| {
                let area = p.bounds.half_area();
                match best {
                    Some((_, a)) if a >= area => best,
                    _ => Some((i, area)),
                }
            });
        let Some((i, _)) = widest else { break };
        let part = parts[i];
        let (mid, left, right) = split(
            &mut prims[part.begin..part.end],
            &part.bounds,
            part.must_halve(),
        );
        let side = |begin: usize, end: usize, bounds: RangeBounds| Part {
            begin,
            end,
            bounds,
            depth: part.depth + 1,
        };
        parts.copy_within(i + 1..count, i + 2);
        parts[i] = side(part.begin, part.begin + mid, left);
        parts[i + 1] = side(part.begin + mid, part.end, right);
        count += 1;
    }
    (parts, count)
}
