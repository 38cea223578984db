//! The per-node kernels of the traversal as a trait, [`Lanes`], with a
//! portable scalar implementation ([`Scalar`]); `simd.rs` implements the
//! same trait with AVX2 intrinsics. Both visit the same nodes in the same
//! order, so a traversal counts the same node visits whatever kernel runs
//! (a kernel that tests two leaves in one pass counts the second where the
//! traversal would have visited it).

use super::crossings::BlockCrossings;
use super::node::{BLOCK_WIDTH, EdgeNorms, LEAF_BIT, TriangleBlock, WIDTH, WideNode};
use crate::bvh::MAX_DEPTH;
use crate::bvh::ray_box::{GROW, SHRINK};
use crate::geometry::triangle::{Segment, WatertightRay};
use crate::geometry::{Aabb, Ray};
use glam::Vec3;
use std::mem::MaybeUninit;

/// Which lanes pass, one bit per lane (bit `i` for lane `i`).
pub(super) type LaneMask = u32;

/// The lanes of `mask`, lowest first.
#[inline(always)]
pub(super) fn lanes(mut mask: LaneMask) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        (mask != 0).then(|| {
            let lane = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            lane
        })
    })
}

/// The highest lane of `mask`, which must not be empty.
#[inline(always)]
pub(super) fn highest_lane(mask: LaneMask) -> usize {
    (LaneMask::BITS - 1 - mask.leading_zeros()) as usize
}

/// A ray prepared for the box tests over `t >= 0`.
///
/// The slab distances `(plane - origin) · (1 / dir)` carry at most three
/// roundings, so scaling the reciprocal direction once per ray by
/// `1 - 2γ(3)` for the planes met first and `1 + 2γ(3)` for those met last
/// (Ize, "Robust BVH Ray Traversal", JCGT 2(2), 2013) makes every
/// non-negative entry distance a lower bound and every non-negative exit
/// distance an upper bound of the exact one: no box the exact ray touches
/// at `t >= 0` is rejected. Negative distances would be rounded the wrong
/// way, so a ray whose interval starts below 0 has that part traversed
/// as the reversed ray ([`BoxRay::reversed`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct BoxRay {
    pub origin: [f32; 3],
    /// `1 / dir` scaled towards 0, for the planes met first; a zero
    /// component gives an infinity of the zero's sign.
    pub inv_near: [f32; 3],
    /// `1 / dir` scaled away from 0, for the planes met last.
    pub inv_far: [f32; 3],
    /// Per axis, whether the direction is negative: the upper plane is
    /// met first (the side in [`WideNode::planes`] of the plane met first).
    pub negative: [bool; 3],
    /// Bit `k` set when the direction is negative along axis `k`.
    pub octant: u32,
    /// Where the boxes' part of the interval starts, at least 0.
    pub tnear: f32,
}

impl BoxRay {
    /// The ray from `origin` along `dir` over `[tnear, ∞)`, `tnear >= 0`.
    pub fn new(origin: Vec3, dir: Vec3, tnear: f32) -> Self {
        let inv_dir = dir.recip();
        let negative = inv_dir.cmplt(Vec3::ZERO);
        Self {
            origin: origin.to_array(),
            inv_near: (inv_dir * SHRINK).to_array(),
            inv_far: (inv_dir * GROW).to_array(),
            negative: [negative.x, negative.y, negative.z],
            octant: negative.bitmask(),
            tnear,
        }
    }

    /// The sides in [`WideNode::planes`] of the planes met first and last
    /// along `axis`.
    #[inline(always)]
    pub fn sides(&self, axis: usize) -> [usize; 2] {
        let negative = self.negative[axis];
        [usize::from(negative), usize::from(!negative)]
    }

    /// The ray along `-dir` from the same origin over `[0, ∞)`: its
    /// parameter `s` is the original's `-s`, so it meets the boxes the
    /// original meets at `t <= 0`.
    pub fn reversed(origin: Vec3, dir: Vec3) -> Self {
        Self::new(origin, -dir, 0.0)
    }
}

/// Entries on the traversal stack: enough for the deepest tree (at most
/// `WIDTH - 1` entries per level) plus one full vector store beyond it.
const STACK_SIZE: usize = (WIDTH - 1) * MAX_DEPTH as usize + WIDTH;

/// Children still to visit, with the distances where the ray enters them.
///
/// Aligned to a cache line, which aligns the traversal's whole frame: its
/// 32-byte spills of the ray's broadcast constants then never straddle two
/// lines. Unaligned, whether they did depended on how deep the caller's
/// stack was, and moved the Cornell box's primary rays by up to a third
/// (17.1 against 22.9 ms, one thread, AVX-512, the frame shifted 64 bytes
/// at a time).
#[repr(align(64))]
pub(super) struct Stack {
    children: [MaybeUninit<u32>; STACK_SIZE],
    entries: [MaybeUninit<f32>; STACK_SIZE],
    len: usize,
}

impl Stack {
    /// An empty stack; its storage is left uninitialised, since zeroing it
    /// for every ray would cost more than many node visits.
    #[inline(always)]
    pub fn new() -> Self {
        Stack {
            children: [const { MaybeUninit::uninit() }; STACK_SIZE],
            entries: [const { MaybeUninit::uninit() }; STACK_SIZE],
            len: 0,
        }
    }

    #[inline(always)]
    pub fn push(&mut self, child: u32, entry: f32) {
        self.children[self.len].write(child);
        self.entries[self.len].write(entry);
        self.len += 1;
    }

    #[inline(always)]
    pub fn pop(&mut self) -> Option<(u32, f32)> {
        self.len = self.len.checked_sub(1)?;
        // SAFETY: every entry below `len` was written by a push (`push`, or
        // a kernel's stores through `top` followed by `push_all_but_last`),
        // and `len` never exceeds `STACK_SIZE`: `push` indexes checked and
        // `top` asserts room before `push_all_but_last` grows it.
        unsafe {
            Some((
                self.children.get_unchecked(self.len).assume_init(),
                self.entries.get_unchecked(self.len).assume_init(),
            ))
        }
    }

    /// Pops the child on top if it is a leaf entered no farther than
    /// `tfar`, with its entry distance.
    #[inline(always)]
    pub fn pop_leaf_entered_by(&mut self, tfar: f32) -> Option<(u32, f32)> {
        let top = self.len.checked_sub(1)?;
        // SAFETY: as in `pop`: every entry below `len` was written.
        let (child, entry) = unsafe {
            (
                self.children.get_unchecked(top).assume_init(),
                self.entries.get_unchecked(top).assume_init(),
            )
        };
        (child & LEAF_BIT != 0 && entry <= tfar).then(|| {
            self.len = top;
            (child, entry)
        })
    }

    /// The child on top, the next one popped; the stack must not be
    /// empty.
    #[inline(always)]
    pub fn top_child(&self) -> u32 {
        self.child_below_top(0)
    }

    /// The child `depth` entries below the top; there must be more.
    #[inline(always)]
    pub fn child_below_top(&self, depth: usize) -> u32 {
        assert!(depth < self.len, "only {} children on the stack", self.len);
        // SAFETY: as in `pop`: every entry below `len` was written.
        unsafe { self.children[self.len - 1 - depth].assume_init() }
    }

    /// Where a kernel may store up to [`WIDTH`] entries above the top:
    /// the children's and the entries' slots.
    #[inline(always)]
    pub fn top(&mut self) -> (*mut u32, *mut f32) {
        assert!(self.len + WIDTH <= STACK_SIZE, "traversal stack overflow");
        (
            self.children[self.len..].as_mut_ptr().cast(),
            self.entries[self.len..].as_mut_ptr().cast(),
        )
    }

    /// Of the `count` children just stored through [`Stack::top`], takes
    /// all but the last onto the stack and returns the last: the child
    /// visited next.
    ///
    /// # Safety
    /// As for [`Stack::keep_all_but_last`].
    #[inline(always)]
    pub unsafe fn push_all_but_last(&mut self, count: usize) -> u32 {
        // SAFETY: as the caller promises.
        unsafe { self.keep_all_but_last(count) };
        // SAFETY: the caller wrote this entry, which `top` found room for.
        unsafe { self.children.get_unchecked(self.len).assume_init() }
    }

    /// Of the `count` children just stored through [`Stack::top`], takes
    /// all but the last onto the stack; the caller visits the last.
    ///
    /// # Safety
    /// The `count` entries above the top must have been written through
    /// the pointers [`Stack::top`] gave since the stack last changed, so
    /// `count` is at most [`WIDTH`], and `count` must be at least 1.
    #[inline(always)]
    pub unsafe fn keep_all_but_last(&mut self, count: usize) {
        self.len += count - 1;
    }
}

/// The triangles of a block (or of two, [`Lanes::pair_lanes`]) sorted by
/// what the watertight test would do; `R` holds one f32 per lane.
pub(super) struct TriangleLanes<R = [f32; BLOCK_WIDTH]> {
    /// Lanes whose edge functions all have the same sign, each beyond its
    /// error bound: the hit is decided by the determinant and the distance
    /// ([`WatertightRay::hit_within_edges`] with [`TriangleLanes::edges`]).
    pub inside: LaneMask,
    /// Lanes some edge function of which the f32 values cannot decide:
    /// they take the whole scalar test ([`WatertightRay::intersect_in`]).
    pub undecided: LaneMask,
    /// `edges[i][lane]`: edge function `i` as the scalar test computes it.
    pub edges: [R; 3],
}

impl<R: AsRef<[f32]>> TriangleLanes<R> {
    #[inline(always)]
    pub fn edges(&self, lane: usize) -> [f32; 3] {
        // Rows of one type, so one check covers all three once inlined
        // (and no `array::map`, which copies the rows to pick one lane of
        // each).
        let [e0, e1, e2] = &self.edges;
        assert!(lane < e0.as_ref().len(), "lane {lane}");
        [e0.as_ref()[lane], e1.as_ref()[lane], e2.as_ref()[lane]]
    }
}

/// An upper bound of the L1 distance from `origin` to every point of
/// `bounds`: to its farthest corner, scaled up by `2^-16`, far more than
/// the rounding of its three differences and two sums. The triangle
/// kernels bound every corner's distance with it once per ray instead of
/// measuring each corner's ([`Lanes::triangle_ray`]).
#[inline(always)]
pub(super) fn reach(bounds: &Aabb, origin: Vec3) -> f32 {
    const ROUNDING: f32 = 1.0 + 1.0 / 65536.0;
    let farthest = (bounds.min - origin).abs().max((bounds.max - origin).abs());
    farthest.element_sum() * ROUNDING
}

/// What the any-hit filter ([`Lanes::filter`]) finds in a block.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Filtered {
    /// The lanes the ray may hit; the scalar test misses every other.
    pub may_hit: LaneMask,
    /// Lanes of `may_hit` the scalar test hits (when asked for).
    pub hit: LaneMask,
}

/// The kernels one traversal is built on.
pub(super) trait Lanes {
    /// The result of a node's box tests, in whatever form the kernel
    /// orders children from.
    type Boxes: Copy;

    /// Tests the children of `node` against `ray` over
    /// `[ray.tnear, tfar]`: which it enters, and where.
    fn enter_boxes(node: &WideNode, ray: &BoxRay, tfar: f32) -> (LaneMask, Self::Boxes);

    /// Pushes the children in `mask` (two or more) from far to near in the
    /// node's order for `octant`, with their entry distances, except the
    /// nearest, which it returns.
    fn push_children(
        node: &WideNode,
        mask: LaneMask,
        boxes: &Self::Boxes,
        octant: u32,
        stack: &mut Stack,
    ) -> u32;

    /// Pushes the children in `mask` (two or more) in slot order, with
    /// their entry distances, except the last, which it returns: the
    /// any-hit traversal's order, the highest slot first (`traverse.rs`).
    fn push_children_in_slot_order(
        node: &WideNode,
        mask: LaneMask,
        boxes: &Self::Boxes,
        stack: &mut Stack,
    ) -> u32;

    /// A ray prepared for [`Lanes::triangle_lanes`], once per ray.
    type TriangleRay;

    /// `ray` prepared for the triangles of a tree whose corners all lie
    /// within L1 distance `reach` of its origin ([`reach`]).
    fn triangle_ray(ray: &WatertightRay, reach: f32) -> Self::TriangleRay;

    /// Sorts the triangles of `block` for hits within `segment`; lanes in
    /// neither mask are missed.
    fn triangle_lanes(
        block: &TriangleBlock,
        ray: &Self::TriangleRay,
        segment: &Segment,
    ) -> TriangleLanes;

    /// Whether the kernel tests two leaves' blocks in one pass
    /// ([`Lanes::pair_lanes`]).
    const PAIRS: bool = false;

    /// [`Lanes::triangle_lanes`] of two blocks in one pass, `first`'s
    /// lanes lowest; called only for kernels with [`Lanes::PAIRS`].
    fn pair_lanes(
        _first: &TriangleBlock,
        _second: &TriangleBlock,
        _ray: &Self::TriangleRay,
        _segment: &Segment,
    ) -> TriangleLanes<[f32; 2 * BLOCK_WIDTH]> {
        unreachable!("this kernel tests one block at a time")
    }

    /// How far along `ray` it meets the planes of `block`'s triangles, for
    /// the lanes [`Lanes::triangle_lanes`] leaves inside; called only for
    /// kernels that leave lanes inside.
    fn block_crossings(_block: &TriangleBlock, _ray: &WatertightRay) -> BlockCrossings {
        unreachable!("this kernel leaves no lane inside")
    }

    /// The any-hit traversal's filter on `block` (with its edges' `norms`)
    /// for `ray` over its interval: the lanes
    /// it may hit, a superset of those the whole scalar test hits, after
    /// which each lane left takes that test; and with `PROVE_HITS`, among
    /// those, lanes the scalar test is proved to hit, which need not take
    /// it to answer whether any is hit.
    fn filter<const PROVE_HITS: bool>(
        block: &TriangleBlock,
        norms: &EdgeNorms,
        ray: &Ray,
    ) -> Filtered;

    /// Runs `make` in a function of its own compiled for the kernel's
    /// instruction set: the once-per-ray preparation of the triangle tests,
    /// kept out of the traversal's loop (whose registers it would crowd)
    /// and yet not left to baseline SSE2 code.
    fn outlined<R>(make: impl FnOnce() -> R) -> R;
}

/// One lane at a time, with the same operations in the same order as the
/// SIMD kernels, so both enter the same boxes; every triangle goes to the
/// whole scalar test (which also checks the segment's window).
pub(super) struct Scalar;

/// `max(value, acc)` as the SIMD max instruction computes it: `acc` when
/// either is NaN or both are equal, so a NaN slab distance (a ray in a
/// box's face plane along a zero direction component) never rejects.
fn max_keep(value: f32, acc: f32) -> f32 {
    if value > acc { value } else { acc }
}

/// `min(value, acc)`, keeping `acc` when either is NaN or both are equal.
fn min_keep(value: f32, acc: f32) -> f32 {
    if value < acc { value } else { acc }
}

impl Lanes for Scalar {
    type Boxes = [f32; WIDTH];

    fn enter_boxes(node: &WideNode, ray: &BoxRay, tfar: f32) -> (LaneMask, [f32; WIDTH]) {
        let mut mask = 0;
        let mut entries = [0.0; WIDTH];
        for (lane, entry) in entries.iter_mut().enumerate() {
            let (mut enter, mut exit) = (ray.tnear, tfar);
            for axis in 0..3 {
                let origin = ray.origin[axis];
                let [near, far] = ray.sides(axis).map(|side| node.planes[axis][side][lane]);
                let near = (near - origin) * ray.inv_near[axis];
                let far = (far - origin) * ray.inv_far[axis];
                enter = max_keep(near, enter);
                exit = min_keep(far, exit);
            }
            *entry = enter;
            mask |= LaneMask::from(enter <= exit) << lane;
        }
        (mask, entries)
    }

    fn push_children(
        node: &WideNode,
        mask: LaneMask,
        entries: &[f32; WIDTH],
        octant: u32,
        stack: &mut Stack,
    ) -> u32 {
        for slot in node.slots_far_to_near(octant) {
            if mask & 1 << slot != 0 {
                stack.push(node.child[slot], entries[slot]);
            }
        }
        stack.pop().expect("two or more children were pushed").0
    }

    fn push_children_in_slot_order(
        node: &WideNode,
        mask: LaneMask,
        entries: &[f32; WIDTH],
        stack: &mut Stack,
    ) -> u32 {
        for slot in lanes(mask) {
            stack.push(node.child[slot], entries[slot]);
        }
        stack.pop().expect("two or more children were pushed").0
    }

    type TriangleRay = ();

    fn triangle_ray(_ray: &WatertightRay, _reach: f32) {}

    fn triangle_lanes(block: &TriangleBlock, _ray: &(), _segment: &Segment) -> TriangleLanes {
        TriangleLanes {
            inside: 0,
            undecided: block.stored_lanes(),
            edges: [[0.0; BLOCK_WIDTH]; 3],
        }
    }

    /// Every stored lane may be hit; none is proved hit.
    fn filter<const PROVE_HITS: bool>(
        block: &TriangleBlock,
        _norms: &EdgeNorms,
        _ray: &Ray,
    ) -> Filtered {
        Filtered {
            may_hit: block.stored_lanes(),
            hit: 0,
        }
    }

    #[inline(never)]
    fn outlined<R>(make: impl FnOnce() -> R) -> R {
        make()
    }
}
