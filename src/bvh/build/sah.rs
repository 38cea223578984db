//! Binned surface area heuristic split, after Wald, "On fast Construction of
//! SAH-based Bounding Volume Hierarchies" (IEEE RT 2007), with the cost model
//! of MacDonald and Booth (1990).
//!
//! Centroids are binned into equal-width bins along each axis; the split
//! candidates are the bin boundaries, each priced in one sweep from either
//! side.

use super::{BuildPrim, centroid_bounds, median};
use crate::bvh::stats::{INTERSECTION_COST, TRAVERSAL_COST, surface_area};
use crate::geometry::Aabb;
use std::cell::RefCell;

/// A candidate split: triangles whose centroid falls in a bin below
/// `boundary` along `axis` go left.
#[derive(Clone, Copy, Debug)]
struct Split {
    axis: usize,
    boundary: usize,
    /// The children's part of the SAH cost, times the node's surface area.
    cost: f64,
}

/// Maps centroid coordinates along one axis to bins.
#[derive(Clone, Copy, Debug)]
struct Binning {
    axis: usize,
    min: f32,
    scale: f32,
    bins: usize,
}

impl Binning {
    fn bin(&self, prim: &BuildPrim) -> usize {
        // A float-to-int `as` saturates (NaN gives 0), so the index is
        // always in range; to `u32`, it is cheaper than to `usize`.
        (((prim.centroid[self.axis] - self.min) * self.scale) as u32 as usize).min(self.bins - 1)
    }
}

/// Partitions `prims` (at least 2, inside `bounds`) at the cheapest binned
/// split and returns the split index, or `None` for a leaf: when the SAH
/// prices the leaf no higher than any split and `must_split` is false. When
/// a split is required but no bin boundary separates the centroids, falls
/// back to the median split.
pub(in crate::bvh) fn partition(
    prims: &mut [BuildPrim],
    bounds: Aabb,
    bins: usize,
    must_split: bool,
) -> Option<usize> {
    let area = surface_area(&bounds);
    let leaf_cost = INTERSECTION_COST * prims.len() as f64 * area;
    let centroids = centroid_bounds(prims);
    match cheapest_split(prims, &centroids, bins) {
        Some(split) if must_split || TRAVERSAL_COST * area + split.cost < leaf_cost => {
            let binning = binning(&centroids, split.axis, bins)?;
            Some(partition_by(prims, |p| binning.bin(p) < split.boundary))
        }
        None if must_split => Some(median::partition(prims)),
        _ => None,
    }
}

fn binning(centroids: &Aabb, axis: usize, bins: usize) -> Option<Binning> {
    let extent = centroids.max[axis] - centroids.min[axis];
    (extent > 0.0).then(|| Binning {
        axis,
        min: centroids.min[axis],
        scale: bins as f32 / extent,
        bins,
    })
}

/// One bin's tallies, per axis: how many centroids fall in it, their
/// triangles' box, and (filled by the sweep) the cost of it and all bins
/// above it.
#[derive(Clone, Copy)]
struct Bin {
    counts: [usize; 3],
    boxes: [Aabb; 3],
    right_cost: f64,
}

impl Bin {
    const EMPTY: Bin = Bin {
        counts: [0; 3],
        boxes: [Aabb::EMPTY; 3],
        right_cost: 0.0,
    };
}

thread_local! {
    /// Each thread's bins, reused: three fresh `Vec`s per split cost about
    /// a fifth of the build in allocation.
    static BINS: RefCell<Vec<Bin>> = const { RefCell::new(Vec::new()) };
}

/// The cheapest split over all axes and bin boundaries that leaves both
/// sides non-empty; ties go to the lower axis, then the lower boundary.
/// All three axes are binned in one pass over `prims`.
fn cheapest_split(prims: &[BuildPrim], centroids: &Aabb, bins: usize) -> Option<Split> {
    let binnings = [0, 1, 2].map(|axis| binning(centroids, axis, bins));
    BINS.with_borrow_mut(|tallies| {
        tallies.clear();
        tallies.resize(bins, Bin::EMPTY);
        for prim in prims {
            for (axis, binning) in binnings.iter().enumerate() {
                if let Some(binning) = binning {
                    let bin = &mut tallies[binning.bin(prim)];
                    bin.counts[axis] += 1;
                    bin.boxes[axis] = bin.boxes[axis].union(prim.bounds);
                }
            }
        }
        let mut best: Option<Split> = None;
        for axis in (0..3).filter(|&axis| binnings[axis].is_some()) {
            // right_cost of bin b: area × count of everything in bins b.. .
            let (mut right_box, mut right_count) = (Aabb::EMPTY, 0usize);
            for bin in tallies[1..].iter_mut().rev() {
                right_box = right_box.union(bin.boxes[axis]);
                right_count += bin.counts[axis];
                bin.right_cost = surface_area(&right_box) * right_count as f64;
            }
            let (mut left_box, mut left_count) = (Aabb::EMPTY, 0usize);
            for boundary in 1..bins {
                left_box = left_box.union(tallies[boundary - 1].boxes[axis]);
                left_count += tallies[boundary - 1].counts[axis];
                if left_count == 0 || left_count == prims.len() {
                    continue;
                }
                let cost = INTERSECTION_COST
                    * (surface_area(&left_box) * left_count as f64 + tallies[boundary].right_cost);
                if best.is_none_or(|b| cost < b.cost) {
                    best = Some(Split {
                        axis,
                        boundary,
                        cost,
                    });
                }
            }
        }
        best
    })
}

/// Moves the elements satisfying `goes_left` to the front; returns how many
/// there are.
fn partition_by(prims: &mut [BuildPrim], goes_left: impl Fn(&BuildPrim) -> bool) -> usize {
    let mut mid = 0;
    for i in 0..prims.len() {
        if goes_left(&prims[i]) {
            prims.swap(i, mid);
            mid += 1;
        }
    }
    mid
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::build::bounds_of;
    use glam::Vec3;

    fn small_prim(prim: u32, centre: Vec3) -> BuildPrim {
        BuildPrim::new(
            prim,
            [centre, centre + 0.01 * Vec3::X, centre + 0.01 * Vec3::Y],
        )
    }

    #[test]
    fn separates_two_distant_clusters() {
        let mut prims: Vec<BuildPrim> = (0..20)
            .map(|i| {
                let far = if i % 2 == 0 { 10.0 } else { 0.0 };
                small_prim(i, Vec3::new(0.01 * i as f32, far, 0.02 * i as f32))
            })
            .collect();
        let bounds = bounds_of(&prims);
        let mid = partition(&mut prims, bounds, 16, false).expect("a split");
        assert_eq!(mid, 10);
        let near_side = prims[0].centroid.y < 5.0;
        assert!(
            prims[..mid]
                .iter()
                .all(|p| (p.centroid.y < 5.0) == near_side)
        );
        assert!(
            prims[mid..]
                .iter()
                .all(|p| (p.centroid.y < 5.0) != near_side)
        );
    }

    #[test]
    fn keeps_a_leaf_when_splitting_costs_more() {
        // Three large, heavily overlapping triangles: any split pays the
        // traversal and still tests nearly the whole area twice.
        let big = |prim: u32, dx: f32| {
            BuildPrim::new(
                prim,
                [
                    Vec3::new(dx, 0.0, 0.0),
                    Vec3::new(dx + 10.0, 0.0, 0.0),
                    Vec3::new(dx, 10.0, 0.0),
                ],
            )
        };
        let mut prims = vec![big(0, 0.0), big(1, 0.1), big(2, 0.2)];
        let bounds = bounds_of(&prims);
        assert_eq!(partition(&mut prims, bounds, 16, false), None);
        let mid = partition(&mut prims, bounds, 16, true).expect("forced split");
        assert!((1..3).contains(&mid));
    }

    #[test]
    fn falls_back_to_the_median_when_centroids_coincide() {
        let mut prims: Vec<BuildPrim> = (0..9).map(|i| small_prim(i, Vec3::ONE)).collect();
        let bounds = bounds_of(&prims);
        assert_eq!(partition(&mut prims, bounds, 16, false), None);
        assert_eq!(partition(&mut prims, bounds, 16, true), Some(4));
    }
}
