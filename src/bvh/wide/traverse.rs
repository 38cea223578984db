//! Closest-hit and any-hit traversal of the 8-wide BVH, generic over the
//! [`Lanes`] kernels.
//!
//! Closest hit visits the children a ray enters in the node's order for the
//! ray's octant, nearest last, and keeps the others on a stack with their
//! entry distances, skipping them on pop once a closer hit is known. Any
//! hit has its own loop: no culling, children in slot order, and it stops
//! at the first triangle hit. Not nearest first: a shadow or bounce ray
//! starts on a surface, so the children nearest its origin hold that
//! surface's neighbourhood, which seldom blocks it; visiting them first
//! made shadow rays 2–5% slower on the monkey and the dragons (Xeon,
//! AVX-512 and AVX2 kernels alike), and slot order needs no permutes. Its
//! leaves go through the kernel's filter first ([`Lanes::filter`]): a
//! lane it proves hit answers the query, and otherwise only the lanes it
//! cannot rule out take the scalar test.
//! Incoherent closest-hit rays in a tree of sparse leaves put each leaf
//! through the same filter before the kernel, clipped to the best hit
//! ([`super::leaf_fill`]). Other closest-hit rays, with a kernel that
//! tests two blocks in one pass, take a leaf together with the next one
//! on the stack when that is a leaf entered before the best hit
//! ([`Lanes::pair_lanes`]).
//!
//! Every triangle that may be hit goes through the watertight test, whole
//! ([`WatertightRay::intersect_in`]) or finished from edge functions the
//! kernel computed with its operations and the plane distances it made for
//! the whole block ([`WatertightRay::hit_within_edges`],
//! [`Lanes::block_crossings`]); a candidate replaces the best hit when it
//! is closer, or equally close with a lower prim id; the box tests are
//! conservative. So the answer is the lowest `(t, prim)` over all
//! triangles the test hits, whatever the kernels and the visiting order:
//! the same bits as the binary BVH and its brute-force reference.

use super::WideBvh;
use super::lanes::{BoxRay, Lanes, Stack, lanes, reach};
use super::node::{BLOCK_WIDTH, EdgeNorms, LEAF_BIT, TriangleBlock, WideNode};
use super::prefetch::{Prefetch, prefetch_line};
use crate::bvh::traverse::NodeVisits;
use crate::geometry::triangle::{Segment, TriangleHit, WatertightRay, geometric_normal};
use crate::geometry::{Hit, Ray};
use glam::Vec3;

/// The best hit so far, with its triangle's [`geometric_normal`], made
/// once a candidate becomes the best (not for every candidate, nor for
/// the hits rejected after it).
#[derive(Clone, Copy)]
struct Closest {
    hit: TriangleHit,
    prim: u32,
    ng: Vec3,
}

/// A closest-hit search: the best hit so far, and the triangle side of
/// the ray once a leaf is reached.
struct Search<K: Lanes> {
    best: Option<Closest>,
    leaves: Option<Leaves<K>>,
}

/// A ray prepared for the triangle tests (for the scalar watertight test
/// and for the kernel's) and the segment still searched, `[tnear, tfar]`
/// of the ray up to the best hit. Made when the traversal first reaches a
/// leaf: a ray that reaches none, as most rays that miss the mesh, never
/// pays for it (on AVX2 about 200 instructions, half of such a ray's).
struct Leaves<K: Lanes> {
    scalar: WatertightRay,
    kernel: K::TriangleRay,
    segment: Segment,
}

impl<K: Lanes> Leaves<K> {
    /// The leaves in `slot`, made there first if it is empty, in a function
    /// of its own compiled for the kernel ([`Lanes::outlined`]). Made in
    /// place: returned by value, they were copied into the slot with wide
    /// loads of fields just stored one by one, which cannot be forwarded
    /// from the stores (closest-hit rays 9–16% slower on the Cornell box,
    /// the monkey and the dragons, Xeon, AVX-512).
    #[inline(always)]
    fn made_in<'a>(slot: &'a mut Option<Self>, ray: &Ray, bvh: &WideBvh) -> &'a mut Self {
        match slot {
            Some(leaves) => leaves,
            empty => K::outlined(move || empty.insert(Self::new(ray, bvh))),
        }
    }

    #[inline(always)]
    fn new(ray: &Ray, bvh: &WideBvh) -> Self {
        let scalar = WatertightRay::new(ray);
        Leaves {
            kernel: K::triangle_ray(&scalar, reach(&bvh.bounds, ray.origin)),
            segment: scalar.segment(ray.tnear, ray.tfar),
            scalar,
        }
    }
}

/// The triangle side of an any-hit ray: the scalar watertight test over
/// the ray's whole segment, which every lane the filter leaves takes,
/// made when the first such lane is reached. Without the kernel's side of
/// [`Leaves`], which any-hit leaves never read: making it cost shadow rays
/// 1-3% on the Cornell box and the monkey (Xeon, AVX-512; AVX2 within
/// its noise).
struct AnyHitLeaves {
    scalar: WatertightRay,
    segment: Segment,
}

impl AnyHitLeaves {
    /// The leaves in `slot`, made there first if it is empty, out of line
    /// as [`Leaves::made_in`] makes its own.
    #[inline(always)]
    fn made_in<'a, K: Lanes>(slot: &'a mut Option<Self>, ray: &Ray) -> &'a mut Self {
        match slot {
            Some(leaves) => leaves,
            empty => K::outlined(move || {
                let scalar = WatertightRay::new(ray);
                empty.insert(AnyHitLeaves {
                    segment: scalar.segment(ray.tnear, ray.tfar),
                    scalar,
                })
            }),
        }
    }
}

/// The box ray over the part of `ray`'s interval at `t >= 0`.
#[inline(always)]
fn ahead(ray: &Ray) -> BoxRay {
    BoxRay::new(ray.origin, ray.dir, ray.tnear.max(0.0))
}

/// The reversed box ray over the part of `ray`'s interval at `t <= 0`,
/// which ends at `-tnear` in its own parameter.
fn behind(ray: &Ray) -> (BoxRay, f32) {
    (BoxRay::reversed(ray.origin, ray.dir), -ray.tnear)
}

#[inline(always)]
pub(super) fn intersect<K: Lanes, const FILTER_LEAVES: bool>(
    bvh: &WideBvh,
    ray: &Ray,
    visits: &mut impl NodeVisits,
) -> Option<Hit> {
    if bvh.nodes.is_empty() || !ray.is_traceable() {
        return None;
    }
    let mut search = Search::<K> {
        best: None,
        leaves: None,
    };
    if ray.tnear < 0.0 {
        closest_behind::<K, FILTER_LEAVES>(bvh, ray, &mut search, visits);
    }
    if ray.tfar >= 0.0 {
        let boxes = (&ahead(ray), ray.tfar, true);
        closest_hit::<K, FILTER_LEAVES>(bvh, ray, boxes, &mut search, visits);
    }
    search.best.map(|b| Hit {
        t: b.hit.t,
        u: b.hit.u,
        v: b.hit.v,
        prim: b.prim,
        ng: b.ng,
    })
}

/// The part of the interval behind the origin, with no culling (its
/// distances count backwards). Rare, so kept out of the hot loop.
#[cold]
#[inline(never)]
fn closest_behind<K: Lanes, const FILTER_LEAVES: bool>(
    bvh: &WideBvh,
    ray: &Ray,
    search: &mut Search<K>,
    visits: &mut impl NodeVisits,
) {
    let (box_ray, tfar) = behind(ray);
    closest_hit::<K, FILTER_LEAVES>(bvh, ray, (&box_ray, tfar, false), search, visits);
}

/// Tests the children of inner node `index` against `box_ray` up to
/// `tfar`: the one entered to visit next, with the others pushed on
/// `stack` behind it; `None` when the ray enters none. With
/// `NEAREST_FIRST` the children are visited roughly nearest first (the
/// node's order for the ray's octant), else in slot order. With
/// `FILTERED` the leaves are filtered first, and their edge norms are
/// prefetched with them.
#[inline(always)]
fn enter<K: Lanes, const NEAREST_FIRST: bool, const FILTERED: bool>(
    bvh: &WideBvh,
    index: u32,
    box_ray: &BoxRay,
    tfar: f32,
    stack: &mut Stack,
) -> Option<u32> {
    // SAFETY: `index` is the root (the tree is not empty) or an inner
    // child reference, and every inner reference the build stores is below
    // `nodes.len()` (`WideBvh::validate`); the tree never changes after.
    // An unused slot's reference has `LEAF_BIT` set, so were it entered it
    // would reach the bounds-checked `leaf`, not this. Unchecked, the
    // traversal frees the register holding the length and the compare at
    // every node: 1-3% on secondary rays (Xeon, AVX-512).
    let node = unsafe { bvh.nodes.get_unchecked(index as usize) };
    // The child references sit on the node's last line, which the box
    // tests do not read, and a lone child's is read at the index they
    // give: in a tree larger than the caches that line was a second miss
    // to memory, begun only once the planes' had come in (dragon-14m's
    // rays took 10-20% longer, Xeon, AVX-512 and AVX2 alike). Asked for
    // here, the two overlap; in a tree that fits in L2 the hint moves
    // the speed by under 1%.
    prefetch_line(node.child.as_ptr());
    let (mask, boxes) = K::enter_boxes(node, box_ray, tfar);
    match mask {
        0 => None,
        // One child: visited by this branch, without touching the stack.
        // Pushed and popped back instead, even by the AVX-512 kernel's
        // `vcompress`, primary rays ran 2.5-4.5% slower on an AMD EPYC
        // (docs/performance.md, "Kernels and instruction sets").
        _ if mask & (mask - 1) == 0 => Some(node.child[mask.trailing_zeros() as usize]),
        _ => {
            let first = if NEAREST_FIRST {
                K::push_children(node, mask, &boxes, box_ray.octant, stack)
            } else {
                K::push_children_in_slot_order(node, mask, &boxes, stack)
            };
            match bvh.prefetch {
                Prefetch::Nothing => {}
                Prefetch::NextPopped => prefetch::<FILTERED>(bvh, stack.top_child()),
                Prefetch::EveryPushed => {
                    for depth in 0..mask.count_ones() as usize - 1 {
                        prefetch::<FILTERED>(bvh, stack.child_below_top(depth));
                    }
                }
            }
            Some(first)
        }
    }
}

/// Asks for the cache lines of the node or block `reference` names, a
/// child a ray is likely to visit after the subtree it enters now: its
/// loads then overlap that subtree's work instead of stalling the step
/// after it, on trees larger than the caches (the first loads of nodes and
/// blocks took a third of the traversal's time on dragon-203k). Only a
/// hint: no answer depends on it. Which children are asked for depends on
/// the tree's size against the caches ([`super::prefetch::Prefetch`]).
/// Rays whose leaves are `FILTERED` (any-hit, and incoherent closest-hit
/// in a tree of sparse leaves) also ask for a block's edge norms, which
/// the filter reads.
#[inline(always)]
fn prefetch<const FILTERED: bool>(bvh: &WideBvh, reference: u32) {
    let start: *const u8 = if reference & LEAF_BIT == 0 {
        bvh.nodes.as_ptr().wrapping_add(reference as usize).cast()
    } else {
        let block = block_index(reference);
        if FILTERED {
            prefetch_line(bvh.edge_norms.as_ptr().wrapping_add(block));
        }
        bvh.blocks.as_ptr().wrapping_add(block).cast()
    };
    // A block's five lines; a node's four, and the first of the next node.
    const LINES: usize = size_of::<TriangleBlock>().div_ceil(64);
    const _: () = assert!(size_of::<WideNode>() <= 64 * LINES);
    for line in 0..LINES {
        prefetch_line(start.wrapping_add(64 * line));
    }
}

/// The index, in the blocks and in their edge norms, of the leaf
/// `reference` names.
#[inline(always)]
fn block_index(reference: u32) -> usize {
    (reference & !LEAF_BIT) as usize
}

/// The block of the leaf `reference` names.
#[inline(always)]
fn leaf(bvh: &WideBvh, reference: u32) -> &TriangleBlock {
    &bvh.blocks[block_index(reference)]
}

/// The block of the leaf `reference` names and its edge norms (one a
/// block: `validate` checks it): what the any-hit filter reads.
#[inline(always)]
fn filtered_leaf(bvh: &WideBvh, reference: u32) -> (&TriangleBlock, &EdgeNorms) {
    let norms = &bvh.edge_norms[block_index(reference)];
    (leaf(bvh, reference), norms)
}

/// Finishes the lanes a kernel sorted (`$sorted`, a
/// [`TriangleLanes`](super::lanes::TriangleLanes)),
/// keeping any that beats the best. When any lane is inside,
/// `$crossings = |$ray| $make` makes the blocks' plane distances
/// ([`Lanes::block_crossings`]) and `|$lane| $at` gives an inside lane's
/// block, its lane there and its distance; `|$plain| $plain_at` gives an
/// undecided lane's block and lane. A macro rather than a function taking
/// those mappings as closures: shared that way, one block's loop made the
/// Cornell box's primary rays 2-4% slower with either kernel and the monkey's and the
/// dragons' diffuse rays 2-3% slower with AVX-512 (AMD EPYC).
macro_rules! finish_lanes {
    (
        $sorted:expr, $leaves:expr, $best:expr,
        $crossings:ident = |$ray:ident| $make:expr,
        |$lane:ident| $at:expr,
        |$plain:ident| $plain_at:expr
    ) => {{
        let (sorted, leaves, best) = ($sorted, $leaves, $best);
        if sorted.inside != 0 {
            let $ray = &leaves.scalar;
            let $crossings = $make;
            // The kernel left out the lanes outside the segment as it was;
            // once a hit shortens it, the lanes after are checked against
            // the shorter one.
            let mut shortened = false;
            for $lane in lanes(sorted.inside) {
                let (block, slot, distance) = $at;
                let [p0, p1, p2] = block.triangle(slot);
                if shortened && leaves.scalar.outside(p0, p1, p2, &leaves.segment) {
                    continue;
                }
                let edges = sorted.edges($lane);
                let hit = leaves
                    .scalar
                    .hit_within_edges(edges, distance, &leaves.segment);
                shortened |= keep_nearer(best, leaves, hit, block.prims[slot], [p0, p1, p2]);
            }
        }
        for $plain in lanes(sorted.undecided) {
            let (block, slot) = $plain_at;
            let [p0, p1, p2] = block.triangle(slot);
            let hit = leaves.scalar.intersect_in(p0, p1, p2, &leaves.segment);
            keep_nearer(best, leaves, hit, block.prims[slot], [p0, p1, p2]);
        }
    }};
}

/// Tests the triangles of `block` and keeps any that beats the best.
#[inline(always)]
fn closest_in_block<K: Lanes>(
    block: &TriangleBlock,
    leaves: &mut Leaves<K>,
    best: &mut Option<Closest>,
) {
    let sorted = K::triangle_lanes(block, &leaves.kernel, &leaves.segment);
    finish_lanes!(
        sorted,
        leaves,
        best,
        crossings = |ray| K::block_crossings(block, ray),
        |lane| (block, lane, crossings.distance(lane)),
        |lane| (block, lane)
    );
}

/// Tests the triangles of `first` and `second` in one pass
/// ([`Lanes::pair_lanes`]) and keeps any that beats the best.
#[inline(always)]
fn closest_in_pair<K: Lanes>(
    [first, second]: [&TriangleBlock; 2],
    leaves: &mut Leaves<K>,
    best: &mut Option<Closest>,
) {
    let sorted = K::pair_lanes(first, second, &leaves.kernel, &leaves.segment);
    let at = |lane: usize| match lane.checked_sub(BLOCK_WIDTH) {
        Some(slot) => (1, slot),
        None => (0, lane),
    };
    finish_lanes!(
        sorted,
        leaves,
        best,
        crossings = |ray| [first, second].map(|block| K::block_crossings(block, ray)),
        |lane| {
            let (which, slot) = at(lane);
            (
                [first, second][which],
                slot,
                crossings[which].distance(slot),
            )
        },
        |lane| {
            let (which, slot) = at(lane);
            ([first, second][which], slot)
        }
    );
}

/// Makes `hit` of triangle `prim`, with corners `p0`, `p1`, `p2`, the
/// best if it is nearer, and ends the segment searched there; whether it
/// did.
#[inline(always)]
fn keep_nearer<K: Lanes>(
    best: &mut Option<Closest>,
    leaves: &mut Leaves<K>,
    hit: Option<TriangleHit>,
    prim: u32,
    [p0, p1, p2]: [Vec3; 3],
) -> bool {
    let Some(hit) = hit else { return false };
    // Bounded by the best `t` already, so a tie is the only other case.
    let nearer = best.is_none_or(|b| hit.nearer_than(prim, &b.hit, b.prim));
    if nearer {
        let ng = geometric_normal(p0, p1, p2);
        *best = Some(Closest { hit, prim, ng });
        leaves.segment = leaves.scalar.segment(leaves.segment.tnear, hit.t);
    }
    nearer
}

/// Traverses the tree with box ray `boxes.0` up to `boxes.1`, improving
/// the search; with `boxes.2` (cull), no box entered beyond the best hit.
/// With `FILTER_LEAVES`, a leaf goes to the kernel only when the any-hit
/// filter finds a triangle the ray may hit before the best hit
/// ([`super::leaf_fill`] says when that pays).
#[inline(always)]
fn closest_hit<K: Lanes, const FILTER_LEAVES: bool>(
    bvh: &WideBvh,
    ray: &Ray,
    (box_ray, tfar, cull): (&BoxRay, f32, bool),
    search: &mut Search<K>,
    visits: &mut impl NodeVisits,
) {
    let box_tfar = |search: &Search<K>| match search.best {
        Some(b) if cull => b.hit.t,
        _ => tfar,
    };
    let mut stack = Stack::new();
    let mut current = 0u32;
    loop {
        visits.visit();
        if current & LEAF_BIT == 0 {
            if let Some(next) =
                enter::<K, true, FILTER_LEAVES>(bvh, current, box_ray, box_tfar(search), &mut stack)
            {
                current = next;
                continue;
            }
        } else if K::PAIRS && !FILTER_LEAVES {
            // The next leaf on the stack, if the ray enters it before its
            // best hit, is tested in the same pass, and counted as visited
            // where the traversal would have visited it: only if its box
            // still starts before the best hit after this leaf (a leaf it
            // would have skipped holds no nearer hit either).
            let next = stack.pop_leaf_entered_by(box_tfar(search));
            let leaves = Leaves::made_in(&mut search.leaves, ray, bvh);
            let block = leaf(bvh, current);
            match next {
                Some((second, entry)) => {
                    closest_in_pair([block, leaf(bvh, second)], leaves, &mut search.best);
                    if entry <= box_tfar(search) {
                        visits.visit();
                    }
                }
                None => closest_in_block(block, leaves, &mut search.best),
            }
        } else if !FILTER_LEAVES || may_improve::<K>(bvh, current, ray, search) {
            let leaves = Leaves::made_in(&mut search.leaves, ray, bvh);
            closest_in_block::<K>(leaf(bvh, current), leaves, &mut search.best);
        }
        let tfar = box_tfar(search);
        loop {
            let Some((child, entry)) = stack.pop() else {
                return;
            };
            if entry <= tfar {
                current = child;
                break;
            }
        }
    }
}

/// Whether the filter leaves a triangle of the leaf `reference` names
/// that `ray` may hit no farther than the best hit so far.
#[inline(always)]
fn may_improve<K: Lanes>(bvh: &WideBvh, reference: u32, ray: &Ray, search: &Search<K>) -> bool {
    let segment = Ray {
        tfar: search.best.map_or(ray.tfar, |b| b.hit.t),
        ..*ray
    };
    let (block, norms) = filtered_leaf(bvh, reference);
    K::filter::<false>(block, norms, &segment).may_hit != 0
}

#[inline(always)]
pub(super) fn occluded<K: Lanes>(bvh: &WideBvh, ray: &Ray) -> bool {
    if bvh.nodes.is_empty() || !ray.is_traceable() {
        return false;
    }
    (ray.tnear < 0.0 && occluded_behind::<K>(bvh, ray))
        || (ray.tfar >= 0.0 && any_hit::<K>(bvh, ray, &ahead(ray), ray.tfar))
}

/// The part of the interval behind the origin; rare.
#[cold]
#[inline(never)]
fn occluded_behind<K: Lanes>(bvh: &WideBvh, ray: &Ray) -> bool {
    let (box_ray, tfar) = behind(ray);
    any_hit::<K>(bvh, ray, &box_ray, tfar)
}

/// Whether any triangle of the leaf `reference` names is hit within the
/// segment: yes if the kernel's filter ([`Lanes::filter`]) proves a lane
/// hit, else the lanes it may hit take the whole scalar test, its side of
/// the ray made at the first ([`AnyHitLeaves`]).
#[inline(always)]
fn any_in_leaf<K: Lanes>(
    bvh: &WideBvh,
    reference: u32,
    ray: &Ray,
    leaves: &mut Option<AnyHitLeaves>,
) -> bool {
    let (block, norms) = filtered_leaf(bvh, reference);
    let filtered = K::filter::<true>(block, norms, ray);
    if filtered.hit != 0 {
        return true;
    }
    for lane in lanes(filtered.may_hit) {
        let leaves = AnyHitLeaves::made_in::<K>(leaves, ray);
        let [p0, p1, p2] = block.triangle(lane);
        if leaves
            .scalar
            .intersect_in(p0, p1, p2, &leaves.segment)
            .is_some()
        {
            return true;
        }
    }
    false
}

/// Whether `box_ray` up to `tfar` leads to a triangle `ray` hits.
#[inline(always)]
fn any_hit<K: Lanes>(bvh: &WideBvh, ray: &Ray, box_ray: &BoxRay, tfar: f32) -> bool {
    let mut leaves: Option<AnyHitLeaves> = None;
    let mut stack = Stack::new();
    let mut current = 0u32;
    loop {
        if current & LEAF_BIT == 0 {
            if let Some(next) = enter::<K, false, true>(bvh, current, box_ray, tfar, &mut stack) {
                current = next;
                continue;
            }
        } else {
            if any_in_leaf::<K>(bvh, current, ray, &mut leaves) {
                return true;
            }
        }
        let Some((child, _)) = stack.pop() else {
            return false;
        };
        current = child;
    }
}
