//! Closest-hit traversal (nearer child first, far child on a stack, culled
//! on pop once a closer hit is known) and any-hit traversal with early exit.
//!
//! Closest hit is deterministic: a candidate replaces the best hit when it is
//! closer (by the unrounded distance), or equally close with a lower prim
//! id, so the answer never
//! depends on the visiting order and equals [`Bvh::intersect_brute_force`]
//! bit for bit.
//!
//! Closest-hit traversal is generic over a [`NodeVisits`] counter: the
//! [`Intersector`] path uses [`Uncounted`], whose visit compiles to nothing,
//! and the debug heat map counts with a `u32`.

use super::ray_box::RayBox;
use super::{Bvh, MAX_DEPTH};
use crate::geometry::triangle::{TriangleHit, WatertightRay, geometric_normal};
use crate::geometry::{Hit, Ray};
use crate::trace::Intersector;

/// Whether a ray can hit anything: finite origin and direction, a nonzero
/// direction and an interval `tnear <= tfar` without NaN. Others are answered
/// "no hit" without traversal.
fn is_traceable(ray: &Ray) -> bool {
    ray.origin.is_finite()
        && ray.dir.is_finite()
        && ray.dir != glam::Vec3::ZERO
        && ray.tnear <= ray.tfar
}

/// Counts the nodes a traversal visits (each node whose box the ray enters
/// and whose children or triangles are then tested).
pub trait NodeVisits {
    fn visit(&mut self);
}

/// No counting: the normal traversal.
pub struct Uncounted;

impl NodeVisits for Uncounted {
    #[inline(always)]
    fn visit(&mut self) {}
}

impl NodeVisits for u32 {
    fn visit(&mut self) {
        *self += 1;
    }
}

/// The best hit so far and the slot it came from.
#[derive(Clone, Copy)]
struct Closest {
    hit: TriangleHit,
    slot: usize,
}

impl Bvh {
    /// Closest hit by testing every triangle in turn with the same test and
    /// tie rule as [`Intersector::intersect`]: the reference the traversal
    /// must match exactly.
    pub fn intersect_brute_force(&self, ray: &Ray) -> Option<Hit> {
        if !is_traceable(ray) {
            return None;
        }
        let wray = WatertightRay::new(ray);
        let mut best = None;
        for slot in 0..self.triangles.len() {
            self.consider(&wray, ray, slot, &mut best);
        }
        best.map(|b| self.to_hit(b))
    }

    /// Any hit by testing every triangle in turn.
    pub fn occluded_brute_force(&self, ray: &Ray) -> bool {
        is_traceable(ray) && {
            let wray = WatertightRay::new(ray);
            self.triangles
                .iter()
                .any(|&[p0, p1, p2]| wray.intersect(p0, p1, p2, ray.tnear, ray.tfar).is_some())
        }
    }

    /// Tests slot `slot` and keeps it if it beats `best`.
    fn consider(&self, wray: &WatertightRay, ray: &Ray, slot: usize, best: &mut Option<Closest>) {
        let [p0, p1, p2] = self.triangles[slot];
        let tfar = best.map_or(ray.tfar, |b| b.hit.t);
        let Some(hit) = wray.intersect(p0, p1, p2, ray.tnear, tfar) else {
            return;
        };
        // The test already bounded `hit.t` by the best `t`; equal f32 `t`s
        // are ordered by the unrounded distance, then the prim id.
        let better = best
            .is_none_or(|b| hit.nearer_than(self.prim_ids[slot], &b.hit, self.prim_ids[b.slot]));
        if better {
            *best = Some(Closest { hit, slot });
        }
    }

    fn to_hit(&self, best: Closest) -> Hit {
        let [p0, p1, p2] = self.triangles[best.slot];
        Hit {
            t: best.hit.t,
            u: best.hit.u,
            v: best.hit.v,
            prim: self.prim_ids[best.slot],
            ng: geometric_normal(p0, p1, p2),
        }
    }
}

impl Bvh {
    /// The closest hit, as [`Intersector::intersect`], counting every node
    /// visited into `visits`.
    pub fn intersect_counted(&self, ray: &Ray, visits: &mut impl NodeVisits) -> Option<Hit> {
        if self.nodes.is_empty() || !is_traceable(ray) {
            return None;
        }
        let rb = RayBox::new(ray);
        rb.entry(&self.nodes[0], ray.tnear, ray.tfar)?;
        let wray = WatertightRay::new(ray);
        let mut best: Option<Closest> = None;
        // Far children still to visit, with the distance where the ray
        // enters them; one per inner level at most.
        let mut stack = [(0u32, 0f32); MAX_DEPTH as usize];
        let mut depth = 0;
        let mut current = 0;
        loop {
            visits.visit();
            let node = &self.nodes[current];
            let tfar = best.map_or(ray.tfar, |b| b.hit.t);
            match node.children() {
                None => {
                    for slot in node.triangle_slots() {
                        self.consider(&wray, ray, slot, &mut best);
                    }
                }
                Some([left, right]) => {
                    let l = rb.entry(&self.nodes[left], ray.tnear, tfar);
                    let r = rb.entry(&self.nodes[right], ray.tnear, tfar);
                    match (l, r) {
                        (Some(l), Some(r)) => {
                            let (near, far, far_entry) = if l <= r {
                                (left, right, r)
                            } else {
                                (right, left, l)
                            };
                            stack[depth] = (far as u32, far_entry);
                            depth += 1;
                            current = near;
                            continue;
                        }
                        (Some(_), None) => {
                            current = left;
                            continue;
                        }
                        (None, Some(_)) => {
                            current = right;
                            continue;
                        }
                        (None, None) => {}
                    }
                }
            }
            // Pop the next far child the ray can still reach.
            let tfar = best.map_or(ray.tfar, |b| b.hit.t);
            loop {
                if depth == 0 {
                    return best.map(|b| self.to_hit(b));
                }
                depth -= 1;
                let (node, entry) = stack[depth];
                if entry <= tfar {
                    current = node as usize;
                    break;
                }
            }
        }
    }
}

impl Intersector for Bvh {
    fn intersect(&self, ray: &Ray) -> Option<Hit> {
        self.intersect_counted(ray, &mut Uncounted)
    }

    fn occluded(&self, ray: &Ray) -> bool {
        if self.nodes.is_empty() || !is_traceable(ray) {
            return false;
        }
        let rb = RayBox::new(ray);
        if rb.entry(&self.nodes[0], ray.tnear, ray.tfar).is_none() {
            return false;
        }
        let wray = WatertightRay::new(ray);
        let mut stack = [0u32; MAX_DEPTH as usize];
        let mut depth = 0;
        let mut current = 0;
        loop {
            let node = &self.nodes[current];
            match node.children() {
                None => {
                    let hit = node.triangle_slots().any(|slot| {
                        let [p0, p1, p2] = self.triangles[slot];
                        wray.intersect(p0, p1, p2, ray.tnear, ray.tfar).is_some()
                    });
                    if hit {
                        return true;
                    }
                }
                Some([left, right]) => {
                    let l = rb.entry(&self.nodes[left], ray.tnear, ray.tfar).is_some();
                    let r = rb.entry(&self.nodes[right], ray.tnear, ray.tfar).is_some();
                    match (l, r) {
                        (true, true) => {
                            stack[depth] = right as u32;
                            depth += 1;
                            current = left;
                            continue;
                        }
                        (true, false) => {
                            current = left;
                            continue;
                        }
                        (false, true) => {
                            current = right;
                            continue;
                        }
                        (false, false) => {}
                    }
                }
            }
            if depth == 0 {
                return false;
            }
            depth -= 1;
            current = stack[depth] as usize;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::BuildOptions;
    use crate::bvh::test_meshes::{
        LOWEST_TIED_PRIM, Rng, grid, option_sets, random_rays, random_soup, sphere, tie_mesh,
        untraceable_variants,
    };
    use crate::geometry::TriangleMesh;
    use glam::Vec3;

    /// Every bit of a hit, so -0.0 and 0.0 (or two NaNs) are told apart.
    fn bits(hit: Option<Hit>) -> Option<[u32; 7]> {
        hit.map(|h| {
            [
                h.t.to_bits(),
                h.u.to_bits(),
                h.v.to_bits(),
                h.prim,
                h.ng.x.to_bits(),
                h.ng.y.to_bits(),
                h.ng.z.to_bits(),
            ]
        })
    }

    fn check_against_brute_force(name: &str, mesh: &TriangleMesh, rays: &[Ray]) -> usize {
        let mut hits = 0;
        for options in option_sets() {
            let bvh = Bvh::build(mesh, &options);
            for ray in rays {
                let expected = bvh.intersect_brute_force(ray);
                let found = bvh.intersect(ray);
                assert_eq!(bits(found), bits(expected), "{name}, {options:?}, {ray:?}");
                assert_eq!(
                    bvh.occluded(ray),
                    expected.is_some(),
                    "{name}, {options:?}, {ray:?}"
                );
                assert_eq!(
                    bvh.occluded_brute_force(ray),
                    expected.is_some(),
                    "{name}, {ray:?}"
                );
                hits += usize::from(expected.is_some());
            }
        }
        hits
    }

    #[test]
    fn closest_hit_equals_brute_force_bit_for_bit() {
        let mut rng = Rng::new(20);
        let rays = random_rays(3000, &mut rng);
        let mut duplicated = random_soup(300, 0.3, &mut rng);
        let copy = duplicated.clone();
        duplicated.append(&copy, 0);
        let meshes = [
            ("soup", random_soup(2000, 0.1, &mut rng)),
            ("big triangles", random_soup(300, 1.0, &mut rng)),
            ("grid", {
                let mut g = grid(30);
                g.positions
                    .iter_mut()
                    .for_each(|p| *p = 2.0 * *p - Vec3::ONE);
                g
            }),
            ("sphere", sphere(Vec3::ZERO, 0.9, 24, 37)),
            ("duplicated", duplicated),
        ];
        for (name, mesh) in &meshes {
            let hits = check_against_brute_force(name, mesh, &rays);
            // The comparison means something only if many rays hit.
            assert!(
                hits > rays.len(),
                "{name}: only {hits} hits over all option sets"
            );
        }
    }

    #[test]
    fn counted_traversal_gives_the_same_hits_and_counts_visits() {
        let mut rng = Rng::new(26);
        let mesh = random_soup(2000, 0.1, &mut rng);
        for options in option_sets() {
            let bvh = Bvh::build(&mesh, &options);
            let (mut most, mut hits) = (0, 0);
            for ray in random_rays(2000, &mut rng) {
                let mut visits = 0u32;
                let counted = bvh.intersect_counted(&ray, &mut visits);
                assert_eq!(bits(counted), bits(bvh.intersect(&ray)), "{ray:?}");
                assert!(visits as usize <= bvh.nodes().len(), "{visits}");
                if counted.is_some() {
                    // The root and at least one leaf.
                    assert!(visits >= 2 || bvh.nodes().len() == 1, "{visits}");
                    hits += 1;
                }
                most = most.max(visits);
            }
            assert!(hits > 100 && most > 2, "{options:?}: {hits} hits, {most}");
        }
        let bvh = Bvh::build(&mesh, &BuildOptions::sah());
        let mut visits = 0u32;
        let away = Ray::new(Vec3::splat(5.0), Vec3::ONE);
        assert_eq!(bvh.intersect_counted(&away, &mut visits), None);
        assert_eq!(visits, 0, "a ray missing the root box visits nothing");
    }

    #[test]
    fn ties_go_to_the_lowest_prim_id() {
        let (mesh, ray) = tie_mesh(&mut Rng::new(21));
        for options in option_sets() {
            let bvh = Bvh::build(&mesh, &options);
            let hit = bvh.intersect(&ray).unwrap();
            assert_eq!((hit.t, hit.prim), (1.0, LOWEST_TIED_PRIM), "{options:?}");
        }
    }

    #[test]
    fn both_builders_give_identical_hits() {
        let mut rng = Rng::new(22);
        let mesh = random_soup(5000, 0.08, &mut rng);
        let median = Bvh::build(&mesh, &BuildOptions::median());
        let sah = Bvh::build(&mesh, &BuildOptions::sah());
        for ray in random_rays(5000, &mut rng) {
            assert_eq!(
                bits(median.intersect(&ray)),
                bits(sah.intersect(&ray)),
                "{ray:?}"
            );
        }
    }

    /// As Embree's verify WatertightTest: a tessellated sphere far from the
    /// origin, rays from its centre; no ray may escape.
    #[test]
    fn no_ray_escapes_a_closed_sphere() {
        let centre = Vec3::new(148_376.0, 1234.0, -223_423.0);
        let mesh = sphere(centre, 2.0, 200, 200);
        let mut rng = Rng::new(23);
        for options in [BuildOptions::median(), BuildOptions::sah()] {
            let bvh = Bvh::build(&mesh, &options);
            for _ in 0..20_000 {
                let ray = Ray::new(centre, rng.point(-1.0, 1.0));
                assert!(
                    bvh.intersect(&ray).is_some(),
                    "{options:?}: {ray:?} escapes"
                );
                assert!(bvh.occluded(&ray), "{options:?}: {ray:?} escapes");
            }
        }
    }

    /// Rays through inner grid vertices and points on shared inner edges
    /// (horizontal, vertical and diagonal), from random points above and
    /// below, always hit the grid.
    #[test]
    fn no_ray_slips_through_a_grid() {
        let n = 40;
        let mesh = grid(n);
        let mut rng = Rng::new(24);
        for options in [BuildOptions::median(), BuildOptions::sah()] {
            let bvh = Bvh::build(&mesh, &options);
            for i in 0..20_000 {
                let cell = |rng: &mut Rng| (1 + rng.next_u64() % u64::from(n - 2)) as f32;
                let (x, y, s) = (cell(&mut rng), cell(&mut rng), rng.unit_f32());
                let (x, y) = match i % 4 {
                    0 => (x, y),
                    1 => (x + s, y),
                    2 => (x, y + s),
                    _ => (x + s, y + s),
                };
                let target = Vec3::new(x / n as f32, y / n as f32, 0.0);
                let origin = rng.point(-2.0, 3.0) + Vec3::Z * if i % 2 == 0 { 3.0 } else { -3.0 };
                let ray = Ray::new(origin, target - origin);
                assert!(
                    bvh.intersect_brute_force(&ray).is_some(),
                    "{ray:?} slips through"
                );
                assert!(
                    bvh.intersect(&ray).is_some(),
                    "{options:?}: {ray:?} slips through"
                );
            }
        }
    }

    #[test]
    fn untraceable_rays_and_empty_trees_hit_nothing() {
        let mesh = random_soup(100, 0.5, &mut Rng::new(25));
        let bvh = Bvh::build(&mesh, &BuildOptions::sah());
        let ok = Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::Z);
        assert!(bvh.intersect(&ok).is_some(), "the valid ray should hit");
        for ray in untraceable_variants(ok) {
            assert_eq!(bvh.intersect(&ray), None, "{ray:?}");
            assert!(!bvh.occluded(&ray), "{ray:?}");
            assert_eq!(bvh.intersect_brute_force(&ray), None, "{ray:?}");
        }
        let empty = Bvh::build(&TriangleMesh::default(), &BuildOptions::median());
        assert_eq!(empty.intersect(&ok), None);
        assert!(!empty.occluded(&ok));
    }

    #[test]
    fn nan_vertices_are_never_hit() {
        let tri = [
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        let mut bad = tri;
        bad[1].x = f32::NAN;
        let mut nearer = bad;
        nearer.iter_mut().for_each(|p| p.z = -1.0);
        let mesh = TriangleMesh::soup(&[nearer, tri]);
        for options in option_sets() {
            let bvh = Bvh::build(&mesh, &options);
            let hit = bvh
                .intersect(&Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::Z))
                .unwrap();
            assert_eq!((hit.prim, hit.t), (1, 5.0));
        }
    }
}
