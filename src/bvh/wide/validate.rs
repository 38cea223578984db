//! The invariants of a [`WideBvh`], checked after every build in the tests:
//! every usable mesh triangle stored exactly once with its own corners, the
//! nodes one tree laid out depth first, every child box exactly the tight
//! box of its contents, unused slots empty and every node's octant orders
//! permutations of its slots that list the used slots nearest last.

use super::WideBvh;
use super::node::{BLOCK_WIDTH, Child, EdgeNorms, TriangleBlock, WIDTH};
use crate::bvh::build::usable_corners;
use crate::geometry::{Aabb, TriangleMesh};
use glam::Vec3;
use thiserror::Error;

#[derive(Clone, Debug, PartialEq, Error)]
pub enum WideValidationError {
    #[error("mesh triangle {prim} is stored {count} times; expected {expected}")]
    TriangleCount {
        prim: usize,
        count: usize,
        expected: usize,
    },
    #[error("block {block} lane {lane} does not hold the corners of mesh triangle {prim}")]
    WrongCorners {
        block: usize,
        lane: usize,
        prim: u32,
    },
    #[error("block {block}'s edge norms are not its triangles'")]
    WrongNorms { block: usize },
    #[error("block {block} has a padding lane before a stored triangle, or holds nothing")]
    BadPadding { block: usize },
    #[error("node {node} slot {slot} points at {child}, outside the array or not after it")]
    BadChild {
        node: usize,
        slot: usize,
        child: usize,
    },
    #[error("node or block {index} is reached {count} times; expected once")]
    Coverage { index: usize, count: usize },
    #[error("node {node} slot {slot} has box {found:?}, not the tight box {tight:?}")]
    LooseBox {
        node: usize,
        slot: usize,
        found: Aabb,
        tight: Aabb,
    },
    #[error("node {node} has no child, or a used slot after an unused one")]
    BadSlots { node: usize },
    #[error("node {node} is at depth {depth}, beyond the limit")]
    TooDeep { node: usize, depth: u32 },
    #[error(
        "node {node}'s order for octant {octant} is {order:?}, not a permutation ending with its used slots"
    )]
    BadOrder {
        node: usize,
        octant: u32,
        order: [usize; WIDTH],
    },
    #[error("the tree claims {claimed} triangles but stores {stored}")]
    TriangleTotal { claimed: usize, stored: usize },
}

impl WideBvh {
    /// Checks every invariant of the tree against the mesh it was built on.
    pub fn validate(&self, mesh: &TriangleMesh) -> Result<(), WideValidationError> {
        self.validate_blocks(mesh)?;
        if self.nodes.is_empty() {
            return Ok(());
        }
        let mut node_visits = vec![0usize; self.nodes.len()];
        let mut block_visits = vec![0usize; self.blocks.len()];
        self.validate_node(0, 0, &mut node_visits, &mut block_visits)?;
        for visits in [&node_visits, &block_visits] {
            if let Some((index, &count)) = visits.iter().enumerate().find(|(_, c)| **c != 1) {
                return Err(WideValidationError::Coverage { index, count });
            }
        }
        Ok(())
    }

    fn validate_blocks(&self, mesh: &TriangleMesh) -> Result<(), WideValidationError> {
        let mut stored = vec![0usize; mesh.indices.len()];
        let mut total = 0;
        for (index, block) in self.blocks.iter().enumerate() {
            let used = (0..BLOCK_WIDTH)
                .take_while(|&l| block.prim(l).is_some())
                .count();
            if used == 0 || (used..BLOCK_WIDTH).any(|l| block.prim(l).is_some()) {
                return Err(WideValidationError::BadPadding { block: index });
            }
            let norms_bits =
                |norms: &EdgeNorms| [norms.sum, norms.product].map(|n| n.map(f32::to_bits));
            if self.edge_norms.get(index).map(norms_bits) != Some(norms_bits(&EdgeNorms::of(block)))
            {
                return Err(WideValidationError::WrongNorms { block: index });
            }
            for lane in 0..used {
                let prim = block.prims[lane];
                let corners = usable_corners(mesh, prim as usize);
                let same = corners.is_some_and(|c| same_bits(c, block.triangle(lane)));
                if !same {
                    return Err(WideValidationError::WrongCorners {
                        block: index,
                        lane,
                        prim,
                    });
                }
                stored[prim as usize] += 1;
                total += 1;
            }
        }
        for (prim, &count) in stored.iter().enumerate() {
            let expected = usize::from(usable_corners(mesh, prim).is_some());
            if count != expected {
                return Err(WideValidationError::TriangleCount {
                    prim,
                    count,
                    expected,
                });
            }
        }
        if self.edge_norms.len() != self.blocks.len() {
            return Err(WideValidationError::WrongNorms {
                block: self.blocks.len(),
            });
        }
        if total != self.triangles {
            return Err(WideValidationError::TriangleTotal {
                claimed: self.triangles,
                stored: total,
            });
        }
        Ok(())
    }

    /// Checks the subtree at `index` (at `depth`); returns the tight box of
    /// its triangles.
    fn validate_node(
        &self,
        index: usize,
        depth: u32,
        node_visits: &mut [usize],
        block_visits: &mut [usize],
    ) -> Result<Aabb, WideValidationError> {
        node_visits[index] += 1;
        if depth >= crate::bvh::MAX_DEPTH {
            return Err(WideValidationError::TooDeep { node: index, depth });
        }
        let node = &self.nodes[index];
        let used = (0..WIDTH)
            .take_while(|&s| node.child(s) != Child::Empty)
            .count();
        if used == 0 || (used..WIDTH).any(|s| node.child(s) != Child::Empty) {
            return Err(WideValidationError::BadSlots { node: index });
        }
        for octant in 0..8 {
            let order = node.slots_far_to_near(octant);
            let mut sorted = order;
            sorted.sort_unstable();
            let unused_first = order[..WIDTH - used].iter().all(|&s| s >= used);
            if sorted != std::array::from_fn(|s| s) || !unused_first {
                return Err(WideValidationError::BadOrder {
                    node: index,
                    octant,
                    order,
                });
            }
        }
        let mut bounds = Aabb::EMPTY;
        for slot in 0..WIDTH {
            let tight = match node.child(slot) {
                Child::Empty => Aabb::EMPTY,
                Child::Inner(child) => {
                    if child <= index || child >= self.nodes.len() {
                        return Err(WideValidationError::BadChild {
                            node: index,
                            slot,
                            child,
                        });
                    }
                    self.validate_node(child, depth + 1, node_visits, block_visits)?
                }
                Child::Leaf(block) => {
                    if block >= self.blocks.len() {
                        return Err(WideValidationError::BadChild {
                            node: index,
                            slot,
                            child: block,
                        });
                    }
                    block_visits[block] += 1;
                    block_bounds(&self.blocks[block])
                }
            };
            let found = node.child_bounds(slot);
            if box_bits(found) != box_bits(tight) {
                return Err(WideValidationError::LooseBox {
                    node: index,
                    slot,
                    found,
                    tight,
                });
            }
            bounds = bounds.union(tight);
        }
        Ok(bounds)
    }
}

fn block_bounds(block: &TriangleBlock) -> Aabb {
    (0..BLOCK_WIDTH)
        .filter(|&lane| block.prim(lane).is_some())
        .fold(Aabb::EMPTY, |b, lane| {
            b.union(Aabb::from_points(&block.triangle(lane)))
        })
}

fn same_bits(a: [Vec3; 3], b: [Vec3; 3]) -> bool {
    a.map(point_bits) == b.map(point_bits)
}

fn box_bits(b: Aabb) -> [[u32; 3]; 2] {
    [point_bits(b.min), point_bits(b.max)]
}

fn point_bits(p: Vec3) -> [u32; 3] {
    p.to_array().map(f32::to_bits)
}
