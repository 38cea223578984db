//! The parallel top-down build of the 8-wide BVH.
//!
//! Each node is formed as in the collapse of Wald et al. 2008 and Dammertz
//! et al. ("Shallow Bounding Volume Hierarchies for Fast SIMD Ray Tracing of
//! Incoherent Rays", EGSR 2008), the way Embree's wide builders do: starting
//! from the node's whole range, the child with the largest surface area is
//! split by the binned SAH ([`binning`](super::binning)) until there are
//! eight children or none has more than a block of triangles. Close to the
//! depth limit the split is at the median instead, which halves the range,
//! so every leaf fits in one block. Slots still free then take halves of
//! the widest leaves where that saves enough block tests by the SAH
//! ([`LEAF_SPLIT_SAVING`]): a small mesh's few leaves get tight boxes. A
//! mesh that fits in the leaves of one node is grouped into them bottom
//! up instead ([`cluster`]).
//!
//! The build runs in two passes so that the tree's arrays are written
//! once. The first plans the tree: it orders the triangles and forms every
//! node (boxes, octant orders), with its children named by where they are
//! in the plan; subtrees of more than [`PARALLEL_THRESHOLD`] triangles are
//! planned on rayon's workers into plans of their own, and within a node
//! two sides of that size are split at once ([`split_both_ahead`]). The
//! second lays the nodes out depth first, numbering nodes and leaves as it
//! meets them (leaves so come in triangle order), and then writes the leaf
//! blocks in parallel straight into the final array, from the triangles'
//! ids alone (their boxes freed first), and measures how much of their
//! boxes the leaves fill ([`leaf_fill`]). Every split depends only on its
//! own range and the layout only on the tree, so the result is the same
//! whatever the thread count.

use super::awake;
use super::binning::{Prim, RangeBounds, split};
use super::cluster;
use super::huge_pages;
use super::leaf_fill;
use super::node::{BLOCK_WIDTH, Child, EdgeNorms, TriangleBlock, WIDTH, WideNode};
use crate::bvh::MAX_DEPTH;
use crate::bvh::build::usable_corners;
use crate::geometry::{Aabb, TriangleMesh};
use rayon::prelude::*;

/// Ranges of at most this many triangles become leaves (one block).
pub const LEAF_SIZE: usize = BLOCK_WIDTH;

/// A leaf in a node with a free slot is split in two when the halves'
/// surface areas add up to less than its own by this share of the root's
/// area: by the surface area heuristic, the block tests a ray entering the
/// tree saves. Near the root (the whole tree, for a small mesh) that
/// tightens leaves that most rays meet; deep down the saving is too small
/// to pay for another block's memory.
const LEAF_SPLIT_SAVING: f32 = 1.0 / 256.0;

/// Subtrees with more triangles than this are built in parallel.
const PARALLEL_THRESHOLD: usize = 1 << 9;

/// A child range of the node being formed, relative to the node's range.
#[derive(Clone, Copy)]
struct Part {
    begin: usize,
    end: usize,
    bounds: RangeBounds,
    depth: u32,
    /// A leaf whose split was tried and did not pay.
    settled: bool,
    /// Its split, made ahead ([`children`]), the range already partitioned.
    split: Option<Halves>,
}

/// A split range: where it was cut and both sides' bounds.
type Halves = (usize, RangeBounds, RangeBounds);

impl Part {
    fn len(&self) -> usize {
        self.end - self.begin
    }

    /// The same part as the whole range of its own node.
    fn whole(&self) -> Part {
        Part {
            begin: 0,
            end: self.len(),
            ..*self
        }
    }

    fn is_leaf(&self) -> bool {
        self.len() <= LEAF_SIZE
    }

    /// Splits the part's triangles, `range`.
    fn split_now(&self, range: &mut [Prim]) -> Halves {
        split(range, &self.bounds, self.must_halve())
    }

    /// Whether a leaf may still be split into two, to fill a free slot of
    /// its node with tighter boxes.
    fn may_split_leaf(&self) -> bool {
        self.is_leaf() && self.len() > 1 && !self.settled && self.depth + 2 < MAX_DEPTH
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

/// Splits both `sides` of `range` (cut at `mid`) on two workers when both
/// are inner ranges of more than [`PARALLEL_THRESHOLD`] triangles: each
/// will be split, in this node or as the first split of its own, and a
/// split depends only on its range, so splitting it ahead leaves the tree
/// the same. A large node's splits otherwise follow one another on one
/// worker.
fn split_both_ahead(range: &mut [Prim], mid: usize, sides: &mut [Part; 2]) {
    if sides.iter().any(|s| s.len() <= PARALLEL_THRESHOLD) {
        return;
    }
    let (left, right) = range.split_at_mut(mid);
    let [first, second] = sides;
    let (a, b) = rayon::join(|| first.split_now(left), || second.split_now(right));
    (first.split, second.split) = (Some(a), Some(b));
}

/// How many levels of halving bring `len` triangles to leaves of at most
/// [`LEAF_SIZE`].
fn levels_to_leaves(len: usize) -> u32 {
    len.div_ceil(LEAF_SIZE).next_power_of_two().trailing_zeros()
}

/// Where a child of a planned node is.
#[derive(Clone, Copy, Debug)]
enum Planned {
    Empty,
    /// Node `i` of the same plan.
    Node(u32),
    /// The root of the plan's subplan `i`, planned on a worker.
    Subplan(u32),
    /// Triangles `begin .. begin + len` of the build order.
    Leaf {
        begin: u32,
        len: u32,
    },
}

/// The nodes of a subtree, formed but not yet laid out: their child
/// references are set when they are ([`lay_out`]).
struct Plan {
    nodes: Vec<(WideNode, [Planned; WIDTH])>,
    subplans: Vec<Plan>,
}

/// What the build makes.
pub(super) struct Built {
    /// Root first, depth first.
    pub nodes: Vec<WideNode>,
    /// In leaf order.
    pub blocks: Vec<TriangleBlock>,
    /// One per block.
    pub edge_norms: Vec<EdgeNorms>,
    /// Mesh triangles left out.
    pub skipped_triangles: usize,
    /// Whether the leaves leave most of their boxes empty
    /// ([`leaf_fill::is_sparse`]).
    pub sparse_leaves: bool,
}

/// The tree over `mesh`'s usable triangles, with its blocks' edge norms.
/// A mesh with parallel work keeps a second worker awake beside the build
/// ([`awake`]).
pub(super) fn build(mesh: &TriangleMesh) -> Built {
    if mesh.indices.len() > PARALLEL_THRESHOLD {
        awake::with_helper_awake(|| build_tree(mesh))
    } else {
        build_tree(mesh)
    }
}

/// [`build`], on whatever workers are awake.
fn build_tree(mesh: &TriangleMesh) -> Built {
    let (mut prims, bounds, skipped) = boxes(mesh);
    if skipped > 0 {
        prims.retain(|p| p.prim() != Prim::UNUSABLE.prim());
    }
    if prims.is_empty() {
        return Built {
            nodes: Vec::new(),
            blocks: Vec::new(),
            edge_norms: Vec::new(),
            skipped_triangles: skipped,
            sparse_leaves: false,
        };
    }
    let mut plan = Plan::for_triangles(prims.len());
    let root = Part {
        begin: 0,
        end: prims.len(),
        bounds,
        depth: 0,
        settled: false,
        split: None,
    };
    let root_area = bounds.half_area();
    match clustered(mesh, &mut prims) {
        Some((parts, count)) => plan_parts(&mut prims, 0, &parts[..count], root_area, &mut plan),
        None => plan_node(&mut prims, 0, root, root_area, &mut plan),
    };

    // The two arrays the traversal reads at random, on huge pages.
    let mut nodes = huge_pages::vec_with_capacity(plan.node_count());
    let mut leaves = Vec::new();
    lay_out(&plan, 0, &mut nodes, &mut leaves);
    drop(plan);
    // The blocks need only the triangles' ids: the boxes are dropped
    // first, so the blocks take the pages they held rather than fresh ones
    // (dragon-14m's blocks took 1.0-1.6 s instead of 3.1-3.4 s of a
    // two-thread build, and the build's peak falls by the boxes' 32 bytes
    // a triangle).
    let mut ids = Vec::new();
    prims.par_iter().map(Prim::prim).collect_into_vec(&mut ids);
    drop(prims);
    let mut blocks = huge_pages::vec_with_capacity(leaves.len());
    let block = |&(begin, len): &(u32, u32)| {
        let range = begin as usize..(begin + len) as usize;
        TriangleBlock::new(ids[range].iter().map(|&p| (p, mesh.triangle(p as usize))))
    };
    let mut edge_norms = huge_pages::vec_with_capacity(leaves.len());
    leaves
        .par_iter()
        .map(|leaf| {
            let block = block(leaf);
            (block, EdgeNorms::of(&block))
        })
        .unzip_into_vecs(&mut blocks, &mut edge_norms);
    let sparse_leaves = leaf_fill::is_sparse(&blocks);
    Built {
        nodes,
        blocks,
        edge_norms,
        skipped_triangles: skipped,
        sparse_leaves,
    }
}

/// The boxes of `mesh`'s triangles, [`Prim::UNUSABLE`] for those the
/// build leaves out, with the usable ones' bounds and how many were left
/// out. One pass over the triangles, in parallel: each box is bounded as
/// it is made, which took a third of the time of making the boxes first
/// and bounding them in a pass of their own (the monkey, one thread).
/// Straight into one array, on huge pages: the build's largest temporary,
/// every page of it written once, where faulting 4 KiB pages in one by
/// one cost more than the writes.
fn boxes(mesh: &TriangleMesh) -> (Vec<Prim>, RangeBounds, usize) {
    let count = mesh.indices.len();
    let mut prims = huge_pages::vec_with_capacity(count);
    let (bounds, skipped) = prims.spare_capacity_mut()[..count]
        .par_chunks_mut(PARALLEL_THRESHOLD)
        .enumerate()
        .map(|(chunk, slots)| {
            let mut bounds = RangeBounds::EMPTY;
            let mut skipped = 0;
            for (i, slot) in slots.iter_mut().enumerate() {
                let prim = chunk * PARALLEL_THRESHOLD + i;
                match usable_corners(mesh, prim) {
                    Some(corners) => {
                        let made = Prim::new(prim as u32, corners);
                        bounds.add(&made);
                        slot.write(made);
                    }
                    None => {
                        skipped += 1;
                        slot.write(Prim::UNUSABLE);
                    }
                }
            }
            (bounds, skipped)
        })
        .reduce(
            || (RangeBounds::EMPTY, 0),
            |(a, m), (b, n)| (a.union(b), m + n),
        );
    // SAFETY: the chunks cover the first `count` slots, each written
    // above, and `count` is within the capacity.
    unsafe { prims.set_len(count) };
    (prims, bounds, skipped)
}

impl Plan {
    /// An empty plan with room for the nodes of a subtree over `triangles`.
    /// Above [`PARALLEL_THRESHOLD`] it holds the root alone (its inner
    /// children are subplans); below, the whole subtree, and the dragons
    /// and the monkey have one node per 19-26 triangles, so one per 16
    /// seldom grows the array (growing it copied every node planned so
    /// far: 1.6% of the monkey's build; Xeon, one thread).
    fn for_triangles(triangles: usize) -> Self {
        let nodes = if triangles > PARALLEL_THRESHOLD {
            1
        } else {
            triangles / 16 + 1
        };
        Plan {
            nodes: Vec::with_capacity(nodes),
            subplans: Vec::new(),
        }
    }

    /// Nodes in the plan and all its subplans.
    fn node_count(&self) -> usize {
        self.nodes.len() + self.subplans.iter().map(Plan::node_count).sum::<usize>()
    }
}

/// The leaves of a mesh that fits in one node ([`cluster`]), with `prims`
/// reordered leaf by leaf; `None` for a larger mesh or where clustering
/// found no grouping.
fn clustered(mesh: &TriangleMesh, prims: &mut [Prim]) -> Option<([Part; WIDTH], usize)> {
    if prims.len() > cluster::MAX_TRIANGLES {
        return None;
    }
    let sizes = cluster::leaves(mesh, prims)?;
    let mut parts = [Part {
        begin: 0,
        end: 0,
        bounds: RangeBounds::EMPTY,
        depth: 1,
        settled: true,
        split: None,
    }; WIDTH];
    let mut begin = 0;
    for (part, size) in parts.iter_mut().zip(&sizes) {
        let end = begin + size;
        (part.begin, part.end) = (begin, end);
        part.bounds = RangeBounds::of(&prims[begin..end]);
        begin = end;
    }
    Some((parts, sizes.len()))
}

/// Plans the node over `prims` (triangles `offset ..` of the build order,
/// the part `whole` with its bounds, binary depth and any split made
/// ahead, in a tree whose root has half area `root_area`) and its subtree
/// into `plan`; returns its index there.
fn plan_node(
    prims: &mut [Prim],
    offset: usize,
    whole: Part,
    root_area: f32,
    plan: &mut Plan,
) -> u32 {
    let (parts, count) = children(prims, whole, root_area);
    plan_parts(prims, offset, &parts[..count], root_area, plan)
}

/// Plans the node whose children are `parts` of `prims` (as
/// [`plan_node`]) and their subtrees.
fn plan_parts(
    prims: &mut [Prim],
    offset: usize,
    parts: &[Part],
    root_area: f32,
    plan: &mut Plan,
) -> u32 {
    let index = plan.nodes.len();
    plan.nodes
        .push((WideNode::new(&[]), [Planned::Empty; WIDTH]));
    let count = parts.len();

    // Above the threshold, the inner children are planned in parallel,
    // each into a plan of its own.
    let mut subplans: Vec<Option<Plan>> = Vec::new();
    if prims.len() > PARALLEL_THRESHOLD {
        let mut rest = &mut *prims;
        let mut jobs = Vec::with_capacity(count);
        for part in parts {
            let (range, tail) = rest.split_at_mut(part.len());
            rest = tail;
            jobs.push((*part, range));
        }
        subplans = jobs
            .into_par_iter()
            .map(|(part, range)| {
                (!part.is_leaf()).then(|| {
                    let mut subplan = Plan::for_triangles(range.len());
                    let begin = offset + part.begin;
                    plan_node(range, begin, part.whole(), root_area, &mut subplan);
                    subplan
                })
            })
            .collect();
    }

    let mut children = [(Aabb::EMPTY, Child::Empty); WIDTH];
    let mut planned = [Planned::Empty; WIDTH];
    for (slot, part) in parts.iter().enumerate() {
        planned[slot] = if part.is_leaf() {
            Planned::Leaf {
                begin: (offset + part.begin) as u32,
                len: part.len() as u32,
            }
        } else if let Some(subplan) = subplans.get_mut(slot).and_then(Option::take) {
            plan.subplans.push(subplan);
            Planned::Subplan(plan.subplans.len() as u32 - 1)
        } else {
            let range = &mut prims[part.begin..part.end];
            let begin = offset + part.begin;
            Planned::Node(plan_node(range, begin, part.whole(), root_area, plan))
        };
        let boxes = &part.bounds.boxes;
        let bounds = Aabb {
            min: boxes.lower(),
            max: boxes.upper(),
        };
        // The node's slots and orders come from the boxes; the references
        // are set when it is laid out.
        children[slot] = (bounds, Child::Empty);
    }
    plan.nodes[index] = (WideNode::new(&children[..count]), planned);
    index as u32
}

/// Appends node `index` of `plan` and its subtree to `nodes`, depth first,
/// numbering the leaves as they come into `leaves` (their triangle
/// ranges); returns the node's index in `nodes`.
fn lay_out(
    plan: &Plan,
    index: usize,
    nodes: &mut Vec<WideNode>,
    leaves: &mut Vec<(u32, u32)>,
) -> usize {
    let (node, planned) = &plan.nodes[index];
    let at = nodes.len();
    nodes.push(*node);
    for (slot, child) in planned.iter().enumerate() {
        let child = match *child {
            Planned::Empty => continue,
            Planned::Node(i) => Child::Inner(lay_out(plan, i as usize, nodes, leaves)),
            Planned::Subplan(i) => {
                Child::Inner(lay_out(&plan.subplans[i as usize], 0, nodes, leaves))
            }
            Planned::Leaf { begin, len } => {
                leaves.push((begin, len));
                Child::Leaf(leaves.len() - 1)
            }
        };
        nodes[at].child[slot] = child.encode();
    }
    at
}

/// Splits `prims` into at most [`WIDTH`] children by splitting the child
/// of largest surface area that is not a leaf (ties to the first) until
/// there are [`WIDTH`] or all are leaves, then, while slots remain, the
/// widest leaf whose split saves [`LEAF_SPLIT_SAVING`]; returns them in
/// order with their count.
fn children(prims: &mut [Prim], whole: Part, root_area: f32) -> ([Part; WIDTH], usize) {
    let mut parts = [whole; WIDTH];
    let mut count = 1;
    let widest = |parts: &[Part], pick: &dyn Fn(&Part) -> bool| {
        parts.iter().enumerate().filter(|(_, p)| pick(p)).fold(
            None::<(usize, f32)>,
            |best, (i, p)| {
                let area = p.bounds.half_area();
                match best {
                    Some((_, a)) if a >= area => best,
                    _ => Some((i, area)),
                }
            },
        )
    };
    while count < WIDTH {
        // A leaf smaller than the saving asked for cannot save it.
        let worth_splitting =
            |p: &Part| p.may_split_leaf() && p.bounds.half_area() >= LEAF_SPLIT_SAVING * root_area;
        let Some((i, _)) = widest(&parts[..count], &|p| !p.is_leaf())
            .or_else(|| widest(&parts[..count], &worth_splitting))
        else {
            break;
        };
        let part = parts[i];
        let range = &mut prims[part.begin..part.end];
        let (mid, left, right) = part.split.unwrap_or_else(|| part.split_now(range));
        let saving = part.bounds.half_area() - (left.half_area() + right.half_area());
        if part.is_leaf() && saving < LEAF_SPLIT_SAVING * root_area {
            parts[i].settled = true;
            continue;
        }
        let side = |begin: usize, end: usize, bounds: RangeBounds| Part {
            begin,
            end,
            bounds,
            depth: part.depth + 1,
            settled: false,
            split: None,
        };
        let mut sides = [
            side(part.begin, part.begin + mid, left),
            side(part.begin + mid, part.end, right),
        ];
        split_both_ahead(range, mid, &mut sides);
        parts.copy_within(i + 1..count, i + 2);
        parts[i..i + 2].copy_from_slice(&sides);
        count += 1;
    }
    (parts, count)
}
