//! The 4-wide node and the 4-triangle leaf block, both laid out as
//! structures of arrays so that one SIMD instruction works on all four
//! children or all four triangles (Wald, Benthin, Boulos, "Getting Rid of
//! Packets", IEEE RT 2008).

use crate::geometry::Aabb;
use glam::Vec3;
use std::ops::Range;

/// Children per node and triangles per leaf block.
pub const WIDTH: usize = 4;

/// Marks an unused child slot.
const NO_CHILD: u32 = u32::MAX;

/// Up to four children, each an inner node or a leaf (a run of triangle
/// blocks), with their boxes stored plane by plane.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub struct WideNode {
    /// The children's boxes: `[min_x, max_x, min_y, max_y, min_z, max_z]`,
    /// one lane per child. An unused slot holds the empty box, which no ray
    /// enters.
    pub(super) planes: [[f32; WIDTH]; 6],
    /// Per child: the node index (inner child), the first block (leaf) or
    /// [`NO_CHILD`].
    child: [u32; WIDTH],
    /// Per child: the number of blocks of a leaf, 0 for an inner child.
    blocks: [u32; WIDTH],
}

const _: () = assert!(std::mem::size_of::<WideNode>() == 128);

/// What one child slot of a [`WideNode`] holds.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Child {
    Empty,
    Inner(usize),
    /// Leaf blocks `range`.
    Leaf(Range<usize>),
}

impl WideNode {
    pub(super) const EMPTY: WideNode = WideNode {
        planes: [
            [f32::INFINITY; WIDTH],
            [f32::NEG_INFINITY; WIDTH],
            [f32::INFINITY; WIDTH],
            [f32::NEG_INFINITY; WIDTH],
            [f32::INFINITY; WIDTH],
            [f32::NEG_INFINITY; WIDTH],
        ],
        child: [NO_CHILD; WIDTH],
        blocks: [0; WIDTH],
    };

    pub(super) fn set_inner(&mut self, slot: usize, bounds: Aabb, node: usize) {
        self.set(slot, bounds, node as u32, 0);
    }

    pub(super) fn set_leaf(&mut self, slot: usize, bounds: Aabb, blocks: Range<usize>) {
        self.set(slot, bounds, blocks.start as u32, blocks.len() as u32);
    }

    fn set(&mut self, slot: usize, bounds: Aabb, child: u32, blocks: u32) {
        for axis in 0..3 {
            self.planes[2 * axis][slot] = bounds.min[axis];
            self.planes[2 * axis + 1][slot] = bounds.max[axis];
        }
        self.child[slot] = child;
        self.blocks[slot] = blocks;
    }

    /// The raw `(child, blocks)` of `slot`, as [`WideNode::child`] decodes
    /// them: for a slot the traversal entered, the node index and 0, or the
    /// first block and the block count.
    #[inline(always)]
    pub(super) fn slot(&self, slot: usize) -> (u32, u32) {
        (self.child[slot], self.blocks[slot])
    }

    pub fn child(&self, slot: usize) -> Child {
        match self.slot(slot) {
            (NO_CHILD, _) => Child::Empty,
            (node, 0) => Child::Inner(node as usize),
            (first, count) => Child::Leaf(first as usize..(first + count) as usize),
        }
    }

    pub fn child_bounds(&self, slot: usize) -> Aabb {
        let plane = |p: usize| self.planes[p][slot];
        Aabb {
            min: Vec3::new(plane(0), plane(2), plane(4)),
            max: Vec3::new(plane(1), plane(3), plane(5)),
        }
    }
}

/// Up to four triangles, corner by corner and axis by axis; unused lanes
/// have NaN corners and the prim id [`TriangleBlock::PADDING`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub struct TriangleBlock {
    /// `corners[corner][axis][lane]`.
    pub(super) corners: [[[f32; WIDTH]; 3]; 3],
    /// The mesh triangle index of each lane.
    pub(super) prims: [u32; WIDTH],
}

const _: () = assert!(std::mem::size_of::<TriangleBlock>() == 160);

impl TriangleBlock {
    pub const PADDING: u32 = u32::MAX;

    /// A block of up to [`WIDTH`] `(prim, corners)` pairs.
    pub(super) fn new(triangles: impl IntoIterator<Item = (u32, [Vec3; 3])>) -> Self {
        let mut block = TriangleBlock {
            corners: [[[f32::NAN; WIDTH]; 3]; 3],
            prims: [Self::PADDING; WIDTH],
        };
        for (lane, (prim, corners)) in triangles.into_iter().enumerate() {
            block.prims[lane] = prim;
            for (corner, p) in corners.iter().enumerate() {
                for axis in 0..3 {
                    block.corners[corner][axis][lane] = p[axis];
                }
            }
        }
        block
    }

    /// The mesh triangle in `lane`, or `None` for padding.
    pub fn prim(&self, lane: usize) -> Option<u32> {
        (self.prims[lane] != Self::PADDING).then_some(self.prims[lane])
    }

    /// The corners of the triangle in `lane`.
    pub fn triangle(&self, lane: usize) -> [Vec3; 3] {
        let c = &self.corners;
        [0, 1, 2].map(|k| Vec3::new(c[k][0][lane], c[k][1][lane], c[k][2][lane]))
    }
}
