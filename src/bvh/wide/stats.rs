//! The shape of a [`WideBvh`] for the report's table: levels, node and leaf
//! counts and the largest leaf, as [`crate::bvh::BvhStats`] gives them for
//! the binary trees.

use super::WideBvh;
use super::node::{Child, WIDTH};
use serde::Serialize;

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct WideStats {
    /// Depth of the deepest leaf plus one, the root node at depth 0 (0 for
    /// an empty tree).
    pub levels: u32,
    pub nodes: usize,
    pub leaves: usize,
    pub max_leaf_triangles: u32,
}

impl WideBvh {
    /// Levels, nodes, leaves and the largest leaf. Nodes are stored parent
    /// before child, so one pass in order knows every node's depth.
    pub fn stats(&self) -> WideStats {
        let mut depth = vec![0u32; self.nodes.len()];
        let mut stats = WideStats {
            nodes: self.nodes.len(),
            ..WideStats::default()
        };
        for (index, node) in self.nodes.iter().enumerate() {
            for slot in 0..WIDTH {
                match node.child(slot) {
                    Child::Empty => {}
                    Child::Inner(child) => depth[child] = depth[index] + 1,
                    Child::Leaf(block) => {
                        let triangles = self.blocks[block].stored_lanes().count_ones();
                        stats.leaves += 1;
                        stats.levels = stats.levels.max(depth[index] + 2);
                        stats.max_leaf_triangles = stats.max_leaf_triangles.max(triangles);
                    }
                }
            }
        }
        stats
    }
}
