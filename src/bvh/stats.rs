//! Summary numbers of a built tree, and the SAH cost model both the SAH
//! builder and the reported cost use.

use super::Node;
use crate::geometry::Aabb;
use crate::geometry::aabb::half_area;
use glam::Vec3;
use std::fmt;
use std::time::Duration;

/// Cost of visiting an inner node (the box tests of its two children), in
/// the surface area heuristic of MacDonald and Booth (1990).
pub const TRAVERSAL_COST: f64 = 1.0;

/// Cost of one ray/triangle test, in the same units. Equal to
/// [`TRAVERSAL_COST`]: one node visit tests two boxes, which costs about as
/// much as one watertight triangle test.
pub const INTERSECTION_COST: f64 = 1.0;

/// Surface area in f64, so SAH sums over huge boxes or many triangles do not
/// overflow; 0 for the empty box.
pub fn surface_area(b: &Aabb) -> f64 {
    if b.is_empty() {
        return 0.0;
    }
    let e = b.extent().as_dvec3();
    2.0 * half_area(e.x, e.y, e.z)
}

/// What a build produced.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BvhStats {
    /// Depth of the deepest leaf plus one (0 for an empty tree).
    pub levels: u32,
    pub nodes: usize,
    pub leaves: usize,
    /// Triangles in the tree.
    pub triangles: usize,
    /// Mesh triangles left out: a vertex not finite or beyond Embree's
    /// coordinate limit, or an index out of range.
    pub skipped_triangles: usize,
    pub max_leaf_triangles: u32,
    pub mean_leaf_triangles: f64,
    /// Expected cost of a random ray that hits the root box:
    /// sum over inner nodes of `TRAVERSAL_COST · A(node)/A(root)` plus sum
    /// over leaves of `INTERSECTION_COST · triangles · A(leaf)/A(root)`.
    /// When the root box has no area, each node counts with weight 1.
    pub sah_cost: f64,
    pub build_time: Duration,
    /// Memory held by the nodes, the triangle corners and the prim ids.
    pub bytes: usize,
}

impl BvhStats {
    pub(super) fn measure(
        nodes: &[Node],
        triangles: usize,
        skipped_triangles: usize,
        build_time: Duration,
    ) -> Self {
        let root_area = nodes
            .first()
            .map_or(0.0, |root| surface_area(&root.bounds()));
        let weight = |node: &Node| {
            if root_area > 0.0 {
                surface_area(&node.bounds()) / root_area
            } else {
                1.0
            }
        };
        let (mut levels, mut leaves, mut max_leaf, mut sah_cost) = (0u32, 0usize, 0u32, 0.0f64);
        let mut stack = if nodes.is_empty() {
            vec![]
        } else {
            vec![(0usize, 1u32)]
        };
        while let Some((index, level)) = stack.pop() {
            let node = &nodes[index];
            levels = levels.max(level);
            match node.children() {
                Some([left, right]) => {
                    sah_cost += TRAVERSAL_COST * weight(node);
                    stack.extend([(left, level + 1), (right, level + 1)]);
                }
                None => {
                    let count = node.triangle_slots().len();
                    leaves += 1;
                    max_leaf = max_leaf.max(count as u32);
                    sah_cost += INTERSECTION_COST * count as f64 * weight(node);
                }
            }
        }
        let corner_bytes = std::mem::size_of::<[Vec3; 3]>() + std::mem::size_of::<u32>();
        Self {
            levels,
            nodes: nodes.len(),
            leaves,
            triangles,
            skipped_triangles,
            max_leaf_triangles: max_leaf,
            mean_leaf_triangles: if leaves > 0 {
                triangles as f64 / leaves as f64
            } else {
                0.0
            },
            sah_cost,
            build_time,
            bytes: std::mem::size_of_val(nodes) + triangles * corner_bytes,
        }
    }
}

impl fmt::Display for BvhStats {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} triangles ({} skipped), {} nodes, {} leaves, {} levels, leaf size mean {:.2} max {}, SAH cost {:.2}, {:.1} MiB, built in {:.1} ms",
            self.triangles,
            self.skipped_triangles,
            self.nodes,
            self.leaves,
            self.levels,
            self.mean_leaf_triangles,
            self.max_leaf_triangles,
            self.sah_cost,
            self.bytes as f64 / (1024.0 * 1024.0),
            self.build_time.as_secs_f64() * 1e3,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::test_meshes::{Rng, random_soup};
    use crate::bvh::{BuildOptions, Bvh};
    use crate::geometry::TriangleMesh;

    #[test]
    fn single_triangle_and_empty_trees() {
        let one = TriangleMesh::soup(&[[Vec3::ZERO, Vec3::X, Vec3::Y]]);
        let s = *Bvh::build(&one, &BuildOptions::sah()).stats();
        assert_eq!(
            (s.levels, s.nodes, s.leaves, s.max_leaf_triangles),
            (1, 1, 1, 1)
        );
        assert_eq!(
            (s.mean_leaf_triangles, s.sah_cost),
            (1.0, INTERSECTION_COST)
        );
        assert_eq!(s.bytes, 32 + 36 + 4);
        let s = *Bvh::build(&TriangleMesh::default(), &BuildOptions::sah()).stats();
        assert_eq!(
            (s.levels, s.nodes, s.leaves, s.triangles, s.bytes),
            (0, 0, 0, 0, 0)
        );
        assert_eq!(s.sah_cost, 0.0);
    }

    #[test]
    fn sah_cost_adds_up_by_hand() {
        // Two unit triangles 10 apart along x: the root box is 11 × 1 × 0
        // (area 22), each leaf box 1 × 1 × 0 (area 2).
        let t = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let mesh = TriangleMesh::soup(&[t, t.map(|p| p + 10.0 * Vec3::X)]);
        let options = BuildOptions {
            max_leaf_size: 1,
            ..BuildOptions::median()
        };
        let s = *Bvh::build(&mesh, &options).stats();
        assert_eq!((s.nodes, s.leaves, s.levels), (3, 2, 2));
        let expected = TRAVERSAL_COST + 2.0 * INTERSECTION_COST * 2.0 / 22.0;
        assert!(
            (s.sah_cost - expected).abs() < 1e-12,
            "{} vs {expected}",
            s.sah_cost
        );
    }

    #[test]
    fn sah_builder_beats_median_split_on_its_own_measure() {
        let mesh = random_soup(20_000, 0.05, &mut Rng::new(30));
        let median = Bvh::build(&mesh, &BuildOptions::median()).stats().sah_cost;
        let sah = Bvh::build(&mesh, &BuildOptions::sah()).stats().sah_cost;
        assert!(sah < median, "SAH {sah} vs median {median}");
    }
}
