//! How much of its leaves' boxes a tree's triangles fill, which decides
//! whether incoherent closest-hit rays put each leaf through the any-hit
//! filter ([`super::lanes::Lanes::filter`]) before the kernel.
//!
//! By Cauchy's formula a convex body's mean projected area over all
//! directions is a quarter of its surface area, and a flat triangle's is
//! half its area: so of the uniformly distributed lines that enter a leaf's
//! box, a share `2·A / S` (at most 1) meets one of its triangles, `A` their
//! total area and `S` the box's surface area. That is the conditional
//! probability the surface area heuristic rests on (MacDonald and Booth,
//! "Heuristics for ray tracing using space subdivision", The Visual
//! Computer 6(3), 1990). Weighted by `S`, how often lines enter each leaf,
//! its mean over the leaves is the chance that a leaf a ray enters holds a
//! triangle it may hit.
//!
//! Where that chance is low, most leaves an incoherent ray enters are
//! empty of hits and the filter drops them before the kernel and the
//! ray's per-leaf set-up: diffuse rays 6-15% faster on the monkey and
//! dragon-11k to dragon-871k (chance 0.35-0.39), 2% on dragon-14m, Xeon,
//! AVX-512 (6-18% with AVX2). In the Cornell box (0.96) nearly every leaf
//! entered holds a candidate, and the filter only added its own cost
//! (diffuse rays 1-9% slower). Coherent rays never take it: their first
//! leaves usually hold their hit, and the filter cost primary rays 8-19%
//! on every scene.

use super::lanes::lanes;
use super::node::TriangleBlock;
use crate::geometry::Aabb;
use rayon::prelude::*;

/// Below this chance of a hit in a leaf entered, incoherent rays filter
/// the leaves.
const SPARSE_BELOW: f64 = 0.5;

/// Whether `blocks` leave most of their boxes empty (module). The build
/// asks it last, while its second worker is still awake
/// ([`super::awake`]), in pieces that let even a small tree's pass share
/// the workers: asked after the build and in pieces of 1024 blocks, it
/// kept the monkey's two-thread build 15-20 us longer (0.36-0.40 ms
/// against 0.34-0.37, warm; Xeon).
pub(super) fn is_sparse(blocks: &[TriangleBlock]) -> bool {
    let (weighted, total) = blocks
        .par_iter()
        .with_min_len(128)
        .map(|block| {
            let (area, surface) = area_and_box_surface(block);
            ((2.0 * area / surface).min(1.0) * surface, surface)
        })
        .reduce(|| (0.0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1));
    total > 0.0 && weighted < SPARSE_BELOW * total
}

/// The total area of `block`'s triangles and the surface area of their
/// box.
fn area_and_box_surface(block: &TriangleBlock) -> (f64, f64) {
    let (mut area, mut bounds) = (0.0, Aabb::EMPTY);
    for lane in lanes(block.stored_lanes()) {
        let [p0, p1, p2] = block.triangle(lane);
        area += 0.5 * f64::from((p1 - p0).cross(p2 - p0).length());
        bounds = bounds.grow(p0).grow(p1).grow(p2);
    }
    (area, f64::from(bounds.surface_area()))
}

#[cfg(test)]
mod tests {
    use super::is_sparse;
    use crate::bvh::test_meshes::{Rng, grid, random_soup};
    use crate::bvh::wide::WideBvh;

    #[test]
    fn flat_grids_fill_their_boxes_and_scattered_triangles_do_not() {
        // A plane of triangles: each leaf's box is flat, its surface twice
        // the triangles' area, so every line entering it meets one.
        assert!(!is_sparse(&WideBvh::build(&grid(32)).blocks));
        let soup = random_soup(4_000, 0.05, &mut Rng::new(57));
        assert!(is_sparse(&WideBvh::build(&soup).blocks));
        assert!(!is_sparse(&[]));
    }
}
