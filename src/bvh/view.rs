//! What the debug views read from our BVHs, whatever their width: the
//! boxes of one level and the node visits of a closest-hit query. Both the
//! binary [`Bvh`] and the 8-wide [`WideBvh`] answer it.
//!
//! A level is a depth in the tree with the root's box at 0. In the binary
//! tree every node has a box of its own; in the wide tree a node stores its
//! children's boxes, so level 0 is the union of the root's children and
//! level `k` holds the boxes of the children of the nodes at level `k - 1`,
//! inner and leaf alike.

use super::Bvh;
use super::wide::{Child, WIDTH, WideBvh};
use crate::geometry::{Aabb, Hit, Ray};
use crate::trace::Intersector;

pub trait BvhView: Intersector + Send {
    /// Depth of the deepest leaf plus one (0 for an empty tree).
    fn levels(&self) -> u32;

    /// The boxes at depth `level` (root = 0), in tree order; empty beyond
    /// the deepest leaf.
    fn boxes_at_level(&self, level: u32) -> Vec<Aabb>;

    /// The closest hit, as [`Intersector::intersect`], adding the nodes the
    /// traversal visits (with their boxes or triangles tested) to `visits`.
    fn intersect_counting(&self, ray: &Ray, visits: &mut u32) -> Option<Hit>;
}

impl BvhView for Bvh {
    fn levels(&self) -> u32 {
        self.stats().levels
    }

    fn boxes_at_level(&self, level: u32) -> Vec<Aabb> {
        let nodes = self.nodes();
        let mut boxes = Vec::new();
        let mut stack = if nodes.is_empty() {
            vec![]
        } else {
            vec![(0usize, 0u32)]
        };
        while let Some((index, depth)) = stack.pop() {
            let node = &nodes[index];
            if depth == level {
                boxes.push(node.bounds());
            } else if let Some([left, right]) = node.children() {
                stack.extend([(right, depth + 1), (left, depth + 1)]);
            }
        }
        boxes
    }

    fn intersect_counting(&self, ray: &Ray, visits: &mut u32) -> Option<Hit> {
        self.intersect_counted(ray, visits)
    }
}

impl BvhView for WideBvh {
    fn levels(&self) -> u32 {
        self.stats().levels
    }

    fn boxes_at_level(&self, level: u32) -> Vec<Aabb> {
        let nodes = self.nodes();
        let Some(root) = nodes.first() else {
            return Vec::new();
        };
        if level == 0 {
            return vec![root.bounds()];
        }
        // Nodes whose children are at `level`, depth first.
        let mut boxes = Vec::new();
        let mut stack = vec![(0usize, 1u32)];
        while let Some((index, depth)) = stack.pop() {
            let node = &nodes[index];
            if depth == level {
                boxes.extend(
                    (0..WIDTH)
                        .filter(|&slot| node.child(slot) != Child::Empty)
                        .map(|slot| node.child_bounds(slot)),
                );
                continue;
            }
            stack.extend((0..WIDTH).rev().filter_map(|slot| match node.child(slot) {
                Child::Inner(child) => Some((child, depth + 1)),
                _ => None,
            }));
        }
        boxes
    }

    fn intersect_counting(&self, ray: &Ray, visits: &mut u32) -> Option<Hit> {
        self.intersect_counted(ray, visits)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::BuildOptions;
    use crate::bvh::test_meshes::{Rng, random_soup};
    use crate::geometry::TriangleMesh;
    use glam::Vec3;

    /// 64 small triangles in a row.
    fn row() -> TriangleMesh {
        let triangles: Vec<[Vec3; 3]> = (0..64)
            .map(|i| {
                let base = Vec3::new(i as f32, (i % 5) as f32, 0.0);
                [base, base + Vec3::X * 0.5, base + Vec3::Y * 0.5]
            })
            .collect();
        TriangleMesh::soup(&triangles)
    }

    /// Every level's boxes together contain every triangle below them, the
    /// root level is the mesh's box, and nothing lies beyond the deepest.
    fn check_levels(tree: &dyn BvhView, mesh: &TriangleMesh) {
        assert_eq!(tree.boxes_at_level(0), vec![mesh.bounds()]);
        let deepest = tree.levels() - 1;
        for level in 0..=deepest {
            let boxes = tree.boxes_at_level(level);
            assert!(!boxes.is_empty(), "level {level}");
            for b in &boxes {
                assert!(mesh.bounds().contains(b), "level {level}: {b:?}");
            }
        }
        assert!(tree.boxes_at_level(deepest + 1).is_empty());
    }

    #[test]
    fn each_level_lies_inside_the_tree_and_ends_at_the_deepest_leaf() {
        let mesh = row();
        let binary = Bvh::build(&mesh, &BuildOptions::median());
        check_levels(&binary, &mesh);
        assert_eq!(binary.boxes_at_level(1).len(), 2);
        let wide = WideBvh::build(&mesh);
        check_levels(&wide, &mesh);
        // Level 1 holds the root's children: at most eight.
        assert!((2..=WIDTH).contains(&wide.boxes_at_level(1).len()));
    }

    #[test]
    fn counting_visits_changes_no_hit() {
        let mut rng = Rng::new(60);
        let mesh = random_soup(2000, 0.1, &mut rng);
        let trees: [Box<dyn BvhView>; 2] = [
            Box::new(Bvh::build(&mesh, &BuildOptions::sah())),
            Box::new(WideBvh::build(&mesh)),
        ];
        for tree in &trees {
            let mut total = 0;
            for _ in 0..200 {
                let ray = Ray::new(rng.point(-3.0, 3.0), rng.point(-1.0, 1.0));
                let mut visits = 0;
                assert_eq!(
                    tree.intersect_counting(&ray, &mut visits),
                    tree.intersect(&ray)
                );
                total += visits;
            }
            assert!(total > 200, "{total} visits");
        }
    }
}
