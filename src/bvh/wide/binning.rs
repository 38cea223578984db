//! The split of the wide build: binned SAH over all three axes in one pass
//! (Wald, "On fast Construction of SAH-based Bounding Volume Hierarchies",
//! IEEE RT 2007), with boxes and centroids as four-lane vectors so every
//! bound is one `min`/`max` instruction (as in Embree's `PrimRef` bins,
//! Wald et al., "Embree: A Kernel Framework for Efficient CPU Ray
//! Tracing", ACM TOG 2014), and an in-place partition without a branch on
//! each triangle's side, then a pass bounding both sides: three passes
//! over a split's range, each in order. A long range is partitioned in
//! pieces, whose misplaced triangles then swap across the split once.
//!
//! The SAH counts triangles in blocks of [`BLOCK_WIDTH`], the unit a leaf
//! tests at once (Embree's `sahBlockSize`), which favours full blocks.

use super::node::BLOCK_WIDTH;
use super::prefetch::prefetch_line;
use crate::geometry::aabb::half_area;
use glam::{BVec4A, IVec4, Mat4, Vec3, Vec4};
use rayon::prelude::*;
use std::cmp::Ordering;

/// Bins per axis.
pub(super) const BINS: usize = 16;

/// Ranges of more triangles than this are binned and partitioned on
/// rayon's workers.
const PARALLEL_BINNING: usize = 1 << 12;

/// Ranges of at least this many triangles are binned into two sets of
/// bins ([`Bins::fill`]).
const TWO_SETS: usize = 48;

/// How many triangles (2 KiB) ahead of itself a pass over a range asks
/// for them ([`prefetch_line`]). Binning and partitioning read their range
/// in order, and on ranges far larger than the caches they waited for it:
/// loading the triangles took 40% of the binning's time on dragon-14m, and
/// asking ahead made its whole build 15% faster (Xeon, one thread).
const PREFETCH_AHEAD: usize = 64;

/// One triangle as the wide builder sees it: its box, with the mesh
/// triangle index in the lower corner's fourth lane (which no bound reads).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub(super) struct Prim {
    lower: Vec4,
    upper: Vec4,
}

impl Prim {
    /// Stands for a triangle the build leaves out; its id is one no
    /// triangle has (they are below `MAX_INDEX`).
    pub const UNUSABLE: Prim = Prim {
        lower: Vec4::new(0.0, 0.0, 0.0, f32::from_bits(u32::MAX)),
        upper: Vec4::ZERO,
    };

    pub fn new(prim: u32, corners: [Vec3; 3]) -> Self {
        let [a, b, c] = corners;
        Prim {
            lower: a.min(b).min(c).extend(f32::from_bits(prim)),
            upper: a.max(b).max(c).extend(0.0),
        }
    }

    pub fn prim(&self) -> u32 {
        self.lower.w.to_bits()
    }

    /// Twice the box centre (no overflow: coordinates are below 2^62).
    fn centroid(&self) -> Vec4 {
        self.lower + self.upper
    }
}

/// A box as two four-lane corners; the fourth lane means nothing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Bounds {
    pub lower: Vec4,
    pub upper: Vec4,
}

impl Bounds {
    pub const EMPTY: Bounds = Bounds {
        lower: Vec4::splat(f32::INFINITY),
        upper: Vec4::splat(f32::NEG_INFINITY),
    };

    fn grow(&mut self, lower: Vec4, upper: Vec4) {
        self.lower = self.lower.min(lower);
        self.upper = self.upper.max(upper);
    }

    fn union(self, other: Bounds) -> Bounds {
        Bounds {
            lower: self.lower.min(other.lower),
            upper: self.upper.max(other.upper),
        }
    }

    /// Half the surface area; 0 for an empty box.
    fn half_area(&self) -> f32 {
        let e = (self.upper - self.lower).truncate().max(Vec3::ZERO);
        half_area(e.x, e.y, e.z)
    }

    pub fn lower(&self) -> Vec3 {
        self.lower.truncate()
    }

    pub fn upper(&self) -> Vec3 {
        self.upper.truncate()
    }
}

/// A range's box and the box of its (doubled) centroids.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct RangeBounds {
    pub boxes: Bounds,
    pub centroids: Bounds,
}

impl RangeBounds {
    pub const EMPTY: RangeBounds = RangeBounds {
        boxes: Bounds::EMPTY,
        centroids: Bounds::EMPTY,
    };

    /// The bounds of `prims`. Even and odd triangles are bounded apart,
    /// then together: each bound waits for the one before it, and two
    /// chains halve that wait (the root node's splits of the monkey 12%
    /// faster; Xeon, one thread).
    pub fn of(prims: &[Prim]) -> Self {
        let (mut even, mut odd) = (Self::EMPTY, Self::EMPTY);
        let pairs = prims.chunks_exact(2);
        pairs.remainder().iter().for_each(|p| even.add(p));
        for pair in pairs {
            even.add(&pair[0]);
            odd.add(&pair[1]);
        }
        even.union(odd)
    }

    pub fn add(&mut self, prim: &Prim) {
        self.boxes.grow(prim.lower, prim.upper);
        let centroid = prim.centroid();
        self.centroids.grow(centroid, centroid);
    }

    pub fn union(self, other: RangeBounds) -> RangeBounds {
        RangeBounds {
            boxes: self.boxes.union(other.boxes),
            centroids: self.centroids.union(other.centroids),
        }
    }

    pub fn half_area(&self) -> f32 {
        self.boxes.half_area()
    }
}

/// Maps centroids to bins on all three axes at once.
#[derive(Clone, Copy)]
struct Binning {
    origin: Vec4,
    /// Bins per unit of doubled centroid, per axis; 0 on an axis where the
    /// centroids do not spread.
    scale: Vec4,
}

impl Binning {
    fn new(centroids: &Bounds) -> Self {
        let extent = centroids.upper - centroids.lower;
        // Slightly fewer than BINS bins per extent keeps the largest
        // centroid in the last bin; an axis without extent bins nothing.
        let per_extent = BINS as f32 * (1.0 - 2.0 * f32::EPSILON);
        let scale = Vec4::select(
            extent.cmpgt(Vec4::ZERO),
            Vec4::splat(per_extent) / extent,
            Vec4::ZERO,
        );
        Binning {
            origin: centroids.lower,
            scale,
        }
    }

    /// The bin of `prim` on each axis.
    #[inline(always)]
    fn bins(&self, prim: &Prim) -> [usize; 3] {
        let [x, y, z, _] = truncate((prim.centroid() - self.origin) * self.scale);
        // Finite centroids scale into [0, BINS); the clamp keeps any
        // other value (a negative one wraps to a large one) in range too.
        [x, y, z].map(|bin| (bin as u32).min(BINS as u32 - 1) as usize)
    }
}

/// Each lane rounded towards zero to an integer, as `x as i32` does for
/// values in range (others give some value in range or `i32::MIN`).
#[inline(always)]
fn truncate(v: Vec4) -> [i32; 4] {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{__m128i, _mm_cvttps_epi32};
        // SAFETY: SSE2 is part of every x86-64 CPU; `__m128i` and
        // `[i32; 4]` have the same size and every bit pattern is valid
        // for both.
        unsafe { std::mem::transmute::<__m128i, [i32; 4]>(_mm_cvttps_epi32(v.into())) }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        v.to_array().map(|x| x as i32)
    }
}

/// The triangles' boxes and counts per axis and bin.
struct Bins {
    boxes: [[Bounds; BINS]; 3],
    counts: [[i32; BINS]; 3],
}

impl Bins {
    fn new() -> Self {
        Bins {
            boxes: [[Bounds::EMPTY; BINS]; 3],
            counts: [[0; BINS]; 3],
        }
    }

    fn add(&mut self, prim: &Prim, binning: &Binning) {
        for (axis, bin) in binning.bins(prim).into_iter().enumerate() {
            self.boxes[axis][bin].grow(prim.lower, prim.upper);
            self.counts[axis][bin] += 1;
        }
    }

    /// Adds `prims` to the bins. Neighbours in a range mostly fall in the
    /// same bins, and each update of a bin waits for the one before it; on
    /// longer ranges, even and odd triangles fill two sets of bins, which
    /// halves that chain, and the sets are merged. The bins are filled in
    /// place: returned by value, their 1.7 KiB were copied at every split
    /// (2.6% of the monkey's build; Xeon, one thread).
    fn fill(&mut self, prims: &[Prim], binning: &Binning) {
        if prims.len() < TWO_SETS {
            prims.iter().for_each(|p| self.add(p, binning));
            return;
        }
        let mut odd = Bins::new();
        let pairs = prims.chunks_exact(2);
        pairs.remainder().iter().for_each(|p| self.add(p, binning));
        for (index, pair) in pairs.enumerate() {
            prefetch_line(prims.as_ptr().wrapping_add(2 * index + PREFETCH_AHEAD));
            self.add(&pair[0], binning);
            odd.add(&pair[1], binning);
        }
        self.merge(&odd);
    }

    /// Adds `other`'s triangles (exact, so the bins of a range do not
    /// depend on how it was cut up).
    fn merge(&mut self, other: &Bins) {
        for axis in 0..3 {
            for bin in 0..BINS {
                self.boxes[axis][bin] = self.boxes[axis][bin].union(other.boxes[axis][bin]);
                self.counts[axis][bin] += other.counts[axis][bin];
            }
        }
    }

    /// Adds `prims`, filled in parallel for long ranges.
    fn fill_all(&mut self, prims: &[Prim], binning: &Binning) {
        if prims.len() <= PARALLEL_BINNING {
            return self.fill(prims, binning);
        }
        let parts = prims
            .par_chunks(PARALLEL_BINNING / 4)
            .fold(Bins::new, |mut bins, chunk| {
                bins.fill(chunk, binning);
                bins
            })
            .collect::<Vec<Bins>>();
        parts.iter().for_each(|part| self.merge(part));
    }
}

/// The blocks that `counts` triangles fill, per lane (0 for none): a
/// side's SAH cost is its half area times these.
fn blocks(counts: IVec4) -> Vec4 {
    ((counts + BLOCK_WIDTH as i32 - 1) / BLOCK_WIDTH as i32).as_vec4()
}

/// The half areas of the three boxes, one lane each ([`Bounds::half_area`]
/// on each, with the extents transposed so that all three take one set of
/// vector operations).
fn half_areas(boxes: &[Bounds; 3]) -> Vec4 {
    let extent = |b: &Bounds| (b.upper - b.lower).max(Vec4::ZERO);
    let lanes = Mat4::from_cols(
        extent(&boxes[0]),
        extent(&boxes[1]),
        extent(&boxes[2]),
        Vec4::ZERO,
    )
    .transpose();
    half_area(lanes.x_axis, lanes.y_axis, lanes.z_axis)
}

/// Where to split: triangles whose bin on `axis` is below `boundary` go
/// left.
#[derive(Clone, Copy, Debug)]
struct Split {
    axis: usize,
    boundary: usize,
}

/// The cheapest split by the SAH over all axes and bin boundaries that
/// leaves both sides non-empty; ties go to the lower axis, then the lower
/// boundary. `None` when the centroids share one bin on every axis.
///
/// The three axes are swept at once, one per lane, as in Embree's
/// `BinInfoT::best`. Every boundary between two filled bins is tried; the
/// boundaries past empty bins cost what the one before them does and so
/// never win a tie.
fn cheapest_split(bins: &Bins) -> Option<Split> {
    let union = |sides: &mut [Bounds; 3], bin: usize| {
        for (axis, side) in sides.iter_mut().enumerate() {
            *side = side.union(bins.boxes[axis][bin]);
        }
    };
    let counts = |bin: usize| {
        let [x, y, z] = bins.counts.map(|axis| axis[bin]);
        IVec4::new(x, y, z, 0)
    };
    // `right_cost[b]` and `right_blocks[b]`: bins `b..` on each axis.
    let mut right_cost = [Vec4::ZERO; BINS];
    let mut right_blocks = [Vec4::ZERO; BINS];
    let (mut right, mut right_count) = ([Bounds::EMPTY; 3], IVec4::ZERO);
    for bin in (1..BINS).rev() {
        union(&mut right, bin);
        right_count += counts(bin);
        right_blocks[bin] = blocks(right_count);
        right_cost[bin] = half_areas(&right) * right_blocks[bin];
    }
    let (mut left, mut left_count) = ([Bounds::EMPTY; 3], IVec4::ZERO);
    let mut found = BVec4A::FALSE;
    let (mut best_cost, mut best_boundary) = (Vec4::ZERO, Vec4::ZERO);
    for bin in 0..BINS - 1 {
        union(&mut left, bin);
        left_count += counts(bin);
        let left_blocks = blocks(left_count);
        let cost = half_areas(&left) * left_blocks + right_cost[bin + 1];
        let both_sides = left_blocks.cmpgt(Vec4::ZERO) & right_blocks[bin + 1].cmpgt(Vec4::ZERO);
        let better = both_sides & (!found | cost.cmplt(best_cost));
        best_cost = Vec4::select(better, cost, best_cost);
        best_boundary = Vec4::select(better, Vec4::splat((bin + 1) as f32), best_boundary);
        found |= both_sides;
    }
    let mut best: Option<(f32, Split)> = None;
    for axis in (0..3).filter(|&axis| found.test(axis)) {
        if best.is_none_or(|(c, _)| best_cost[axis] < c) {
            let boundary = best_boundary[axis] as usize;
            best = Some((best_cost[axis], Split { axis, boundary }));
        }
    }
    best.map(|(_, split)| split)
}

/// Splits `prims` (at least two, with bounds `bounds`) at the cheapest
/// binned SAH split (for a block's worth or fewer, the cheapest of a full
/// sweep, [`sweep_split`]), or at the median centroid of the longest axis
/// when no bin boundary separates them or `halve` asks for equal halves. Returns
/// the split index (in `1..prims.len()`) and both sides' bounds.
pub(super) fn split(
    prims: &mut [Prim],
    bounds: &RangeBounds,
    halve: bool,
) -> (usize, RangeBounds, RangeBounds) {
    if !halve && prims.len() <= BLOCK_WIDTH {
        return sweep_split(prims);
    }
    let binning = Binning::new(&bounds.centroids);
    let split = if halve {
        None
    } else {
        let mut bins = Bins::new();
        bins.fill_all(prims, &binning);
        cheapest_split(&bins)
    };
    match split {
        Some(Split { axis, boundary }) => {
            // `bins(prim)[axis] < boundary`, on the one axis: the scaled
            // value lies in [0, BINS), so its integer part is below the
            // boundary exactly when the value is.
            let (origin, scale) = (binning.origin[axis], binning.scale[axis]);
            let limit = boundary as f32;
            partition(prims, &|prim: &Prim| {
                let (lower, upper): (&[f32; 4], &[f32; 4]) =
                    (prim.lower.as_ref(), prim.upper.as_ref());
                (lower[axis] + upper[axis] - origin) * scale < limit
            })
        }
        None => median_split(prims, &bounds.centroids),
    }
}

/// Moves the triangles for which `goes_left` holds to the front; returns
/// how many there are and both sides' bounds. Long ranges are cut into
/// pieces of [`PARALLEL_BINNING`] triangles, partitioned in parallel; the
/// right parts that lie in the left side's place then swap with the left
/// parts that lie in the right side's, the first with the first
/// ([`exchange`]). Every misplaced triangle moves once, where halving the
/// range and rotating the halves' middles moved each again at every
/// level of halving (a sixth of dragon-14m's build, one thread). The order
/// within each side depends on the range's length only, not on the
/// threads.
fn partition(
    prims: &mut [Prim],
    goes_left: &(impl Fn(&Prim) -> bool + Sync),
) -> (usize, RangeBounds, RangeBounds) {
    if prims.len() <= PARALLEL_BINNING {
        return partition_in_place(prims, goes_left);
    }
    let pieces: Vec<(usize, RangeBounds, RangeBounds)> = prims
        .par_chunks_mut(PARALLEL_BINNING)
        .map(|piece| partition_in_place(piece, goes_left))
        .collect();
    let mid = pieces.iter().map(|(left, _, _)| left).sum();
    // Each piece's right part where the left side goes, and its left part
    // where the right side goes.
    let (mut misplaced_right, mut misplaced_left) = (Vec::new(), Vec::new());
    for (index, (left, _, _)) in pieces.iter().enumerate() {
        let begin = index * PARALLEL_BINNING;
        let end = (begin + PARALLEL_BINNING).min(prims.len());
        let split = begin + left;
        if split < mid {
            misplaced_right.push(split..end.min(mid));
        }
        if split > mid {
            misplaced_left.push(begin.max(mid)..split);
        }
    }
    let swaps = pair_up(&misplaced_right, &misplaced_left);
    let (left_side, right_side) = prims.split_at_mut(mid);
    exchange(left_side, 0, right_side, mid, &swaps);
    let (left, right) = pieces.iter().fold(
        (RangeBounds::EMPTY, RangeBounds::EMPTY),
        |(left, right), (_, piece_left, piece_right)| {
            (left.union(*piece_left), right.union(*piece_right))
        },
    );
    (mid, left, right)
}

/// A run of misplaced triangles to swap: `len` from `left` (in the left
/// side's place) with as many from `right` (in the right side's).
#[derive(Clone, Copy)]
struct Swap {
    left: usize,
    right: usize,
    len: usize,
}

/// Pairs the misplaced right triangles with the misplaced left ones, the
/// i-th with the i-th, both in range order (there are as many of each).
fn pair_up(
    misplaced_right: &[std::ops::Range<usize>],
    misplaced_left: &[std::ops::Range<usize>],
) -> Vec<Swap> {
    let mut swaps = Vec::new();
    let mut lefts = misplaced_left.iter().cloned();
    let mut left = lefts.next().unwrap_or_default();
    for right in misplaced_right {
        let mut right = right.clone();
        while !right.is_empty() {
            if left.is_empty() {
                left = lefts.next().expect("as many misplaced on each side");
            }
            let len = right.len().min(left.len());
            swaps.push(Swap {
                left: right.start,
                right: left.start,
                len,
            });
            right.start += len;
            left.start += len;
        }
    }
    swaps
}

/// Carries out `swaps` between `left_side` (which starts at triangle
/// `left_at` of the range) and `right_side` (at `right_at`), halving the
/// list on rayon's workers: the swaps are in order on both sides, so each
/// half's triangles lie apart from the other's.
fn exchange(
    left_side: &mut [Prim],
    left_at: usize,
    right_side: &mut [Prim],
    right_at: usize,
    swaps: &[Swap],
) {
    const SWAPS_ON_ONE_THREAD: usize = 8;
    if swaps.len() <= SWAPS_ON_ONE_THREAD {
        for swap in swaps {
            let left = &mut left_side[swap.left - left_at..][..swap.len];
            left.swap_with_slice(&mut right_side[swap.right - right_at..][..swap.len]);
        }
        return;
    }
    let (first, second) = swaps.split_at(swaps.len() / 2);
    let (left_first, left_second) = left_side.split_at_mut(second[0].left - left_at);
    let (right_first, right_second) = right_side.split_at_mut(second[0].right - right_at);
    rayon::join(
        || exchange(left_first, left_at, right_first, right_at, first),
        || {
            exchange(
                left_second,
                second[0].left,
                right_second,
                second[0].right,
                second,
            )
        },
    );
}

/// [`partition`] on one thread, in Lomuto's scheme without a branch on
/// the side: each triangle is swapped to the end of the left part, and
/// that end moves past it when it goes left. Hoare's scheme, reading each
/// triangle once, branches on every side, and a range's mixed sides
/// mispredict: the whole build was 12-18% slower with it (dragon-48k,
/// one and two threads; Xeon). The sides' bounds take a pass of their own.
fn partition_in_place(
    prims: &mut [Prim],
    goes_left: impl Fn(&Prim) -> bool,
) -> (usize, RangeBounds, RangeBounds) {
    let mut mid = 0;
    for i in 0..prims.len() {
        prefetch_line(prims.as_ptr().wrapping_add(i + PREFETCH_AHEAD));
        let prim = prims[i];
        let left = goes_left(&prim);
        prims[i] = prims[mid];
        prims[mid] = prim;
        mid += usize::from(left);
    }
    let (left, right) = prims.split_at(mid);
    (mid, RangeBounds::of(left), RangeBounds::of(right))
}

/// The SAH split of at most a block of triangles, by a sweep over their
/// order along each axis (centroid, then prim id) rather than bins: as
/// cheap for so few, and exact. Every side is one block, so the cost is
/// the sum of the two half areas; the smallest wins, ties to the lower
/// axis, then the earlier cut.
fn sweep_split(prims: &mut [Prim]) -> (usize, RangeBounds, RangeBounds) {
    let n = prims.len();
    assert!((2..=BLOCK_WIDTH).contains(&n), "{n} triangles");
    let orders = [0, 1, 2].map(|axis| sweep_order(prims, axis));
    // The three axes are swept at once, one per lane, as in
    // [`cheapest_split`]: `sides[axis]` bounds the triangles on one side
    // of the cut in that axis's order.
    let grow = |sides: &mut [Bounds; 3], at: usize| {
        for (side, order) in sides.iter_mut().zip(&orders) {
            let prim = &prims[order[at] as usize];
            side.grow(prim.lower, prim.upper);
        }
    };
    let mut right_areas = [Vec4::ZERO; BLOCK_WIDTH];
    let mut right = [Bounds::EMPTY; 3];
    for cut in (1..n).rev() {
        grow(&mut right, cut);
        right_areas[cut] = half_areas(&right);
    }
    let mut left = [Bounds::EMPTY; 3];
    let (mut best_cost, mut best_cut) = (Vec4::INFINITY, Vec4::ONE);
    for (cut, right_area) in right_areas.iter().enumerate().take(n).skip(1) {
        grow(&mut left, cut - 1);
        let cost = half_areas(&left) + *right_area;
        let better = cost.cmplt(best_cost);
        best_cost = Vec4::select(better, cost, best_cost);
        best_cut = Vec4::select(better, Vec4::splat(cut as f32), best_cut);
    }
    let axis = (1..3).fold(0, |best, axis| {
        if best_cost[axis] < best_cost[best] {
            axis
        } else {
            best
        }
    });
    let cut = best_cut[axis] as usize;
    let order = &orders[axis];
    let sorted: [Prim; BLOCK_WIDTH] = std::array::from_fn(|i| prims[order[i.min(n - 1)] as usize]);
    prims.copy_from_slice(&sorted[..n]);
    let (left, right) = prims.split_at(cut);
    (cut, RangeBounds::of(left), RangeBounds::of(right))
}

/// The indices of `prims` (at most a block) in order of their centroids on
/// `axis`, ties by prim id, by insertion.
fn sweep_order(prims: &[Prim], axis: usize) -> [u8; BLOCK_WIDTH] {
    let key = |i: u8| {
        let prim = &prims[i as usize];
        (prim.centroid()[axis], prim.prim())
    };
    let mut order = [0; BLOCK_WIDTH];
    for i in 0..prims.len() as u8 {
        let mut at = i as usize;
        while at > 0 && key(order[at - 1]).partial_cmp(&key(i)) == Some(Ordering::Greater) {
            order[at] = order[at - 1];
            at -= 1;
        }
        order[at] = i;
    }
    order
}

/// Splits at the median centroid along the longest centroid axis, ties by
/// prim id (so identical triangles still split in half).
fn median_split(prims: &mut [Prim], centroids: &Bounds) -> (usize, RangeBounds, RangeBounds) {
    let extent = (centroids.upper - centroids.lower).truncate();
    let axis = if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    let mid = prims.len() / 2;
    prims.select_nth_unstable_by(mid, |a, b| {
        a.centroid()[axis]
            .total_cmp(&b.centroid()[axis])
            .then(a.prim().cmp(&b.prim()))
    });
    let (left, right) = prims.split_at(mid);
    (mid, RangeBounds::of(left), RangeBounds::of(right))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn small_prim(prim: u32, centre: Vec3) -> Prim {
        Prim::new(
            prim,
            [centre, centre + 0.01 * Vec3::X, centre + 0.01 * Vec3::Y],
        )
    }

    fn ids(prims: &[Prim]) -> Vec<u32> {
        let mut ids: Vec<u32> = prims.iter().map(Prim::prim).collect();
        ids.sort_unstable();
        ids
    }

    #[test]
    fn separates_two_distant_clusters_and_bounds_both_sides() {
        // Twenty triangles are binned; a block's worth or fewer are swept.
        for count in [20, BLOCK_WIDTH as u32, 3] {
            separates_two_clusters(count);
        }
    }

    fn separates_two_clusters(count: u32) {
        let mut prims: Vec<Prim> = (0..count)
            .map(|i| {
                let far = if i % 2 == 0 { 10.0 } else { 0.0 };
                small_prim(i, Vec3::new(0.01 * i as f32, far, 0.02 * i as f32))
            })
            .collect();
        let bounds = RangeBounds::of(&prims);
        let (mid, left, right) = split(&mut prims, &bounds, false);
        let near_side = prims[0].lower.y < 5.0;
        let near = (0..count).filter(|i| (i % 2 == 1) == near_side).count();
        assert_eq!(mid, near, "{count} triangles");
        assert_eq!(left, RangeBounds::of(&prims[..mid]));
        assert_eq!(right, RangeBounds::of(&prims[mid..]));
        assert!(prims[..mid].iter().all(|p| (p.lower.y < 5.0) == near_side));
        assert!(prims[mid..].iter().all(|p| (p.lower.y < 5.0) != near_side));
        assert_eq!(ids(&prims), (0..count).collect::<Vec<_>>());
    }

    #[test]
    fn coincident_centroids_and_halving_split_at_the_median() {
        let mut prims: Vec<Prim> = (0..9).map(|i| small_prim(8 - i, Vec3::ONE)).collect();
        let bounds = RangeBounds::of(&prims);
        let (mid, left, _) = split(&mut prims, &bounds, false);
        assert_eq!(mid, 4);
        assert_eq!(ids(&prims[..mid]), [0, 1, 2, 3]);
        assert_eq!(left, RangeBounds::of(&prims[..mid]));

        // Two clusters of 4 and 12: the SAH cuts between them, halving
        // cuts through the larger.
        let mut prims: Vec<Prim> = (0..16)
            .map(|i| {
                let x = if i < 4 {
                    0.1 * i as f32
                } else {
                    50.0 + i as f32
                };
                small_prim(i, Vec3::new(x, 0.0, 0.0))
            })
            .collect();
        let bounds = RangeBounds::of(&prims);
        assert_eq!(split(&mut prims.clone(), &bounds, false).0, 4);
        assert_eq!(split(&mut prims, &bounds, true).0, 8);
    }

    /// Every length the partition takes in one piece or cuts into pieces
    /// (above [`PARALLEL_BINNING`]; the longest swaps enough runs to
    /// exchange them on several workers), with each side empty or mixed: the
    /// sides hold what the predicate says, nothing is lost, and the
    /// bounds are each side's.
    #[test]
    fn the_partition_keeps_every_triangle_on_its_side_with_its_bounds() {
        let mut rng = crate::bvh::test_meshes::Rng::new(71);
        let many_pieces = 40 * PARALLEL_BINNING + 7;
        for len in [
            0,
            1,
            2,
            PARALLEL_BINNING,
            PARALLEL_BINNING + 1,
            10_000,
            many_pieces,
        ] {
            let prims: Vec<Prim> = (0..len as u32)
                .map(|i| small_prim(i, rng.point(-1.0, 1.0)))
                .collect();
            type Side<'a> = &'a (dyn Fn(&Prim) -> bool + Sync);
            let sides: [(&str, Side); 3] = [
                ("mixed", &|p: &Prim| p.lower.x < 0.0),
                ("all left", &|_: &Prim| true),
                ("all right", &|_: &Prim| false),
            ];
            for (name, goes_left) in sides {
                let mut parted = prims.clone();
                let (mid, left, right) = partition(&mut parted, &goes_left);
                let case = format!("{len} triangles, {name}");
                assert!(parted[..mid].iter().all(goes_left), "{case}");
                assert!(!parted[mid..].iter().any(goes_left), "{case}");
                assert_eq!(ids(&parted), (0..len as u32).collect::<Vec<_>>(), "{case}");
                assert_eq!(left, RangeBounds::of(&parted[..mid]), "{case}");
                assert_eq!(right, RangeBounds::of(&parted[mid..]), "{case}");
            }
        }
    }

    /// The SAH split found the plain way: each axis on its own, every
    /// boundary with triangles on both sides, the first cheapest kept.
    fn cheapest_split_axis_by_axis(bins: &Bins) -> Option<(usize, usize)> {
        let mut best: Option<(f32, (usize, usize))> = None;
        for axis in 0..3 {
            for boundary in 1..BINS {
                let side = |range: std::ops::Range<usize>| {
                    let bounds = range
                        .clone()
                        .fold(Bounds::EMPTY, |b, bin| b.union(bins.boxes[axis][bin]));
                    let count = range.map(|bin| bins.counts[axis][bin] as u32).sum::<u32>();
                    (
                        bounds.half_area() * count.div_ceil(BLOCK_WIDTH as u32) as f32,
                        count,
                    )
                };
                let ((left_cost, left), (right_cost, right)) =
                    (side(0..boundary), side(boundary..BINS));
                let cost = left_cost + right_cost;
                if left > 0 && right > 0 && best.is_none_or(|(c, _)| cost < c) {
                    best = Some((cost, (axis, boundary)));
                }
            }
        }
        best.map(|(_, split)| split)
    }

    /// Ranges from two triangles to a few hundred, in clusters that leave
    /// bins empty and tie costs, some flat on an axis or all in one point.
    #[test]
    fn the_three_lane_sweep_splits_as_a_sweep_axis_by_axis() {
        let mut rng = crate::bvh::test_meshes::Rng::new(5);
        for case in 0..400 {
            let len = 2 + rng.below(300);
            let clusters = 1 + rng.below(4);
            let centres: Vec<Vec3> = (0..clusters).map(|_| rng.point(-4.0, 4.0)).collect();
            let flat = Vec3::select(
                glam::BVec3::new(case % 3 == 0, case % 5 == 0, false),
                Vec3::ZERO,
                Vec3::ONE,
            );
            let spread = [0.0, 0.01, 1.0][case % 3];
            let prims: Vec<Prim> = (0..len as u32)
                .map(|i| {
                    let centre = centres[rng.below(clusters)] + spread * rng.point(-1.0, 1.0);
                    small_prim(i, centre * flat)
                })
                .collect();
            let binning = Binning::new(&RangeBounds::of(&prims).centroids);
            let mut bins = Bins::new();
            bins.fill(&prims, &binning);
            let lanes = cheapest_split(&bins).map(|s| (s.axis, s.boundary));
            assert_eq!(
                lanes,
                cheapest_split_axis_by_axis(&bins),
                "case {case}, {len} triangles"
            );
        }
    }

    #[test]
    fn the_sah_prefers_full_blocks() {
        // Three blocks' worth of triangles evenly spaced: counted one by
        // one, the halves are cheapest; counted in blocks, one block and
        // two full ones (three blocks in all, against four).
        let count = 3 * BLOCK_WIDTH as u32;
        let mut prims: Vec<Prim> = (0..count)
            .map(|i| small_prim(i, Vec3::new(i as f32, 0.0, 0.0)))
            .collect();
        let bounds = RangeBounds::of(&prims);
        let (mid, _, _) = split(&mut prims, &bounds, false);
        assert!(mid == BLOCK_WIDTH || mid == 2 * BLOCK_WIDTH, "{mid}");
    }
}
