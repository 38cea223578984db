//! Closest-hit and any-hit traversal of the 4-wide BVH, generic over the
//! [`Lanes`] kernels.
//!
//! Closest hit visits the children a ray enters nearest first and keeps the
//! others on a stack with their entry distances, skipping them on pop once
//! a closer hit is known. Any hit has its own kernel: no ordering, no
//! distances kept, and it stops at the first triangle hit.
//!
//! Every triangle that may be hit goes through the one exact test,
//! [`WatertightRay::intersect`], and a candidate replaces the best hit when
//! it is closer, or equally close with a lower prim id; the box tests are
//! conservative. So the answer is the lowest `(t, prim)` over all triangles
//! the exact test hits, whatever the kernels and the visiting order: the
//! same bits as the binary BVH and its brute-force reference.

use super::WideBvh;
use super::lanes::{LaneMask, Lanes, RayLanes};
use super::node::WIDTH;
use crate::bvh::MAX_DEPTH;
use crate::geometry::triangle::{TriangleHit, WatertightRay, geometric_normal};
use crate::geometry::{Hit, Ray};
use std::cell::RefCell;

/// Enough stack for the deepest tree: a node at depth `MAX_DEPTH` at most,
/// and at most `WIDTH - 1` entries pushed per level.
const STACK_SIZE: usize = (WIDTH - 1) * MAX_DEPTH as usize + 1;

thread_local! {
    /// Each thread's traversal stack, allocated once: a fresh array of
    /// [`STACK_SIZE`] entries would be zeroed on every ray, which cost about
    /// a third of the traversal time.
    static STACK: RefCell<Vec<Pending>> = RefCell::new(vec![Pending::default(); STACK_SIZE]);
}

/// A child still to visit: the node it is, or its leaf blocks.
#[derive(Clone, Copy, Default)]
struct Pending {
    child: u32,
    /// 0 for an inner node, else the leaf's block count.
    blocks: u32,
    entry: f32,
}

impl Pending {
    /// Child `slot` of `node`, which the ray entered (so not an unused
    /// slot): the node's own encoding of a child is the pending one.
    #[inline(always)]
    fn new(node: &super::WideNode, slot: usize, entry: f32) -> Self {
        let (child, blocks) = node.slot(slot);
        Pending {
            child,
            blocks,
            entry,
        }
    }
}

/// The best hit so far.
#[derive(Clone, Copy)]
struct Closest {
    hit: TriangleHit,
    prim: u32,
    corners: [glam::Vec3; 3],
}

/// The lanes of `mask`, lowest first.
fn lanes(mut mask: LaneMask) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        (mask != 0).then(|| {
            let lane = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            lane
        })
    })
}

#[inline(always)]
pub(super) fn intersect<K: Lanes>(bvh: &WideBvh, ray: &Ray) -> Option<Hit> {
    if bvh.nodes.is_empty() || !ray.is_traceable() {
        return None;
    }
    STACK.with_borrow_mut(|stack| closest_hit::<K>(bvh, ray, stack))
}

#[inline(always)]
fn closest_hit<K: Lanes>(bvh: &WideBvh, ray: &Ray, stack: &mut [Pending]) -> Option<Hit> {
    let lanes_ray = RayLanes::new(ray);
    let wray = WatertightRay::new(ray);
    let mut best: Option<Closest> = None;
    let mut depth = 0;
    let mut current = Pending::default();
    loop {
        let tfar = best.map_or(ray.tfar, |b| b.hit.t);
        if current.blocks == 0 {
            let node = &bvh.nodes[current.child as usize];
            let (mask, entries) = K::enter_boxes(node, &lanes_ray, tfar);
            if mask != 0 {
                // Nearest first: push the others farthest first.
                let mut order = [(0.0f32, 0usize); WIDTH];
                let mut count = 0;
                for slot in lanes(mask) {
                    let mut i = count;
                    while i > 0 && order[i - 1].0 < entries[slot] {
                        order[i] = order[i - 1];
                        i -= 1;
                    }
                    order[i] = (entries[slot], slot);
                    count += 1;
                }
                for &(entry, slot) in &order[..count - 1] {
                    stack[depth] = Pending::new(node, slot, entry);
                    depth += 1;
                }
                let (entry, slot) = order[count - 1];
                current = Pending::new(node, slot, entry);
                continue;
            }
        } else {
            let first = current.child as usize;
            for block in &bvh.blocks[first..first + current.blocks as usize] {
                for lane in lanes(K::triangle_candidates(block, &wray)) {
                    let corners = block.triangle(lane);
                    let tfar = best.map_or(ray.tfar, |b| b.hit.t);
                    let [p0, p1, p2] = corners;
                    let Some(hit) = wray.intersect(p0, p1, p2, ray.tnear, tfar) else {
                        continue;
                    };
                    let prim = block.prims[lane];
                    // Bounded by the best `t` already, so a tie is the only
                    // other case.
                    if best.is_none_or(|b| hit.nearer_than(prim, &b.hit, b.prim)) {
                        best = Some(Closest { hit, prim, corners });
                    }
                }
            }
        }
        let tfar = best.map_or(ray.tfar, |b| b.hit.t);
        loop {
            if depth == 0 {
                return best.map(|b| {
                    let [p0, p1, p2] = b.corners;
                    Hit {
                        t: b.hit.t,
                        u: b.hit.u,
                        v: b.hit.v,
                        prim: b.prim,
                        ng: geometric_normal(p0, p1, p2),
                    }
                });
            }
            depth -= 1;
            if stack[depth].entry <= tfar {
                current = stack[depth];
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
    STACK.with_borrow_mut(|stack| any_hit::<K>(bvh, ray, stack))
}

#[inline(always)]
fn any_hit<K: Lanes>(bvh: &WideBvh, ray: &Ray, stack: &mut [Pending]) -> bool {
    let lanes_ray = RayLanes::new(ray);
    let wray = WatertightRay::new(ray);
    let mut depth = 0;
    let mut node = 0;
    loop {
        let (mask, _) = K::enter_boxes(&bvh.nodes[node], &lanes_ray, ray.tfar);
        for slot in lanes(mask) {
            // Leaves are tested at once, so a hit stops the ray before any
            // more nodes are pushed; inner children wait on the stack.
            let (first, blocks) = bvh.nodes[node].slot(slot);
            if blocks == 0 {
                stack[depth] = Pending::new(&bvh.nodes[node], slot, 0.0);
                depth += 1;
                continue;
            }
            let first = first as usize;
            for block in &bvh.blocks[first..first + blocks as usize] {
                for lane in lanes(K::triangle_candidates(block, &wray)) {
                    let [p0, p1, p2] = block.triangle(lane);
                    if wray.intersect(p0, p1, p2, ray.tnear, ray.tfar).is_some() {
                        return true;
                    }
                }
            }
        }
        if depth == 0 {
            return false;
        }
        depth -= 1;
        node = stack[depth].child as usize;
    }
}
