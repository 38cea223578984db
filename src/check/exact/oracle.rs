//! The exact answers to a ray's queries against a whole mesh, and the
//! inputs one ulp away: the rays, and the mesh with one vertex coordinate
//! moved.

use super::contact::{Contact, Corners, compare_hits, contact, exact_hit};
use super::cull::{CULL_PADDING, CullTree};
use super::perturbed::ulp_step;
use crate::geometry::{Ray, TriangleMesh};
use std::cmp::Ordering;
use std::sync::Arc;

/// One mesh vertex at another position; every triangle that shares the
/// vertex moves with it, so a closed mesh stays closed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MovedVertex {
    pub index: u32,
    pub position: [f32; 3],
}

/// Exact queries against one mesh, optionally with one vertex moved.
/// Triangles with an index out of range are never hit; the others are
/// decided by [`exact_hit`].
pub struct Oracle<'a> {
    mesh: &'a TriangleMesh,
    /// Each triangle's bounds, padded so that the f64 slab test never
    /// rejects a triangle the ray touches, even with a corner moved by one
    /// f32 ulp, in a culling tree.
    tree: Arc<CullTree>,
    moved: Option<MovedVertex>,
}

impl<'a> Oracle<'a> {
    pub fn new(mesh: &'a TriangleMesh) -> Self {
        let boxes = mesh
            .indices
            .iter()
            .map(|idx| {
                let corners = idx.map(|i| {
                    mesh.positions
                        .get(i as usize)
                        .map_or([f64::NAN; 3], |p| p.as_dvec3().to_array())
                });
                let lo: [f64; 3] = std::array::from_fn(|k| {
                    corners.iter().map(|c| c[k]).fold(f64::INFINITY, f64::min)
                });
                let hi: [f64; 3] = std::array::from_fn(|k| {
                    corners
                        .iter()
                        .map(|c| c[k])
                        .fold(f64::NEG_INFINITY, f64::max)
                });
                let pad: [f64; 3] = std::array::from_fn(|k| {
                    (CULL_PADDING + f64::from(f32::EPSILON)) * (lo[k].abs().max(hi[k].abs()))
                        + f64::from(f32::MIN_POSITIVE)
                });
                [
                    std::array::from_fn(|k| lo[k] - pad[k]),
                    std::array::from_fn(|k| hi[k] + pad[k]),
                ]
            })
            .collect::<Vec<_>>();
        Self {
            mesh,
            tree: Arc::new(CullTree::new(boxes)),
            moved: None,
        }
    }

    /// The same mesh with one vertex moved by at most one f32 ulp per
    /// coordinate (the culling boxes are padded for that much).
    pub fn with_vertex_moved(&self, moved: MovedVertex) -> Self {
        Self {
            mesh: self.mesh,
            tree: Arc::clone(&self.tree),
            moved: Some(moved),
        }
    }

    pub fn triangle_count(&self) -> usize {
        self.mesh.triangle_count()
    }

    pub fn mesh(&self) -> &'a TriangleMesh {
        self.mesh
    }

    /// The corners of triangle `prim` (with the moved vertex where it is
    /// one), or `None` for an index out of range.
    pub fn corners(&self, prim: usize) -> Option<Corners> {
        let [a, b, c] = self.mesh.indices.get(prim)?;
        let corner = |i: &u32| match self.moved {
            Some(moved) if moved.index == *i => Some(moved.position),
            _ => self.mesh.positions.get(*i as usize).map(|p| p.to_array()),
        };
        Some([corner(a)?, corner(b)?, corner(c)?])
    }

    /// The triangles whose padded boxes `ray` may touch, in prim order.
    pub fn candidates(&self, ray: &Ray) -> Vec<u32> {
        self.tree.candidates(ray)
    }

    /// The exact `t` at which `ray` hits triangle `prim`, if it does.
    pub fn hit(&self, ray: &Ray, prim: u32) -> Option<f64> {
        if !self.tree.may_hit(ray, prim) {
            return None;
        }
        exact_hit(ray, &self.corners(prim as usize)?)
    }

    /// The contact of `ray` with triangle `prim` ([`contact`]); a triangle
    /// whose padded box the ray misses is an unsteady miss (a ray one ulp
    /// away may meet the box), one with an index out of range a steady one.
    pub fn contact(&self, ray: &Ray, prim: u32) -> Contact {
        if !self.tree.may_hit(ray, prim) {
            return Contact {
                t: None,
                steady: false,
            };
        }
        match self.corners(prim as usize) {
            Some(corners) => contact(ray, &corners),
            None => Contact {
                t: None,
                steady: true,
            },
        }
    }

    /// Whether `ray` hits any triangle (the exact any-hit answer).
    pub fn any_hit(&self, ray: &Ray) -> bool {
        self.tree
            .candidates(ray)
            .into_iter()
            .any(|prim| self.hit(ray, prim).is_some())
    }

    /// Whether some triangle is hit strictly nearer than `prim`, which
    /// `ray` is known to hit.
    pub fn nearer_hit_exists(&self, ray: &Ray, prim: u32) -> bool {
        let Some(target) = self.corners(prim as usize) else {
            return false;
        };
        self.tree
            .candidates(ray)
            .into_iter()
            .filter(|&other| other != prim)
            .any(|other| {
                self.hit(ray, other).is_some()
                    && self.corners(other as usize).is_some_and(|corners| {
                        compare_hits(ray, &corners, &target) == Ordering::Less
                    })
            })
    }

    /// The exact closest-hit answer: every triangle hit at the smallest
    /// `t` (more than one on an exact tie), in prim order, with that `t`.
    pub fn nearest(&self, ray: &Ray) -> Option<(f64, Vec<u32>)> {
        let hits: Vec<(u32, f64)> = self
            .tree
            .candidates(ray)
            .into_iter()
            .filter_map(|prim| Some((prim, self.hit(ray, prim)?)))
            .collect();
        let corners = |prim: u32| self.corners(prim as usize).expect("a hit triangle exists");
        let mut best: Option<(f64, Vec<u32>)> = None;
        for (prim, t) in hits {
            let order = best.as_ref().map_or(Ordering::Less, |(_, tied)| {
                compare_hits(ray, &corners(prim), &corners(tied[0]))
            });
            match (order, &mut best) {
                (Ordering::Less, _) => best = Some((t, vec![prim])),
                (Ordering::Equal, Some((_, tied))) => tied.push(prim),
                _ => {}
            }
        }
        best
    }
}

/// The rays that differ from `ray` in one input (an origin or direction
/// component, `tnear` or `tfar`) by one f32 ulp, either way ([`ulp_step`]:
/// subnormals skipped, as the backends flush them to zero).
pub fn one_ulp_neighbours(ray: &Ray) -> impl Iterator<Item = Ray> + '_ {
    (0..8).flat_map(move |input| {
        [true, false].into_iter().filter_map(move |up| {
            let mut values = ray.inputs();
            let value = values[input];
            if !value.is_finite() {
                return None;
            }
            values[input] = ulp_step(value, up);
            Some(Ray::from_inputs(values))
        })
    })
}

/// The meshes that differ from `mesh` in one coordinate of one of
/// `vertices` by one f32 ulp, either way (vertices out of range skipped).
pub fn one_ulp_vertex_moves<'m>(
    mesh: &'m TriangleMesh,
    vertices: &'m [u32],
) -> impl Iterator<Item = MovedVertex> + 'm {
    vertices.iter().flat_map(move |&index| {
        let position = mesh.positions.get(index as usize).map(|p| p.to_array());
        position.into_iter().flat_map(move |position| {
            (0..3).flat_map(move |axis| {
                [true, false].into_iter().filter_map(move |up| {
                    let mut moved = position;
                    if !moved[axis].is_finite() {
                        return None;
                    }
                    moved[axis] = ulp_step(moved[axis], up);
                    Some(MovedVertex {
                        index,
                        position: moved,
                    })
                })
            })
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn a_ray_has_two_neighbours_per_finite_input() {
        let ray = Ray::new(Vec3::ONE, Vec3::X);
        // tfar = ∞ has no neighbour.
        assert_eq!(one_ulp_neighbours(&ray).count(), 14);
    }

    #[test]
    fn nearest_reports_exact_ties() {
        let mesh = TriangleMesh {
            positions: vec![
                Vec3::ZERO,
                Vec3::X,
                Vec3::Y,
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(-1.0, 0.0, -1.0),
            ],
            // Twice the same triangle, the other half of the quad, and one
            // behind.
            indices: vec![[0, 1, 2], [1, 3, 2], [0, 1, 2], [4, 1, 2]],
            materials: vec![0; 4],
            ..Default::default()
        };
        let oracle = Oracle::new(&mesh);
        let down = |x: f32, y: f32| Ray::new(Vec3::new(x, y, 1.0), Vec3::NEG_Z);
        assert_eq!(oracle.nearest(&down(0.25, 0.25)), Some((1.0, vec![0, 2])));
        assert_eq!(
            oracle.nearest(&down(0.5, 0.5)),
            Some((1.0, vec![0, 1, 2, 3]))
        );
        assert_eq!(oracle.nearest(&down(0.75, 0.75)), Some((1.0, vec![1])));
        assert_eq!(oracle.nearest(&down(2.0, 2.0)), None);
        assert!(oracle.nearer_hit_exists(&down(0.1, 0.5), 3));
        assert!(!oracle.nearer_hit_exists(&down(0.1, 0.5), 0));
    }
}
