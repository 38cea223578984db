//! The 32-byte BVH node of the flat node array.

use crate::geometry::Aabb;
use glam::Vec3;
use std::ops::Range;

/// A box plus either two children (adjacent in the node array) or a run of
/// triangle slots.
///
/// `count == 0` marks an inner node whose children are `first` and
/// `first + 1`; otherwise the node is a leaf holding slots
/// `first .. first + count`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub struct Node {
    min: Vec3,
    first: u32,
    max: Vec3,
    count: u32,
}

const _: () = assert!(std::mem::size_of::<Node>() == 32);

impl Node {
    pub(super) fn leaf(bounds: Aabb, first: u32, count: u32) -> Self {
        Self {
            min: bounds.min,
            first,
            max: bounds.max,
            count,
        }
    }

    pub(super) fn inner(bounds: Aabb, first_child: u32) -> Self {
        Self::leaf(bounds, first_child, 0)
    }

    pub fn bounds(&self) -> Aabb {
        Aabb {
            min: self.min,
            max: self.max,
        }
    }

    pub fn is_leaf(&self) -> bool {
        self.count > 0
    }

    /// The indices of the two children of an inner node.
    pub fn children(&self) -> Option<[usize; 2]> {
        let first = self.first as usize;
        (!self.is_leaf()).then_some([first, first + 1])
    }

    /// The triangle slots of a leaf (empty for an inner node).
    pub fn triangle_slots(&self) -> Range<usize> {
        if self.is_leaf() {
            let first = self.first as usize;
            first..first + self.count as usize
        } else {
            0..0
        }
    }
}
