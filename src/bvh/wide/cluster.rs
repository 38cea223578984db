//! The leaves of a mesh small enough for one node, formed bottom up.
//!
//! A mesh of at most [`MAX_TRIANGLES`] fits in the leaves of one node, so
//! its tree is just how its triangles are grouped into at most [`WIDTH`]
//! leaves. They are grouped by agglomerative clustering (Walter, Bala,
//! Kulkarni, Pingali, "Fast Agglomerative Clustering for Rendering", IEEE
//! RT 2008): starting from one cluster a triangle, the two clusters whose
//! merge adds least to the leaves' cost are merged, until no merge lowers
//! it and at most [`WIDTH`] remain.
//!
//! A leaf's cost is the surface area heuristic's chance that a ray enters
//! its box, mixed with its end-point overlap (Aila, Karras, Laine, "On
//! Quality Metrics of Bounding Volume Hierarchies", HPG 2013): the area of
//! the other triangles inside its box, relative to all of them. A ray
//! that ends on such a triangle has entered the box before its hit, so the
//! leaf is tested; the surface area heuristic models rays that never end
//! and misses that. In a room it is what decides: the top-down split put
//! the Cornell box's light, ceiling and two side walls in one leaf whose
//! box is the whole room, which nearly every ray entered before its hit;
//! clustered, each wall is a flat leaf of its own.

use super::binning::Prim;
use super::node::{BLOCK_WIDTH, WIDTH};
use crate::geometry::TriangleMesh;
use crate::geometry::aabb::half_area;
use glam::DVec3;

/// Meshes of at most this many triangles are clustered: a full block in
/// every slot of one node.
pub(super) const MAX_TRIANGLES: usize = WIDTH * BLOCK_WIDTH;

/// The end-point overlap's weight in a leaf's cost, the surface area
/// heuristic's being the rest. Chosen on the Cornell box (AMD EPYC,
/// AVX-512 kernel, one thread, six alternating runs of each tree): the
/// leaves clustered with 0.7 traced primary, shadow and diffuse rays 4%,
/// 49% and 8% faster than the top-down tree's; those of 0.3-0.5 (both
/// blocks' tops in one leaf) 3% slower, 39% and 5% faster; those of the
/// surface area heuristic alone (the floor with a block's side) 2% slower,
/// 34% and 3% faster.
const OVERLAP_WEIGHT: f64 = 0.7;

/// A merge whose cost rises by at most this share of its two clusters'
/// cost is taken: within rounding it costs nothing, and it leaves one
/// block fewer (two halves of a quad, whose boxes are the same).
const TIE: f64 = 1e-9;

/// Groups `prims` into the leaves of one node: reorders them leaf by leaf
/// and returns the leaves' sizes, in order. `None` when no grouping into
/// [`WIDTH`] blocks was found (the caller builds top down).
pub(super) fn leaves(mesh: &TriangleMesh, prims: &mut [Prim]) -> Option<Vec<usize>> {
    assert!(prims.len() <= MAX_TRIANGLES, "{} triangles", prims.len());
    let triangles: Vec<_> = prims
        .iter()
        .map(|p| mesh.triangle(p.prim() as usize).map(|c| c.as_dvec3()))
        .collect();
    let owner = Clustering::new(triangles).run()?;
    let mut order: Vec<usize> = (0..prims.len()).collect();
    order.sort_by_key(|&t| (owner[t], t));
    let sorted: Vec<Prim> = order.iter().map(|&t| prims[t]).collect();
    prims.copy_from_slice(&sorted);
    let leaves = order.chunk_by(|&s, &t| owner[s] == owner[t]);
    Some(leaves.map(<[usize]>::len).collect())
}

/// A closed box in `f64`.
#[derive(Clone, Copy, Debug)]
struct Bounds {
    lower: DVec3,
    upper: DVec3,
}

impl Bounds {
    fn of(corners: &[DVec3; 3]) -> Bounds {
        let [a, b, c] = *corners;
        Bounds {
            lower: a.min(b).min(c),
            upper: a.max(b).max(c),
        }
    }

    fn union(self, other: Bounds) -> Bounds {
        Bounds {
            lower: self.lower.min(other.lower),
            upper: self.upper.max(other.upper),
        }
    }

    fn overlaps(&self, other: &Bounds) -> bool {
        self.lower.cmple(other.upper).all() && other.lower.cmple(self.upper).all()
    }

    fn contains(&self, other: &Bounds) -> bool {
        self.lower.cmple(other.lower).all() && other.upper.cmple(self.upper).all()
    }

    fn half_area(&self) -> f64 {
        let e = self.upper - self.lower;
        half_area(e.x, e.y, e.z)
    }
}

/// A cluster: its box, its triangle count, its triangles' area, the
/// area of the other triangles inside its box and its cost as a leaf.
#[derive(Clone, Copy)]
struct Cluster {
    bounds: Bounds,
    size: usize,
    area: f64,
    overlap: f64,
    cost: f64,
}

/// A merge of two clusters at a price, as one number in the order merges
/// are taken: the least rise first (its `f64` by [`f64::total_cmp`]), an
/// exact price before a lower bound on the same rise, then the first
/// pair (a byte each). [`Merge::NONE`], after all others, stands where
/// two clusters cannot merge.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
struct Merge(u128);

// A merge's pair takes a byte per cluster.
const _: () = assert!(MAX_TRIANGLES <= 256);

impl Merge {
    const NONE: Merge = Merge(u128::MAX);

    fn new(rise: f64, exact: bool, (i, j): (usize, usize)) -> Merge {
        let bits = rise.to_bits();
        // `total_cmp`'s order as an unsigned one: negatives reversed, below
        // the positives.
        let ordered = if bits >> 63 == 1 {
            !bits
        } else {
            bits | 1 << 63
        };
        let pair = (i.min(j) << 8 | i.max(j)) as u128;
        Merge(u128::from(ordered) << 64 | u128::from(!exact) << 16 | pair)
    }

    fn rise(self) -> f64 {
        let ordered = (self.0 >> 64) as u64;
        f64::from_bits(if ordered >> 63 == 1 {
            ordered ^ 1 << 63
        } else {
            !ordered
        })
    }

    fn pair(self) -> (usize, usize) {
        ((self.0 >> 8 & 0xff) as usize, (self.0 & 0xff) as usize)
    }

    fn involves(self, cluster: usize) -> bool {
        let (i, j) = self.pair();
        self != Merge::NONE && (i == cluster || j == cluster)
    }
}

/// The clustering's state. Merges are priced lazily: every pair of
/// clusters whose triangles fit in one block starts with a lower bound on
/// its rise, and is priced exactly only when it comes first (the Cornell
/// box's clustering prices 80 merges exactly, of 496 pairs at the start).
/// The cost of a merge depends only on its two clusters, so a price stays
/// valid until one of them changes. Each cluster keeps its own first
/// merge, so the first of all is found among the clusters rather than
/// among the pairs.
struct Clustering {
    triangles: Vec<[DVec3; 3]>,
    boxes: Vec<Bounds>,
    areas: Vec<f64>,
    /// Each triangle's cluster, named by its first triangle.
    owner: Vec<usize>,
    /// By first triangle; `None` once merged into another.
    clusters: Vec<Option<Cluster>>,
    /// `merges[i * n + j]`, the same as `[j * n + i]`: the merge of
    /// clusters `i` and `j` at its price, [`Merge::NONE`] where they cannot
    /// merge (one is gone, or their triangles do not fit in one block).
    merges: Vec<Merge>,
    /// Each cluster's first merge.
    nearest: Vec<Merge>,
    /// The scene's box's half area and the triangles' total area, the
    /// two costs' scales (1 when 0, for flat or empty meshes).
    root_area: f64,
    total_area: f64,
}

impl Clustering {
    fn new(triangles: Vec<[DVec3; 3]>) -> Clustering {
        let boxes: Vec<Bounds> = triangles.iter().map(Bounds::of).collect();
        let scale = |x: f64| if x > 0.0 { x } else { 1.0 };
        let root = boxes.iter().copied().reduce(Bounds::union);
        let areas: Vec<f64> = triangles.iter().map(triangle_area).collect();
        let n = triangles.len();
        let mut clustering = Clustering {
            owner: (0..n).collect(),
            clusters: vec![None; n],
            merges: vec![Merge::NONE; n * n],
            nearest: vec![Merge::NONE; n],
            root_area: scale(root.map_or(0.0, |r| r.half_area())),
            total_area: scale(areas.iter().sum()),
            triangles,
            boxes,
            areas,
        };
        for t in 0..n {
            let (bounds, area) = (clustering.boxes[t], clustering.areas[t]);
            clustering.clusters[t] = Some(clustering.cluster(bounds, 1, area, (t, t)));
        }
        for i in 0..n {
            clustering.bound_merges_of(i, i + 1..n);
        }
        for i in 0..n {
            clustering.nearest[i] = clustering.find_nearest(i);
        }
        clustering
    }

    /// Merges until no merge lowers the cost and at most [`WIDTH`]
    /// clusters remain; each triangle's cluster, or `None` when more than
    /// [`WIDTH`] remain and no two fit in one block.
    fn run(mut self) -> Option<Vec<usize>> {
        let mut left = self.triangles.len();
        loop {
            match self.cheapest_merge() {
                Some((merge, pair, rise)) if left > WIDTH || self.pays(pair, rise) => {
                    self.merge(merge, pair);
                    left -= 1;
                }
                None if left > WIDTH => return None,
                _ => return Some(self.owner),
            }
        }
    }

    /// The merge that raises the cost least (the first pair on a tie),
    /// with its pair and rise. The first merge is priced exactly, and
    /// taken if it still comes first.
    fn cheapest_merge(&mut self) -> Option<(Cluster, (usize, usize), f64)> {
        loop {
            let (i, j) = self.cheapest()?.pair();
            let (Some(a), Some(b)) = (self.clusters[i], self.clusters[j]) else {
                unreachable!("a merge of clusters {i} and {j}, one of them gone");
            };
            let merged = self.merged(&a, &b, (i, j));
            let priced = Merge::new(merged.cost - a.cost - b.cost, true, (i, j));
            self.set((i, j), priced);
            self.nearest[i] = self.find_nearest(i);
            self.nearest[j] = self.find_nearest(j);
            if self.cheapest() == Some(priced) {
                return Some((merged, (i, j), priced.rise()));
            }
        }
    }

    /// The first of all clusters' first merges.
    fn cheapest(&self) -> Option<Merge> {
        self.nearest
            .iter()
            .copied()
            .min()
            .filter(|&m| m != Merge::NONE)
    }

    /// Cluster `i`'s first merge.
    fn find_nearest(&self, i: usize) -> Merge {
        let n = self.clusters.len();
        self.merges[i * n..(i + 1) * n]
            .iter()
            .copied()
            .min()
            .unwrap_or(Merge::NONE)
    }

    /// Records `merge` as the merge of clusters `i` and `j`.
    fn set(&mut self, (i, j): (usize, usize), merge: Merge) {
        let n = self.clusters.len();
        self.merges[i * n + j] = merge;
        self.merges[j * n + i] = merge;
    }

    /// Whether a merge of `pair` rising by `rise` lowers the cost, or
    /// leaves it as it is within [`TIE`].
    fn pays(&self, (i, j): (usize, usize), rise: f64) -> bool {
        let cost = |c: usize| self.clusters[c].map_or(0.0, |c| c.cost);
        rise <= TIE * (cost(i) + cost(j))
    }

    /// Merges cluster `j` into `i`, as `merged`, and finds again the first
    /// merges that involved either.
    fn merge(&mut self, merged: Cluster, (i, j): (usize, usize)) {
        let n = self.clusters.len();
        self.clusters[i] = Some(merged);
        self.clusters[j] = None;
        for owner in &mut self.owner {
            if *owner == j {
                *owner = i;
            }
        }
        for k in 0..n {
            self.set((j, k), Merge::NONE);
        }
        self.bound_merges_of(i, 0..n);
        for k in 0..n {
            let nearest = self.nearest[k];
            self.nearest[k] = if k == i || nearest.involves(i) || nearest.involves(j) {
                self.find_nearest(k)
            } else {
                nearest.min(self.merges[k * n + i])
            };
        }
    }

    /// Prices the merges of cluster `i` with the clusters in `others` with
    /// a lower bound on their rise ([`Merge::NONE`] where their triangles
    /// do not fit in one block): the merged overlap is at least either
    /// cluster's but for the other's triangles.
    fn bound_merges_of(&mut self, i: usize, others: std::ops::Range<usize>) {
        let Some(a) = self.clusters[i] else { return };
        for j in others {
            let merge = match self.clusters[j] {
                Some(b) if j != i && a.size + b.size <= BLOCK_WIDTH => {
                    let overlap = (a.overlap - b.area).max(b.overlap - a.area).max(0.0);
                    let least = self.cost(&a.bounds.union(b.bounds), overlap);
                    Merge::new(least - a.cost - b.cost, false, (i, j))
                }
                _ => Merge::NONE,
            };
            self.set((i, j), merge);
        }
    }

    /// The cluster `a` and `b` merge into.
    fn merged(&self, a: &Cluster, b: &Cluster, pair: (usize, usize)) -> Cluster {
        let bounds = a.bounds.union(b.bounds);
        self.cluster(bounds, a.size + b.size, a.area + b.area, pair)
    }

    /// The cluster of the triangles of clusters `owners` (the same one
    /// twice for a single cluster), with box `bounds`, priced.
    fn cluster(&self, bounds: Bounds, size: usize, area: f64, owners: (usize, usize)) -> Cluster {
        let overlap: f64 = (0..self.triangles.len())
            .filter(|&t| self.owner[t] != owners.0 && self.owner[t] != owners.1)
            .map(|t| self.area_inside(t, &bounds))
            .sum();
        let cost = self.cost(&bounds, overlap);
        Cluster {
            bounds,
            size,
            area,
            overlap,
            cost,
        }
    }

    /// A leaf's cost (module) from its box and its end-point overlap.
    fn cost(&self, bounds: &Bounds, overlap: f64) -> f64 {
        (1.0 - OVERLAP_WEIGHT) * bounds.half_area() / self.root_area
            + OVERLAP_WEIGHT * overlap / self.total_area
    }

    /// The area of triangle `t` inside `bounds`, clipped only where its
    /// box crosses theirs.
    fn area_inside(&self, t: usize, bounds: &Bounds) -> f64 {
        if bounds.contains(&self.boxes[t]) {
            self.areas[t]
        } else if bounds.overlaps(&self.boxes[t]) {
            area_inside(&self.triangles[t], &self.boxes[t], bounds)
        } else {
            0.0
        }
    }
}

fn triangle_area(corners: &[DVec3; 3]) -> f64 {
    let [a, b, c] = *corners;
    0.5 * (b - a).cross(c - a).length()
}

/// The area of the part of a triangle (with box `own`) inside a closed
/// box: the triangle clipped by those of the box's six planes its box
/// crosses, in turn (Sutherland and Hodgman, "Reentrant Polygon
/// Clipping", CACM 1974). A triangle in a flat box's plane is wholly
/// inside.
fn area_inside(corners: &[DVec3; 3], own: &Bounds, bounds: &Bounds) -> f64 {
    // The polygon and the buffer it is clipped into, taking turns.
    let (mut first, mut second) = (Polygon::from(corners), Polygon::EMPTY);
    let (mut polygon, mut buffer) = (&mut first, &mut second);
    for axis in 0..3 {
        let (lower, upper) = (bounds.lower[axis], bounds.upper[axis]);
        if own.lower[axis] < lower {
            polygon.clip_into(buffer, axis, lower, 1.0);
            std::mem::swap(&mut polygon, &mut buffer);
        }
        if own.upper[axis] > upper {
            polygon.clip_into(buffer, axis, upper, -1.0);
            std::mem::swap(&mut polygon, &mut buffer);
        }
    }
    polygon.area()
}

/// A convex polygon of up to nine corners: a triangle clipped by six
/// planes, each adding at most one.
struct Polygon {
    corners: [DVec3; 9],
    len: usize,
}

impl Polygon {
    const EMPTY: Polygon = Polygon {
        corners: [DVec3::ZERO; 9],
        len: 0,
    };

    fn from(&[a, b, c]: &[DVec3; 3]) -> Polygon {
        let zero = DVec3::ZERO;
        Polygon {
            corners: [a, b, c, zero, zero, zero, zero, zero, zero],
            len: 3,
        }
    }

    /// Writes into `clipped` the part where `side * (p[axis] - plane) >= 0`.
    fn clip_into(&self, clipped: &mut Polygon, axis: usize, plane: f64, side: f64) {
        clipped.len = 0;
        let inside = |p: DVec3| side * (p[axis] - plane) >= 0.0;
        let corners = &self.corners[..self.len];
        let Some(&first) = corners.first() else {
            return;
        };
        // Each edge `p -> q` in turn: `p` if inside, then where the edge
        // crosses the plane.
        let (mut p, mut p_inside) = (first, inside(first));
        for &q in corners[1..].iter().chain([&first]) {
            let q_inside = inside(q);
            if p_inside {
                clipped.push(p);
            }
            if p_inside != q_inside {
                let mut crossing = p + (q - p) * ((plane - p[axis]) / (q[axis] - p[axis]));
                crossing[axis] = plane;
                clipped.push(crossing);
            }
            (p, p_inside) = (q, q_inside);
        }
    }

    fn push(&mut self, corner: DVec3) {
        self.corners[self.len] = corner;
        self.len += 1;
    }

    fn area(&self) -> f64 {
        let Some(&first) = self.corners[..self.len].first() else {
            return 0.0;
        };
        let twice: DVec3 = (1..self.len.saturating_sub(1))
            .map(|k| (self.corners[k] - first).cross(self.corners[k + 1] - first))
            .sum();
        0.5 * twice.length()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::wide::WideBvh;
    use glam::{Vec3, Vec3Swizzles};

    #[test]
    fn a_triangle_inside_a_box_counts_whole_and_a_cut_one_in_part() {
        let triangle = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let around = Bounds {
            lower: DVec3::splat(-1.0),
            upper: DVec3::splat(1.0),
        };
        assert_eq!(area_inside(&triangle, &Bounds::of(&triangle), &around), 0.5);
        // Its plane as a flat box: the triangle lies wholly in it.
        let flat = Bounds {
            lower: DVec3::new(-1.0, -1.0, 0.0),
            upper: DVec3::new(1.0, 1.0, 0.0),
        };
        assert_eq!(area_inside(&triangle, &Bounds::of(&triangle), &flat), 0.5);
        // x <= 0.5 keeps all but the corner triangle of legs 0.5.
        let half = Bounds {
            upper: DVec3::new(0.5, 1.0, 1.0),
            ..around
        };
        assert!((area_inside(&triangle, &Bounds::of(&triangle), &half) - 0.375).abs() < 1e-15);
        let apart = Bounds {
            lower: DVec3::splat(2.0),
            upper: DVec3::splat(3.0),
        };
        assert_eq!(area_inside(&triangle, &Bounds::of(&triangle), &apart), 0.0);
    }

    #[test]
    fn merges_order_by_rise_then_exactness_then_pair() {
        let rises = [
            f64::NEG_INFINITY,
            -2.0,
            -1e-300,
            -0.0,
            0.0,
            1e-300,
            1.5,
            f64::INFINITY,
        ];
        for (k, &rise) in rises.iter().enumerate() {
            let merge = Merge::new(rise, false, (5, 3));
            assert_eq!(merge.rise().to_bits(), rise.to_bits());
            assert_eq!(merge.pair(), (3, 5));
            assert!(Merge::new(rise, true, (7, 8)) < merge);
            assert!(Merge::new(rise, false, (2, 9)) < merge);
            assert!(merge < Merge::NONE);
            if let Some(&next) = rises.get(k + 1) {
                assert!(merge < Merge::new(next, true, (0, 1)), "{rise} {next}");
            }
        }
        assert!(Merge::new(1.0, true, (0, 1)).involves(1));
        assert!(!Merge::new(1.0, true, (0, 1)).involves(2));
        assert!(!Merge::NONE.involves(255));
    }

    /// An open box of five walls, each two triangles, around a small cube:
    /// the walls enclose everything, so each is a flat leaf of its own
    /// rather than sharing one whose box is the whole room.
    #[test]
    fn walls_around_a_scene_are_flat_leaves_of_their_own() {
        let quad = |o: Vec3, u: Vec3, v: Vec3| [[o, o + u, o + u + v], [o, o + u + v, o + v]];
        let (x, y, z) = (Vec3::X * 10.0, Vec3::Y * 10.0, Vec3::Z * 10.0);
        let mut triangles: Vec<[Vec3; 3]> = [
            quad(Vec3::ZERO, x, z),
            quad(y, x, z),
            quad(z, x, y),
            quad(Vec3::ZERO, y, z),
            quad(x, y, z),
        ]
        .concat();
        let cube = Vec3::splat(4.0);
        for axis in [Vec3::X, Vec3::Y, Vec3::Z] {
            let (u, v) = (axis.yzx() * 2.0, axis.zxy() * 2.0);
            triangles.extend(quad(cube, u, v));
            triangles.extend(quad(cube + axis * 2.0, u, v));
        }
        let mesh = TriangleMesh::soup(&triangles);
        let wide = WideBvh::build(&mesh);
        wide.validate(&mesh).unwrap();
        let root = &wide.nodes()[0];
        let flat_leaves = (0..WIDTH)
            .map(|slot| root.child_bounds(slot))
            .filter(|b| b.min.cmple(b.max).all())
            .map(|b| b.max - b.min)
            .filter(|size| size.min_element() == 0.0 && size.max_element() == 10.0)
            .count();
        assert_eq!(flat_leaves, 5, "{:?}", wide.stats());
    }

    /// Nine groups of five triangles far apart cluster into nine leaves,
    /// no two of which fit in one block: the mesh is built top down, into
    /// more than one node.
    #[test]
    fn a_mesh_no_grouping_fits_in_one_node_is_built_top_down() {
        let triangles: Vec<[Vec3; 3]> = (0..9)
            .flat_map(|group| {
                (0..5).map(move |k| {
                    let o = Vec3::new(100.0 * group as f32, 0.1 * k as f32, 0.0);
                    [o, o + Vec3::X * 0.1, o + Vec3::Y * 0.1]
                })
            })
            .collect();
        let mesh = TriangleMesh::soup(&triangles);
        let mut prims: Vec<Prim> = (0..triangles.len())
            .map(|t| Prim::new(t as u32, triangles[t]))
            .collect();
        assert_eq!(leaves(&mesh, &mut prims), None);
        let wide = WideBvh::build(&mesh);
        wide.validate(&mesh).unwrap();
        assert!(wide.stats().nodes > 1, "{:?}", wide.stats());
    }
}
