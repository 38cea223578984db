//! Closest-hit and any-hit traversal of the 8-wide BVH, generic over the
//! [`Lanes`] kernels.
//!
//! Closest hit visits the children a ray enters in the node's order for the
//! ray's octant, nearest last, and keeps the others on a stack with their
//! entry distances, skipping them on pop once a closer hit is known. Any
//! hit has its own loop: no culling, and it stops at the first triangle
//! hit.
//!
//! Every triangle that may be hit goes through the watertight test, whole
//! ([`WatertightRay::intersect_in`]) or finished from edge functions the
//! kernel computed with its operations
//! ([`WatertightRay::hit_within_edges`]); a candidate replaces the best
//! hit when it is closer, or equally close with a lower prim id; the box
//! tests are conservative. So the answer is the lowest `(t, prim)` over all
//! triangles the test hits, whatever the kernels and the visiting order:
//! the same bits as the binary BVH and its brute-force reference.

use super::WideBvh;
use super::lanes::{BoxRay, Lanes, Stack, lanes, reach};
use super::node::{LEAF_BIT, TriangleBlock, WideNode};
use crate::bvh::traverse::NodeVisits;
use crate::geometry::triangle::{Segment, TriangleHit, WatertightRay, geometric_normal};
use crate::geometry::{Hit, Ray};
use glam::Vec3;

/// The best hit so far.
#[derive(Clone, Copy)]
struct Closest {
    hit: TriangleHit,
    prim: u32,
    corners: [Vec3; 3],
}

/// A closest-hit search: the best hit so far and the segment still
/// searched, `[tnear, tfar]` of the ray up to the best hit.
struct Search {
    best: Option<Closest>,
    segment: Segment,
}

/// A ray prepared for the triangle tests: for the scalar watertight test
/// and for the kernel's.
struct TriangleRays<K: Lanes> {
    scalar: WatertightRay,
    kernel: K::TriangleRay,
}

impl<K: Lanes> TriangleRays<K> {
    #[inline(always)]
    fn new(ray: &Ray, bvh: &WideBvh) -> Self {
        let scalar = WatertightRay::new(ray);
        TriangleRays {
            kernel: K::triangle_ray(&scalar, reach(&bvh.bounds, ray.origin)),
            scalar,
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
pub(super) fn intersect<K: Lanes>(
    bvh: &WideBvh,
    ray: &Ray,
    visits: &mut impl NodeVisits,
) -> Option<Hit> {
    if bvh.nodes.is_empty() || !ray.is_traceable() {
        return None;
    }
    let rays = TriangleRays::<K>::new(ray, bvh);
    let mut search = Search {
        best: None,
        segment: rays.scalar.segment(ray.tnear, ray.tfar),
    };
    if ray.tnear < 0.0 {
        closest_behind::<K>(bvh, ray, &rays, &mut search, visits);
    }
    if ray.tfar >= 0.0 {
        let boxes = (&ahead(ray), ray.tfar, true);
        closest_hit::<K>(bvh, &rays, boxes, &mut search, visits);
    }
    search.best.map(|b| {
        let [p0, p1, p2] = b.corners;
        Hit {
            t: b.hit.t,
            u: b.hit.u,
            v: b.hit.v,
            prim: b.prim,
            ng: geometric_normal(p0, p1, p2),
        }
    })
}

/// The part of the interval behind the origin, with no culling (its
/// distances count backwards). Rare, so kept out of the hot loop.
#[cold]
#[inline(never)]
fn closest_behind<K: Lanes>(
    bvh: &WideBvh,
    ray: &Ray,
    rays: &TriangleRays<K>,
    search: &mut Search,
    visits: &mut impl NodeVisits,
) {
    let (box_ray, tfar) = behind(ray);
    closest_hit::<K>(bvh, rays, (&box_ray, tfar, false), search, visits);
}

/// Tests the children of inner node `index` against `box_ray` up to
/// `tfar`: the nearest one entered, to visit next, with the others pushed
/// on `stack` behind it; `None` when the ray enters none.
#[inline(always)]
fn enter<K: Lanes>(
    bvh: &WideBvh,
    index: u32,
    box_ray: &BoxRay,
    tfar: f32,
    stack: &mut Stack,
) -> Option<u32> {
    let node = &bvh.nodes[index as usize];
    let (mask, boxes) = K::enter_boxes(node, box_ray, tfar);
    match mask {
        0 => None,
        // One child: visited without touching the stack.
        _ if mask & (mask - 1) == 0 => Some(node.child[mask.trailing_zeros() as usize]),
        _ => {
            let nearest = K::push_children(node, mask, &boxes, box_ray.octant, stack);
            if let Some(second) = stack.top_child() {
                prefetch(bvh, second);
            }
            Some(nearest)
        }
    }
}

/// Asks for the cache lines of the node or block `reference` names, the
/// child a ray is likely to visit after the subtree it enters now: its
/// loads then overlap that subtree's work instead of stalling the step
/// after it, on trees larger than the caches (the first loads of nodes and
/// blocks took a third of the traversal's time on dragon-203k). Only a
/// hint: no answer depends on it.
#[inline(always)]
fn prefetch(bvh: &WideBvh, reference: u32) {
    let start: *const u8 = if reference & LEAF_BIT == 0 {
        bvh.nodes.as_ptr().wrapping_add(reference as usize).cast()
    } else {
        let block = (reference & !LEAF_BIT) as usize;
        bvh.blocks.as_ptr().wrapping_add(block).cast()
    };
    // A block's five lines; a node's four, and the first of the next node.
    const LINES: usize = size_of::<TriangleBlock>().div_ceil(64);
    const _: () = assert!(size_of::<WideNode>() <= 64 * LINES);
    #[cfg(target_arch = "x86_64")]
    for line in 0..LINES {
        // SAFETY: a prefetch never faults; it is a hint for any address.
        unsafe {
            use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
            _mm_prefetch::<_MM_HINT_T0>(start.wrapping_add(64 * line).cast());
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = start;
}

/// The block of the leaf `reference` names.
#[inline(always)]
fn leaf(bvh: &WideBvh, reference: u32) -> &TriangleBlock {
    &bvh.blocks[(reference & !LEAF_BIT) as usize]
}

/// Tests the triangles of `block` and keeps any that beats the best.
#[inline(always)]
fn closest_in_block<K: Lanes>(block: &TriangleBlock, rays: &TriangleRays<K>, search: &mut Search) {
    let sorted = K::triangle_lanes(block, &rays.kernel, &search.segment);
    // The kernel left out the lanes outside the segment as it was; once a
    // hit shortens it, the lanes after are checked against the shorter one.
    let mut shortened = false;
    for lane in lanes(sorted.inside) {
        let [p0, p1, p2] = block.triangle(lane);
        if shortened && rays.scalar.outside(p0, p1, p2, &search.segment) {
            continue;
        }
        let edges = sorted.edges(lane);
        let hit = rays
            .scalar
            .hit_within_edges(edges, p0, p1, p2, &search.segment);
        shortened |= keep_nearer(search, &rays.scalar, hit, block.prims[lane], [p0, p1, p2]);
    }
    for lane in lanes(sorted.undecided) {
        let [p0, p1, p2] = block.triangle(lane);
        let hit = rays.scalar.intersect_in(p0, p1, p2, &search.segment);
        keep_nearer(search, &rays.scalar, hit, block.prims[lane], [p0, p1, p2]);
    }
}

/// Makes `hit` of triangle `prim` the best if it is nearer, and ends the
/// segment searched there; whether it did.
#[inline(always)]
fn keep_nearer(
    search: &mut Search,
    ray: &WatertightRay,
    hit: Option<TriangleHit>,
    prim: u32,
    corners: [Vec3; 3],
) -> bool {
    let Some(hit) = hit else { return false };
    // Bounded by the best `t` already, so a tie is the only other case.
    let nearer = search
        .best
        .is_none_or(|b| hit.nearer_than(prim, &b.hit, b.prim));
    if nearer {
        search.best = Some(Closest { hit, prim, corners });
        search.segment = ray.segment(search.segment.tnear, hit.t);
    }
    nearer
}

/// Traverses the tree with box ray `boxes.0` up to `boxes.1`, improving
/// the search; with `boxes.2` (cull), no box entered beyond the best hit.
#[inline(always)]
fn closest_hit<K: Lanes>(
    bvh: &WideBvh,
    rays: &TriangleRays<K>,
    (box_ray, tfar, cull): (&BoxRay, f32, bool),
    search: &mut Search,
    visits: &mut impl NodeVisits,
) {
    let box_tfar = |search: &Search| match search.best {
        Some(b) if cull => b.hit.t,
        _ => tfar,
    };
    let mut stack = Stack::new();
    let mut current = 0u32;
    loop {
        visits.visit();
        if current & LEAF_BIT == 0 {
            if let Some(next) = enter::<K>(bvh, current, box_ray, box_tfar(search), &mut stack) {
                current = next;
                continue;
            }
        } else {
            closest_in_block::<K>(leaf(bvh, current), rays, search);
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

#[inline(always)]
pub(super) fn occluded<K: Lanes>(bvh: &WideBvh, ray: &Ray) -> bool {
    if bvh.nodes.is_empty() || !ray.is_traceable() {
        return false;
    }
    let rays = TriangleRays::<K>::new(ray, bvh);
    let segment = rays.scalar.segment(ray.tnear, ray.tfar);
    (ray.tnear < 0.0 && occluded_behind::<K>(bvh, ray, &rays, &segment))
        || (ray.tfar >= 0.0 && any_hit::<K>(bvh, &rays, &segment, &ahead(ray), ray.tfar))
}

/// The part of the interval behind the origin; rare.
#[cold]
#[inline(never)]
fn occluded_behind<K: Lanes>(
    bvh: &WideBvh,
    ray: &Ray,
    rays: &TriangleRays<K>,
    segment: &Segment,
) -> bool {
    let (box_ray, tfar) = behind(ray);
    any_hit::<K>(bvh, rays, segment, &box_ray, tfar)
}

/// Whether any triangle of `block` is hit within `segment`.
#[inline(always)]
fn any_in_block<K: Lanes>(
    block: &TriangleBlock,
    rays: &TriangleRays<K>,
    segment: &Segment,
) -> bool {
    let sorted = K::triangle_lanes(block, &rays.kernel, segment);
    for lane in lanes(sorted.inside) {
        let [p0, p1, p2] = block.triangle(lane);
        let edges = sorted.edges(lane);
        if rays
            .scalar
            .hit_within_edges(edges, p0, p1, p2, segment)
            .is_some()
        {
            return true;
        }
    }
    for lane in lanes(sorted.undecided) {
        let [p0, p1, p2] = block.triangle(lane);
        if rays.scalar.intersect_in(p0, p1, p2, segment).is_some() {
            return true;
        }
    }
    false
}

#[inline(always)]
fn any_hit<K: Lanes>(
    bvh: &WideBvh,
    rays: &TriangleRays<K>,
    segment: &Segment,
    box_ray: &BoxRay,
    tfar: f32,
) -> bool {
    let mut stack = Stack::new();
    let mut current = 0u32;
    loop {
        if current & LEAF_BIT == 0 {
            if let Some(next) = enter::<K>(bvh, current, box_ray, tfar, &mut stack) {
                current = next;
                continue;
            }
        } else if any_in_block::<K>(leaf(bvh, current), rays, segment) {
            return true;
        }
        let Some((child, _)) = stack.pop() else {
            return false;
        };
        current = child;
    }
}
