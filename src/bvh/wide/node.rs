//! The 8-wide node and the 8-triangle leaf block, both laid out as
//! structures of arrays so that one SIMD instruction works on all eight
//! children or all eight triangles (Wald, Benthin, Boulos, "Getting Rid of
//! Packets", IEEE RT 2008).
//!
//! Each node also stores, for each of the eight ray octants, an order of
//! its children from far to near along that octant's diagonal, so the
//! traversal visits children roughly nearest first without sorting their
//! entry distances (the precomputed orders of Garanzha and Loop's and
//! Ylitie, Karras and Laine's wide BVHs, "Efficient Incoherent Ray
//! Traversal on GPUs Through Compressed Wide BVHs", HPG 2017).

use crate::geometry::Aabb;
use glam::Vec3;

/// Children per node.
pub const WIDTH: usize = 8;

/// Triangles per leaf block; every leaf is one block.
pub const BLOCK_WIDTH: usize = 8;

/// A child reference with this bit set names a leaf, the block in its
/// other bits.
pub(super) const LEAF_BIT: u32 = 1 << 31;

/// Marks an unused child slot.
pub(super) const NO_CHILD: u32 = u32::MAX;

/// The most nodes, and the most triangle blocks, a tree can index.
pub const MAX_INDEX: usize = (LEAF_BIT - 1) as usize;

/// Up to eight children, each an inner node or a leaf block, with their
/// boxes stored plane by plane and their visiting orders.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub struct WideNode {
    /// The children's boxes: `planes[axis][0]` the lower and
    /// `planes[axis][1]` the upper bounds along `axis`, one lane per child.
    /// An unused slot holds the empty box, which no ray enters.
    pub(super) planes: [[[f32; WIDTH]; 2]; 3],
    /// Per child: the node index (inner child), [`LEAF_BIT`] | the block
    /// index (leaf), or [`NO_CHILD`].
    pub(super) child: [u32; WIDTH],
    /// Bits `3o .. 3o + 3` of entry `j`: the slot at position `j` of the
    /// order for rays of octant `o` (bit 0 set for a negative x direction,
    /// bit 1 for y, bit 2 for z); position 7 is the nearest.
    pub(super) order: [u32; WIDTH],
}

const _: () = assert!(std::mem::size_of::<WideNode>() == 256);

/// The planes of eight empty boxes (min above max on every axis).
const EMPTY_PLANES: [[[f32; WIDTH]; 2]; 3] =
    [[[f32::INFINITY; WIDTH], [f32::NEG_INFINITY; WIDTH]]; 3];

/// What one child slot of a [`WideNode`] holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Child {
    Empty,
    Inner(usize),
    /// A leaf: this triangle block.
    Leaf(usize),
}

impl Child {
    /// The child reference a node stores for `self`; node and block
    /// indices below [`MAX_INDEX`].
    pub(super) fn encode(&self) -> u32 {
        match *self {
            Child::Empty => NO_CHILD,
            Child::Inner(node) => {
                assert!(node < MAX_INDEX, "node index {node}");
                node as u32
            }
            Child::Leaf(block) => {
                assert!(block < MAX_INDEX, "block index {block}");
                LEAF_BIT | block as u32
            }
        }
    }

    pub(super) fn decode(reference: u32) -> Child {
        match reference {
            NO_CHILD => Child::Empty,
            r if r & LEAF_BIT != 0 => Child::Leaf((r & !LEAF_BIT) as usize),
            r => Child::Inner(r as usize),
        }
    }
}

impl WideNode {
    /// The node with the given children (at most [`WIDTH`], in slot order)
    /// and their boxes; the remaining slots are empty.
    pub(super) fn new(children: &[(Aabb, Child)]) -> WideNode {
        assert!(children.len() <= WIDTH, "{} children", children.len());
        let mut node = WideNode {
            planes: EMPTY_PLANES,
            child: [NO_CHILD; WIDTH],
            order: [0; WIDTH],
        };
        for (slot, (bounds, child)) in children.iter().enumerate() {
            for axis in 0..3 {
                node.planes[axis][0][slot] = bounds.min[axis];
                node.planes[axis][1][slot] = bounds.max[axis];
            }
            node.child[slot] = child.encode();
        }
        for octant in 0..4 {
            // The opposite octant's diagonal is the negated one: its order
            // is this one reversed (the unused slots staying first).
            let order = far_to_near(children, octant);
            let (unused, used) = order.split_at(WIDTH - children.len());
            let opposite = unused.iter().chain(used.iter().rev());
            for (position, (&slot, &reverse)) in order.iter().zip(opposite).enumerate() {
                node.order[position] |=
                    (slot as u32) << (3 * octant) | (reverse as u32) << (3 * (7 - octant));
            }
        }
        node
    }

    pub fn child(&self, slot: usize) -> Child {
        Child::decode(self.child[slot])
    }

    pub fn child_bounds(&self, slot: usize) -> Aabb {
        let side = |s: usize| Vec3::from_array([0, 1, 2].map(|axis| self.planes[axis][s][slot]));
        Aabb {
            min: side(0),
            max: side(1),
        }
    }

    /// The box around every child's box (empty for a node of no child).
    pub fn bounds(&self) -> Aabb {
        (0..WIDTH)
            .filter(|&slot| self.child(slot) != Child::Empty)
            .fold(Aabb::EMPTY, |bounds, slot| {
                bounds.union(self.child_bounds(slot))
            })
    }

    /// The slots in visiting order for rays of `octant`, nearest last.
    pub(super) fn slots_far_to_near(&self, octant: u32) -> [usize; WIDTH] {
        self.order
            .map(|entry| ((entry >> (3 * octant)) & (WIDTH as u32 - 1)) as usize)
    }
}

/// The slots `0 .. WIDTH` ordered from far to near for rays of `octant`:
/// unused slots first, then by the projection of each child's box centre
/// on the octant's diagonal, largest first; ties by slot.
fn far_to_near(children: &[(Aabb, Child)], octant: usize) -> [usize; WIDTH] {
    let diagonal = Vec3::new(
        if octant & 1 != 0 { -1.0 } else { 1.0 },
        if octant & 2 != 0 { -1.0 } else { 1.0 },
        if octant & 4 != 0 { -1.0 } else { 1.0 },
    );
    let unused = WIDTH - children.len();
    let mut order: [usize; WIDTH] = std::array::from_fn(|i| (children.len() + i) % WIDTH);
    let mut keys = [0.0f32; WIDTH];
    // Insertion sort of the used slots, which come in slot order.
    for (slot, (bounds, _)) in children.iter().enumerate() {
        let key = diagonal.dot(0.5 * bounds.min + 0.5 * bounds.max);
        let mut i = unused + slot;
        while i > unused && keys[i - 1] < key {
            order[i] = order[i - 1];
            keys[i] = keys[i - 1];
            i -= 1;
        }
        order[i] = slot;
        keys[i] = key;
    }
    order
}

/// Up to eight triangles, corner by corner and axis by axis; unused lanes
/// have NaN corners and the prim id [`TriangleBlock::PADDING`]. Aligned to
/// a cache line, so its 320 bytes are five whole lines, the five the
/// traversal prefetches (aligned to 32 bytes, a vector starting mid-line
/// would have every block span six).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub struct TriangleBlock {
    /// `corners[corner][axis][lane]`.
    pub(super) corners: [[[f32; BLOCK_WIDTH]; 3]; 3],
    /// The mesh triangle index of each lane.
    pub(super) prims: [u32; BLOCK_WIDTH],
}

const _: () = assert!(std::mem::size_of::<TriangleBlock>() == 320);

impl TriangleBlock {
    pub const PADDING: u32 = u32::MAX;

    /// A block of up to [`BLOCK_WIDTH`] `(prim, corners)` pairs.
    pub(super) fn new(triangles: impl IntoIterator<Item = (u32, [Vec3; 3])>) -> Self {
        let mut block = TriangleBlock {
            corners: [[[f32::NAN; BLOCK_WIDTH]; 3]; 3],
            prims: [Self::PADDING; BLOCK_WIDTH],
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

    /// The lanes holding a triangle, one bit per lane.
    pub(super) fn stored_lanes(&self) -> u32 {
        (0..BLOCK_WIDTH)
            .filter(|&lane| self.prims[lane] != Self::PADDING)
            .fold(0, |mask, lane| mask | 1 << lane)
    }

    /// The corners of the triangle in `lane`.
    #[inline(always)]
    pub fn triangle(&self, lane: usize) -> [Vec3; 3] {
        // One check instead of nine (and no `array::map`, which the
        // compiler leaves as a call).
        assert!(lane < BLOCK_WIDTH, "lane {lane}");
        let c = &self.corners;
        let corner = |k: usize| Vec3::new(c[k][0][lane], c[k][1][lane], c[k][2][lane]);
        [corner(0), corner(1), corner(2)]
    }
}

/// `2^-32`, added to every L1 norm in the any-hit filter's error bounds
/// (`candidates.rs` says why).
pub(super) const NORM_PAD: f32 = 1.0 / (1u64 << 32) as f32;

/// Per lane of one block, `b1 + b2` and `b1·b2` of the padded L1 norms
/// `b1`, `b2` of its edges `p0 - p1` and `p2 - p0`: the any-hit filter's
/// error bounds (`candidates.rs`), made once with the block instead of at
/// every visit. Kept in an array beside the blocks, one cache line each,
/// which only filtered rays read: inside the blocks, a sixth line cost
/// closest-hit rays on the largest trees. Made at each visit instead,
/// from the edges the filter loads anyway, they cost dragon-14m's shadow
/// and diffuse rays 5-6% on the EPYC host (32 MiB L3), though on the Xeon
/// host they had saved 2% of its shadow rays (AVX-512).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(super) struct EdgeNorms {
    pub(super) sum: [f32; BLOCK_WIDTH],
    pub(super) product: [f32; BLOCK_WIDTH],
}

const _: () = assert!(std::mem::size_of::<EdgeNorms>() == 64);

impl EdgeNorms {
    /// The norms of `block`'s stored lanes; NaN in its padding.
    pub(super) fn of(block: &TriangleBlock) -> Self {
        let mut norms = EdgeNorms {
            sum: [f32::NAN; BLOCK_WIDTH],
            product: [f32::NAN; BLOCK_WIDTH],
        };
        for lane in (0..BLOCK_WIDTH).filter(|&lane| block.prim(lane).is_some()) {
            [norms.sum[lane], norms.product[lane]] = Self::of_triangle(block.triangle(lane));
        }
        norms
    }

    /// `[b1 + b2, b1·b2]` for the triangle `corners`: in f64, where sums of
    /// f32 values are nearly exact, then rounded to f32 and moved one step
    /// up, so each is at least its exact value.
    fn of_triangle(corners: [Vec3; 3]) -> [f32; 2] {
        let [p0, p1, p2] = corners.map(|p| p.as_dvec3());
        let pad = f64::from(NORM_PAD);
        let b1 = (p0 - p1).abs().element_sum() + pad;
        let b2 = (p2 - p0).abs().element_sum() + pad;
        [b1 + b2, b1 * b2].map(|norm| (norm as f32).next_up())
    }
}
