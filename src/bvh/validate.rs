//! The tree's invariants, checked against the mesh it was built from (as
//! obvhs validates every builder preset).

use super::build::usable_corners;
use super::{Bvh, Node};
use crate::geometry::{Aabb, TriangleMesh};

/// The first broken invariant found by [`Bvh::validate`].
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ValidationError {
    #[error("the tree holds {slots} triangle slots but {prim_ids} prim ids")]
    SlotCountMismatch { slots: usize, prim_ids: usize },
    #[error("slot {slot} names triangle {prim}, which the mesh does not have")]
    UnknownPrim { slot: usize, prim: u32 },
    #[error("mesh triangle {prim} appears {count} times; expected {expected}")]
    PrimCount {
        prim: usize,
        count: usize,
        expected: usize,
    },
    #[error("slot {slot} does not hold the corners of mesh triangle {prim}")]
    WrongCorners { slot: usize, prim: u32 },
    #[error("node {node} has children at {child}, outside the array or not after it")]
    BadChildIndex { node: usize, child: usize },
    #[error("node {node} is reached from more than one parent")]
    SharedNode { node: usize },
    #[error("{unreached} nodes are not reachable from the root")]
    UnreachableNodes { unreached: usize },
    #[error("leaf {node} holds slots {first}..{end}, outside the triangle array")]
    BadSlots {
        node: usize,
        first: usize,
        end: usize,
    },
    #[error("slot {slot} is in {count} leaves; expected 1")]
    SlotCoverage { slot: usize, count: usize },
    #[error("node {node}'s box {child:?} is not inside its parent's box {parent:?}")]
    ChildOutsideParent {
        node: usize,
        child: Aabb,
        parent: Aabb,
    },
    #[error("node {node}'s box {found:?} is not the tight box {tight:?} of its contents")]
    LooseBox {
        node: usize,
        found: Aabb,
        tight: Aabb,
    },
    #[error(
        "leaf {node} at depth {depth} holds {count} triangles; at most {max} allowed above the depth limit"
    )]
    LeafTooLarge {
        node: usize,
        depth: u32,
        count: usize,
        max: u32,
    },
    #[error("node {node} is at depth {depth}, beyond the limit {max}")]
    TooDeep { node: usize, depth: u32, max: u32 },
}

impl Bvh {
    /// Checks that every usable mesh triangle is stored exactly once with its
    /// own corners (and no other triangle is), that the nodes form one tree
    /// over all slots, that every box is exactly the union of its children's
    /// boxes or its triangles' bounds (so inside its parent), and that leaf
    /// sizes and depths respect the build options.
    pub fn validate(&self, mesh: &TriangleMesh) -> Result<(), ValidationError> {
        self.validate_triangles(mesh)?;
        self.validate_tree()
    }

    fn validate_triangles(&self, mesh: &TriangleMesh) -> Result<(), ValidationError> {
        if self.triangles.len() != self.prim_ids.len() {
            return Err(ValidationError::SlotCountMismatch {
                slots: self.triangles.len(),
                prim_ids: self.prim_ids.len(),
            });
        }
        let mut seen = vec![0usize; mesh.indices.len()];
        for (slot, (&prim, corners)) in self.prim_ids.iter().zip(&self.triangles).enumerate() {
            let count = seen
                .get_mut(prim as usize)
                .ok_or(ValidationError::UnknownPrim { slot, prim })?;
            *count += 1;
            if usable_corners(mesh, prim as usize).is_some_and(|c| c != *corners) {
                return Err(ValidationError::WrongCorners { slot, prim });
            }
        }
        for (prim, &count) in seen.iter().enumerate() {
            let expected = usize::from(usable_corners(mesh, prim).is_some());
            if count != expected {
                return Err(ValidationError::PrimCount {
                    prim,
                    count,
                    expected,
                });
            }
        }
        Ok(())
    }

    fn validate_tree(&self) -> Result<(), ValidationError> {
        let nodes = &self.nodes;
        if nodes.is_empty() {
            return match self.triangles.len() {
                0 => Ok(()),
                slots => Err(ValidationError::SlotCoverage {
                    slot: slots - 1,
                    count: 0,
                }),
            };
        }
        let mut reached = vec![false; nodes.len()];
        let mut slot_uses = vec![0usize; self.triangles.len()];
        let mut stack = vec![(0usize, 0u32)];
        reached[0] = true;
        while let Some((index, depth)) = stack.pop() {
            let node = &nodes[index];
            if depth > self.options.max_depth {
                return Err(ValidationError::TooDeep {
                    node: index,
                    depth,
                    max: self.options.max_depth,
                });
            }
            let tight = match node.children() {
                Some(children) => {
                    self.check_children(index, node, children, &mut reached, &mut stack, depth)?
                }
                None => self.check_leaf(index, node, depth, &mut slot_uses)?,
            };
            if node.bounds() != tight {
                return Err(ValidationError::LooseBox {
                    node: index,
                    found: node.bounds(),
                    tight,
                });
            }
        }
        let unreached = reached.iter().filter(|r| !**r).count();
        if unreached > 0 {
            return Err(ValidationError::UnreachableNodes { unreached });
        }
        match slot_uses.iter().position(|&n| n != 1) {
            Some(slot) => Err(ValidationError::SlotCoverage {
                slot,
                count: slot_uses[slot],
            }),
            None => Ok(()),
        }
    }

    /// Checks an inner node's child links and boxes, queues the children and
    /// returns the union of their boxes.
    fn check_children(
        &self,
        index: usize,
        node: &Node,
        [left, right]: [usize; 2],
        reached: &mut [bool],
        stack: &mut Vec<(usize, u32)>,
        depth: u32,
    ) -> Result<Aabb, ValidationError> {
        if left <= index || right >= self.nodes.len() {
            return Err(ValidationError::BadChildIndex {
                node: index,
                child: left,
            });
        }
        let mut union = Aabb::EMPTY;
        for child in [left, right] {
            if std::mem::replace(&mut reached[child], true) {
                return Err(ValidationError::SharedNode { node: child });
            }
            let child_box = self.nodes[child].bounds();
            if !node.bounds().contains(&child_box) {
                return Err(ValidationError::ChildOutsideParent {
                    node: child,
                    child: child_box,
                    parent: node.bounds(),
                });
            }
            union = union.union(child_box);
            stack.push((child, depth + 1));
        }
        Ok(union)
    }

    /// Checks a leaf's slot range and size, counts its slots and returns the
    /// bounds of its triangles.
    fn check_leaf(
        &self,
        index: usize,
        node: &Node,
        depth: u32,
        slot_uses: &mut [usize],
    ) -> Result<Aabb, ValidationError> {
        let slots = node.triangle_slots();
        if slots.end > self.triangles.len() {
            return Err(ValidationError::BadSlots {
                node: index,
                first: slots.start,
                end: slots.end,
            });
        }
        let max = self.options.max_leaf_size;
        if slots.len() > max as usize && depth < self.options.max_depth {
            return Err(ValidationError::LeafTooLarge {
                node: index,
                depth,
                count: slots.len(),
                max,
            });
        }
        let mut bounds = Aabb::EMPTY;
        for slot in slots {
            slot_uses[slot] += 1;
            bounds = bounds.union(Aabb::from_points(&self.triangles[slot]));
        }
        Ok(bounds)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::BuildOptions;
    use crate::bvh::test_meshes::{Rng, grid, option_sets, random_soup, sphere};
    use glam::Vec3;

    fn meshes() -> Vec<(&'static str, TriangleMesh)> {
        let mut rng = Rng::new(10);
        let one = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let mut duplicated = random_soup(50, 0.2, &mut rng);
        duplicated.append(&TriangleMesh::soup(&[one; 300]), 0);
        vec![
            ("empty", TriangleMesh::default()),
            ("single", TriangleMesh::soup(&[one])),
            (
                "two",
                TriangleMesh::soup(&[one, [Vec3::ONE, Vec3::Z, Vec3::Y]]),
            ),
            ("soup", random_soup(3000, 0.1, &mut rng)),
            ("big triangles", random_soup(500, 1.0, &mut rng)),
            ("grid", grid(24)),
            ("sphere", sphere(Vec3::new(3.0, -2.0, 1.0), 2.0, 20, 31)),
            ("identical", TriangleMesh::soup(&[one; 100])),
            ("duplicated", duplicated),
        ]
    }

    #[test]
    fn every_builder_gives_a_valid_tree() {
        for options in option_sets() {
            for (name, mesh) in meshes() {
                let bvh = Bvh::build(&mesh, &options);
                bvh.validate(&mesh)
                    .unwrap_or_else(|e| panic!("{name}, {options:?}: {e}"));
                let stats = bvh.stats();
                assert_eq!(stats.triangles, mesh.triangle_count(), "{name}");
                assert_eq!(stats.skipped_triangles, 0, "{name}");
                assert_eq!(
                    stats.nodes,
                    2 * stats.leaves - usize::from(stats.leaves > 0),
                    "{name}"
                );
                assert!(stats.levels <= options.clamped().max_depth + 1, "{name}");
            }
        }
    }

    #[test]
    fn unusable_triangles_are_left_out() {
        let mut rng = Rng::new(11);
        let mut mesh = random_soup(200, 0.1, &mut rng);
        mesh.positions[0].x = f32::NAN;
        mesh.positions[4].y = f32::INFINITY;
        mesh.positions[8].z = -2e18;
        mesh.positions[9].z = 1.8e18; // within Embree's limit: kept
        mesh.indices[5][2] = 10_000;
        // Two corners of one triangle the same: its normal is zero, and the
        // watertight test never hits it.
        mesh.positions[23] = mesh.positions[21];
        for options in option_sets() {
            let bvh = Bvh::build(&mesh, &options);
            bvh.validate(&mesh).unwrap();
            assert_eq!(bvh.stats().skipped_triangles, 5);
            let mut kept = bvh.prim_ids().to_vec();
            kept.sort_unstable();
            let expected: Vec<u32> = (0..200).filter(|p| ![0, 1, 2, 5, 7].contains(p)).collect();
            assert_eq!(kept, expected);
        }
        let all_nan = TriangleMesh::soup(&[[Vec3::NAN; 3]; 5]);
        let bvh = Bvh::build(&all_nan, &BuildOptions::sah());
        assert!(bvh.nodes().is_empty());
        bvh.validate(&all_nan).unwrap();
    }

    #[test]
    fn identical_triangles_still_respect_the_leaf_size() {
        let mesh = TriangleMesh::soup(&[[Vec3::ZERO, Vec3::X, Vec3::Y]; 1000]);
        for options in [BuildOptions::median(), BuildOptions::sah()] {
            let bvh = Bvh::build(&mesh, &options);
            bvh.validate(&mesh).unwrap();
            assert!(bvh.stats().max_leaf_triangles <= options.max_leaf_size);
        }
    }

    fn built() -> (TriangleMesh, Bvh) {
        let mesh = random_soup(400, 0.1, &mut Rng::new(12));
        let bvh = Bvh::build(&mesh, &BuildOptions::sah());
        bvh.validate(&mesh).unwrap();
        (mesh, bvh)
    }

    #[test]
    fn swapped_prim_ids_are_caught() {
        let (mesh, mut bvh) = built();
        bvh.prim_ids.swap(0, 1);
        assert!(matches!(
            bvh.validate(&mesh),
            Err(ValidationError::WrongCorners { .. })
        ));
    }

    #[test]
    fn a_missing_or_repeated_triangle_is_caught() {
        let (mesh, mut bvh) = built();
        bvh.prim_ids[3] = bvh.prim_ids[4];
        bvh.triangles[3] = bvh.triangles[4];
        assert!(matches!(
            bvh.validate(&mesh),
            Err(ValidationError::PrimCount { .. })
        ));
        let (mesh, mut bvh) = built();
        bvh.prim_ids[3] = 400;
        assert_eq!(
            bvh.validate(&mesh),
            Err(ValidationError::UnknownPrim { slot: 3, prim: 400 })
        );
    }

    #[test]
    fn loose_and_escaping_boxes_are_caught() {
        let (mesh, mut bvh) = built();
        let mut root = bvh.nodes[0].bounds();
        root.max.x += 0.5;
        bvh.nodes[0] = Node::inner(root, 1);
        assert!(matches!(
            bvh.validate(&mesh),
            Err(ValidationError::LooseBox { node: 0, .. })
        ));

        let (mesh, mut bvh) = built();
        let leaf = bvh.nodes.iter().position(Node::is_leaf).unwrap();
        let node = bvh.nodes[leaf];
        let mut bounds = node.bounds();
        bounds.min.y -= 10.0;
        bvh.nodes[leaf] = Node::leaf(
            bounds,
            node.triangle_slots().start as u32,
            node.triangle_slots().len() as u32,
        );
        assert!(matches!(
            bvh.validate(&mesh),
            Err(ValidationError::ChildOutsideParent { .. })
        ));
    }

    #[test]
    fn broken_links_are_caught() {
        let (mesh, mut bvh) = built();
        let inner = bvh.nodes.iter().rposition(|n| !n.is_leaf()).unwrap();
        bvh.nodes[inner] = Node::inner(bvh.nodes[inner].bounds(), 0);
        assert!(matches!(
            bvh.validate(&mesh),
            Err(ValidationError::BadChildIndex { .. })
        ));

        let (mesh, mut bvh) = built();
        bvh.nodes.push(bvh.nodes[1]);
        assert_eq!(
            bvh.validate(&mesh),
            Err(ValidationError::UnreachableNodes { unreached: 1 })
        );
    }

    #[test]
    fn option_limits_are_enforced() {
        let (mesh, mut bvh) = built();
        bvh.options.max_leaf_size = 1;
        assert!(matches!(
            bvh.validate(&mesh),
            Err(ValidationError::LeafTooLarge { .. })
        ));
        let (mesh, mut bvh) = built();
        bvh.options.max_depth = 2;
        assert!(matches!(
            bvh.validate(&mesh),
            Err(ValidationError::TooDeep { depth: 3, .. })
        ));
    }
}
