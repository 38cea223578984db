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
use std::cmp::Ordering;
use std::collections::BinaryHeap;

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

/// A merge on the queue: how much it raises the cost, or a lower bound on
/// that, and the two clusters with the versions it was priced at.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Candidate {
    rise: f64,
    exact: bool,
    pair: (u8, u8),
    versions: (u8, u8),
}

impl Eq for Candidate {}

impl Ord for Candidate {
    /// The least rise first, then the first pair: reversed, for
    /// [`BinaryHeap`]'s greatest-first.
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .rise
            .total_cmp(&self.rise)
            .then(self.exact.cmp(&other.exact))
            .then(other.pair.cmp(&self.pair))
    }
}

impl PartialOrd for Candidate {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// The clustering's state. Merges are priced lazily: a merge enters the
/// queue with a lower bound on its rise and is priced exactly only when
/// it comes first (the Cornell box's clustering prices about 100, of 496
/// pairs at the start). The cost of a merge depends only on its two
/// clusters, so a price stays valid until one of them changes (their
/// versions).
struct Clustering {
    triangles: Vec<[DVec3; 3]>,
    boxes: Vec<Bounds>,
    /// Each triangle's cluster, named by its first triangle.
    owner: Vec<usize>,
    /// By first triangle; `None` once merged into another.
    clusters: Vec<Option<Cluster>>,
    /// Merges each cluster has taken part in (below 64).
    versions: Vec<u8>,
    queue: BinaryHeap<Candidate>,
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
        let total_area = triangles.iter().map(triangle_area).sum();
        let n = triangles.len();
        let mut clustering = Clustering {
            owner: (0..n).collect(),
            clusters: vec![None; n],
            versions: vec![0; n],
            queue: BinaryHeap::new(),
            root_area: scale(root.map_or(0.0, |r| r.half_area())),
            total_area: scale(total_area),
            triangles,
            boxes,
        };
        for t in 0..n {
            let area = triangle_area(&clustering.triangles[t]);
            clustering.clusters[t] = Some(clustering.cluster(clustering.boxes[t], 1, area, (t, t)));
        }
        for i in 0..n {
            clustering.queue_merges_of(i, i + 1..n);
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
    /// with its pair and rise; off the queue. A merge priced exactly is
    /// taken at once if it still comes first, and queued again if not.
    fn cheapest_merge(&mut self) -> Option<(Cluster, (usize, usize), f64)> {
        while let Some(candidate) = self.queue.pop() {
            let (i, j) = (candidate.pair.0 as usize, candidate.pair.1 as usize);
            let (Some(a), Some(b)) = (self.clusters[i], self.clusters[j]) else {
                continue;
            };
            if candidate.versions != (self.versions[i], self.versions[j]) {
                continue;
            }
            let merge = self.merged(&a, &b, (i, j));
            let priced = Candidate {
                rise: merge.cost - a.cost - b.cost,
                exact: true,
                ..candidate
            };
            if self.queue.peek().is_none_or(|next| priced >= *next) {
                return Some((merge, (i, j), priced.rise));
            }
            self.queue.push(priced);
        }
        None
    }

    /// Whether a merge of `pair` rising by `rise` lowers the cost, or
    /// leaves it as it is within [`TIE`].
    fn pays(&self, (i, j): (usize, usize), rise: f64) -> bool {
        let cost = |c: usize| self.clusters[c].map_or(0.0, |c| c.cost);
        rise <= TIE * (cost(i) + cost(j))
    }

    fn merge(&mut self, merged: Cluster, (i, j): (usize, usize)) {
        self.clusters[i] = Some(merged);
        self.clusters[j] = None;
        self.versions[i] += 1;
        self.versions[j] += 1;
        for owner in &mut self.owner {
            if *owner == j {
                *owner = i;
            }
        }
        self.queue_merges_of(i, 0..self.clusters.len());
    }

    /// Queues the merges of cluster `i` with the clusters in `others`
    /// whose triangles fit in one block with its, each with a lower bound
    /// on its rise: its overlap is at least either cluster's but for the
    /// other's triangles.
    fn queue_merges_of(&mut self, i: usize, others: std::ops::Range<usize>) {
        let Some(a) = self.clusters[i] else { return };
        for j in others {
            let Some(b) = self.clusters[j].filter(|b| j != i && a.size + b.size <= BLOCK_WIDTH)
            else {
                continue;
            };
            let overlap = (a.overlap - b.area).max(b.overlap - a.area).max(0.0);
            let least = self.cost(&a.bounds.union(b.bounds), overlap);
            let (first, second) = (i.min(j), i.max(j));
            self.queue.push(Candidate {
                rise: least - a.cost - b.cost,
                exact: false,
                pair: (first as u8, second as u8),
                versions: (self.versions[first], self.versions[second]),
            });
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
        let corners = &self.triangles[t];
        if bounds.contains(&self.boxes[t]) {
            triangle_area(corners)
        } else if bounds.overlaps(&self.boxes[t]) {
            area_inside(corners, &self.boxes[t], bounds)
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
    let mut polygons = [Polygon::from(corners), Polygon::from(corners)];
    let mut current = 0;
    for axis in 0..3 {
        let (lower, upper) = (bounds.lower[axis], bounds.upper[axis]);
        let crossed = [
            (lower, 1.0, own.lower[axis] < lower),
            (upper, -1.0, own.upper[axis] > upper),
        ];
        for (plane, side, _) in crossed.into_iter().filter(|&(_, _, crossed)| crossed) {
            let [first, second] = &mut polygons;
            let (from, into) = if current == 0 {
                (first, second)
            } else {
                (second, first)
            };
            from.clip_into(into, axis, plane, side);
            current = 1 - current;
        }
    }
    polygons[current].area()
}

/// A convex polygon of up to nine corners: a triangle clipped by six
/// planes, each adding at most one.
struct Polygon {
    corners: [DVec3; 9],
    len: usize,
}

impl Polygon {
    fn from(triangle: &[DVec3; 3]) -> Polygon {
        let mut corners = [DVec3::ZERO; 9];
        corners[..3].copy_from_slice(triangle);
        Polygon { corners, len: 3 }
    }

    /// Writes into `clipped` the part where `side * (p[axis] - plane) >= 0`.
    fn clip_into(&self, clipped: &mut Polygon, axis: usize, plane: f64, side: f64) {
        clipped.len = 0;
        let inside = |p: DVec3| side * (p[axis] - plane) >= 0.0;
        for k in 0..self.len {
            let (p, q) = (self.corners[k], self.corners[(k + 1) % self.len]);
            if inside(p) {
                clipped.push(p);
            }
            if inside(p) != inside(q) {
                let mut crossing = p + (q - p) * ((plane - p[axis]) / (q[axis] - p[axis]));
                crossing[axis] = plane;
                clipped.push(crossing);
            }
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
