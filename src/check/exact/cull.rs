//! A bounding-volume tree over the oracle's padded triangle boxes, so an
//! exact query tests only the triangles whose boxes the ray may touch
//! (Kay & Kajiya 1986 slabs, median splits as in pbrt-v4 section 7.3).
//!
//! Independent of the tracer under judgement: f64 boxes, each the union of
//! its triangles' padded boxes, and the same conservative slab test for
//! nodes and triangles, so no triangle the ray touches is ever skipped.

use crate::geometry::Ray;

/// A box as `[lo, hi]`.
pub type Bounds = [[f64; 3]; 2];

/// Relative padding of the culling boxes and intervals: far above the
/// f64 rounding of the slab test, far below any f32 distance.
pub const CULL_PADDING: f64 = 1e-9;

/// Triangles per leaf.
const LEAF_SIZE: usize = 8;

struct Node {
    bounds: Bounds,
    /// A leaf's range in `order`, or an inner node's two children.
    kind: Kind,
}

enum Kind {
    Leaf(usize, usize),
    Inner(usize, usize),
}

pub struct CullTree {
    nodes: Vec<Node>,
    order: Vec<u32>,
    boxes: Vec<Bounds>,
}

impl CullTree {
    /// The tree over `boxes` (indexed by prim); boxes with a NaN bound
    /// (triangles that are never hit) are left out.
    pub fn new(boxes: Vec<Bounds>) -> Self {
        let mut order: Vec<u32> = (0..boxes.len() as u32)
            .filter(|&p| !boxes[p as usize].iter().flatten().any(|x| x.is_nan()))
            .collect();
        let mut nodes = Vec::new();
        let len = order.len();
        if len > 0 {
            build(&boxes, &mut order, 0, len, &mut nodes);
        }
        Self {
            nodes,
            order,
            boxes,
        }
    }

    /// Whether `ray` may touch the padded box of `prim`.
    pub fn may_hit(&self, ray: &Ray, prim: u32) -> bool {
        self.boxes
            .get(prim as usize)
            .is_some_and(|b| may_hit(ray, b))
    }

    /// The prims whose boxes `ray` may touch within `[tnear, tfar]`, in
    /// increasing order.
    pub fn candidates(&self, ray: &Ray) -> Vec<u32> {
        let mut out = Vec::new();
        let mut stack = vec![0];
        while let Some(index) = stack.pop() {
            let Some(node) = self.nodes.get(index) else {
                break;
            };
            if !may_hit(ray, &node.bounds) {
                continue;
            }
            match node.kind {
                Kind::Inner(left, right) => stack.extend([left, right]),
                Kind::Leaf(start, end) => out.extend(
                    self.order[start..end]
                        .iter()
                        .filter(|&&p| self.may_hit(ray, p)),
                ),
            }
        }
        out.sort_unstable();
        out
    }
}

fn union(boxes: &[Bounds], prims: &[u32]) -> Bounds {
    let mut out = [[f64::INFINITY; 3], [f64::NEG_INFINITY; 3]];
    for &p in prims {
        let [lo, hi] = boxes[p as usize];
        for k in 0..3 {
            out[0][k] = out[0][k].min(lo[k]);
            out[1][k] = out[1][k].max(hi[k]);
        }
    }
    out
}

/// Builds the subtree over `order[start..end]` and returns its index.
fn build(
    boxes: &[Bounds],
    order: &mut [u32],
    start: usize,
    end: usize,
    nodes: &mut Vec<Node>,
) -> usize {
    let bounds = union(boxes, &order[start..end]);
    let index = nodes.len();
    nodes.push(Node {
        bounds,
        kind: Kind::Leaf(start, end),
    });
    if end - start > LEAF_SIZE {
        let centre = |p: &u32, k: usize| boxes[*p as usize][0][k] + boxes[*p as usize][1][k];
        let extent = |k: usize| bounds[1][k] - bounds[0][k];
        let axis = (0..3).fold(0, |best, k| if extent(k) > extent(best) { k } else { best });
        let middle = (start + end) / 2;
        order[start..end].select_nth_unstable_by(middle - start, |a, b| {
            centre(a, axis).total_cmp(&centre(b, axis)).then(a.cmp(b))
        });
        let left = build(boxes, order, start, middle, nodes);
        let right = build(boxes, order, middle, end, nodes);
        nodes[index].kind = Kind::Inner(left, right);
    }
    index
}

/// A conservative slab test against a padded box: false only when the ray
/// certainly misses it.
fn may_hit(ray: &Ray, [lo, hi]: &Bounds) -> bool {
    let o = ray.origin.as_dvec3().to_array();
    let d = ray.dir.as_dvec3().to_array();
    let (mut t0, mut t1) = (f64::from(ray.tnear), f64::from(ray.tfar));
    for k in 0..3 {
        if d[k] == 0.0 {
            if o[k] < lo[k] || o[k] > hi[k] {
                return false;
            }
            continue;
        }
        let (a, b) = ((lo[k] - o[k]) / d[k], (hi[k] - o[k]) / d[k]);
        t0 = t0.max(a.min(b));
        t1 = t1.min(a.max(b));
    }
    // NaN comparisons fall through to "may hit": the exact test decides.
    let (low, high) = (t0 - CULL_PADDING * t0.abs(), t1 + CULL_PADDING * t1.abs());
    low.partial_cmp(&high) != Some(std::cmp::Ordering::Greater)
}
