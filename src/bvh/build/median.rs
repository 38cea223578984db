//! Median split: the node's triangles are divided at the median centroid
//! along the longest axis of their centroid bounds (object median), as in a
//! classic course ray tracer.

use super::{BuildPrim, centroid_bounds};

/// Partitions `prims` (at least 2) so the first half has the smaller
/// centroids along the longest centroid axis; returns the split index,
/// always in `1..prims.len()`.
pub(super) fn partition(prims: &mut [BuildPrim]) -> usize {
    let axis = centroid_bounds(prims).longest_axis();
    let mid = prims.len() / 2;
    prims.select_nth_unstable_by(mid, |a, b| {
        a.centroid[axis]
            .total_cmp(&b.centroid[axis])
            .then(a.prim.cmp(&b.prim))
    });
    mid
}
