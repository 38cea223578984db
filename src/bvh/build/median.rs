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

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn prim_at(prim: u32, centre: Vec3) -> BuildPrim {
        BuildPrim::new(
            prim,
            [centre, centre + 0.1 * Vec3::Y, centre + 0.1 * Vec3::Z],
        )
    }

    #[test]
    fn splits_at_the_median_of_the_longest_centroid_axis() {
        // Centroids spread 0..9 along y (longest), 0..0.9 along x.
        let order = [7u32, 2, 9, 0, 4, 8, 1, 6, 3, 5];
        let mut prims: Vec<BuildPrim> = order
            .iter()
            .map(|&i| prim_at(i, Vec3::new(0.1 * (9 - i) as f32, i as f32, 0.0)))
            .collect();
        assert_eq!(partition(&mut prims), 5);
        let mut left: Vec<u32> = prims[..5].iter().map(|p| p.prim).collect();
        left.sort_unstable();
        assert_eq!(left, [0, 1, 2, 3, 4]);
    }

    #[test]
    fn identical_centroids_split_in_half() {
        let mut prims: Vec<BuildPrim> = (0..7).map(|i| prim_at(i, Vec3::ONE)).collect();
        assert_eq!(partition(&mut prims), 3);
    }
}
