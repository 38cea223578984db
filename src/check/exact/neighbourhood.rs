//! The referee's one-ulp search, made incremental.
//!
//! An answer that is not exactly right is admissible when it is right for
//! some input one ulp away: a ray changed in one input, or one vertex
//! coordinate moved. Deciding each such change from scratch costs a pass
//! over every triangle near the ray per change, and a ray through nested,
//! nearly coincident geometry meets thousands of triangles with thousands
//! of vertices: the search grew with the square of them. Here one ray's
//! contacts are decided once, each marked *steady* when no one-ulp change
//! of any input can flip it ([`contact()`](super::contact::contact),
//! [`steady_order`]); a change then decides again only what it can touch:
//! the unsteady contacts of a ray one ulp away, and the triangles around a
//! moved vertex. Each triangle has three vertices, so a whole search takes
//! a bounded number of exact evaluations per triangle near the ray.

use super::contact::{Contact, Corners, compare_hits, steady_order};
use super::oracle::{MovedVertex, Oracle};
use crate::geometry::Ray;
use std::cell::Cell;
use std::cmp::Ordering;

/// An input the referee tries: the ray and mesh as given, a ray one ulp
/// away in one input, or the mesh with one vertex coordinate one ulp away.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Change {
    None,
    Ray(Ray),
    Vertex(MovedVertex),
}

/// One ray's exact contacts with every triangle whose padded box it
/// meets, and the same questions asked under a [`Change`].
pub struct Neighbourhood<'n, 'm> {
    oracle: &'n Oracle<'m>,
    ray: Ray,
    /// The triangles whose padded boxes the ray meets, in prim order.
    candidates: Vec<u32>,
    /// The ray's contact with each candidate.
    contacts: Vec<Contact>,
    /// `(vertex, candidate position)` for each corner of each candidate,
    /// sorted: the candidates a moved vertex moves.
    incidence: Vec<(u32, usize)>,
    /// Candidates hit.
    hits: usize,
    /// Whether some candidate is hit under every change.
    steady_hit: bool,
    /// Exact evaluations made: contacts and orders no steady sign settled.
    work: Cell<u64>,
}

/// A claimed closest hit on one triangle, and the order of every other
/// candidate against it.
pub struct Claim {
    prim: u32,
    /// Its corners, `None` for an index out of range (never hit).
    corners: Option<Corners>,
    /// Its vertices.
    vertices: [u32; 3],
    /// Its exact `t` for the inputs as given, when it is hit.
    base_t: Option<f64>,
    /// Per candidate that may be hit: its order against the claim, where
    /// steady.
    steady: Vec<Option<Ordering>>,
    /// Per candidate: whether it is hit strictly nearer than the claim,
    /// inputs as given (all false when the claim is not hit).
    base_nearer: Vec<bool>,
    /// How many are.
    nearer: usize,
    /// Whether some candidate is hit, and strictly nearer than the claim,
    /// under every change: then no change makes the claim right.
    beaten: bool,
}

impl Claim {
    /// Whether no change can make the claim right: another triangle is
    /// steadily hit nearer.
    pub fn beaten(&self) -> bool {
        self.beaten
    }
}

impl<'n, 'm> Neighbourhood<'n, 'm> {
    /// Decides every contact of `ray`.
    pub fn new(oracle: &'n Oracle<'m>, ray: Ray) -> Self {
        let candidates = oracle.candidates(&ray);
        let contacts: Vec<Contact> = candidates
            .iter()
            .map(|&prim| oracle.contact(&ray, prim))
            .collect();
        let indices = &oracle.mesh().indices;
        let mut incidence: Vec<(u32, usize)> = candidates
            .iter()
            .enumerate()
            .flat_map(|(position, &prim)| {
                indices
                    .get(prim as usize)
                    .into_iter()
                    .flatten()
                    .map(move |&vertex| (vertex, position))
            })
            .collect();
        incidence.sort_unstable();
        incidence.dedup();
        Self {
            oracle,
            ray,
            hits: contacts.iter().filter(|c| c.t.is_some()).count(),
            steady_hit: contacts.iter().any(|c| c.steady && c.t.is_some()),
            work: Cell::new(candidates.len() as u64),
            candidates,
            contacts,
            incidence,
        }
    }

    /// Exact evaluations made so far, building included (one per
    /// candidate): a count independent of threads and timing.
    pub fn work(&self) -> u64 {
        self.work.get()
    }

    fn exact<T>(&self, evaluate: impl FnOnce() -> T) -> T {
        self.work.set(self.work.get() + 1);
        evaluate()
    }

    /// The candidates, in prim order.
    pub fn candidates(&self) -> &[u32] {
        &self.candidates
    }

    /// The candidates the ray hits, inputs as given.
    pub fn hit_prims(&self) -> impl Iterator<Item = u32> + '_ {
        self.candidates
            .iter()
            .zip(&self.contacts)
            .filter(|(_, c)| c.t.is_some())
            .map(|(&prim, _)| prim)
    }

    /// The positions of the candidates with `vertex` as a corner.
    fn around(&self, vertex: u32) -> impl Iterator<Item = usize> + '_ {
        let start = self.incidence.partition_point(|&(v, _)| v < vertex);
        self.incidence[start..]
            .iter()
            .take_while(move |&&(v, _)| v == vertex)
            .map(|&(_, position)| position)
    }

    /// Whether moving `vertex` by one ulp can change nothing a question
    /// reads: every candidate around it keeps its contact and, where
    /// `claim` is given and the candidate may be hit, its order against
    /// the claim; and it is not a corner of the claimed triangle (which,
    /// when not hit as given, no other move can make hit).
    pub fn settled(&self, vertex: u32, claim: Option<&Claim>) -> bool {
        if let Some(claim) = claim {
            if claim.vertices.contains(&vertex) {
                return false;
            }
            if claim.base_t.is_none() {
                return true;
            }
        }
        self.around(vertex).all(|p| {
            let contact = self.contacts[p];
            contact.steady && (contact.t.is_none() || claim.is_none_or(|c| c.steady[p].is_some()))
        })
    }

    /// The claim of a closest hit on `prim`, with every order the search
    /// may read.
    pub fn claim(&self, prim: u32) -> Claim {
        let corners = self.oracle.corners(prim as usize);
        let vertices = self
            .oracle
            .mesh()
            .indices
            .get(prim as usize)
            .copied()
            .unwrap_or([u32::MAX; 3]);
        let position = self.candidates.binary_search(&prim).ok();
        let base_t = position.and_then(|p| self.contacts[p].t);
        let count = self.candidates.len();
        let others = (0..count).filter(|&p| Some(p) != position);
        let mut steady = vec![None; count];
        let mut base_nearer = vec![false; count];
        if let Some(claimed) = corners {
            for p in others {
                let contact = self.contacts[p];
                if contact.t.is_some() || !contact.steady {
                    steady[p] = steady_order(&self.ray, &self.corners(p), &claimed);
                }
                base_nearer[p] = base_t.is_some()
                    && contact.t.is_some()
                    && steady[p].unwrap_or_else(|| {
                        self.exact(|| compare_hits(&self.ray, &self.corners(p), &claimed))
                    }) == Ordering::Less;
            }
        }
        let beaten = self
            .contacts
            .iter()
            .zip(&steady)
            .any(|(c, o)| c.steady && c.t.is_some() && *o == Some(Ordering::Less));
        Claim {
            prim,
            corners,
            vertices,
            base_t,
            nearer: base_nearer.iter().filter(|&&n| n).count(),
            steady,
            base_nearer,
            beaten,
        }
    }

    /// The corners of candidate `position` (every candidate has them: a
    /// triangle with an index out of range has no box to meet).
    fn corners(&self, position: usize) -> Corners {
        self.corners_in(self.oracle, self.candidates[position])
    }

    fn corners_in(&self, oracle: &Oracle, prim: u32) -> Corners {
        oracle
            .corners(prim as usize)
            .expect("candidates have corners")
    }

    /// Whether the ray hits any triangle under `change`.
    pub fn any_hit(&self, change: &Change) -> bool {
        if self.steady_hit {
            return true;
        }
        match change {
            Change::None => self.hits > 0,
            Change::Ray(ray) => self
                .ray_candidates(ray)
                .into_iter()
                .any(|(prim, position)| self.hit_by_ray(ray, prim, position)),
            Change::Vertex(moved) => {
                let oracle = self.oracle.with_vertex_moved(*moved);
                let hit_around = self
                    .around(moved.index)
                    .filter(|&p| self.contacts[p].t.is_some())
                    .count();
                self.hits > hit_around
                    || self.around(moved.index).any(|p| self.hit_moved(&oracle, p))
            }
        }
    }

    /// Under `change`: the exact `t` of the claimed triangle and whether
    /// another is hit strictly nearer, or `None` when the claimed triangle
    /// is not hit.
    pub fn claimed_hit(&self, claim: &Claim, change: &Change) -> Option<(f64, bool)> {
        let corners = claim.corners?;
        match change {
            Change::None => Some((claim.base_t?, claim.nearer > 0)),
            Change::Ray(ray) => {
                let t = self.exact(|| self.oracle.hit(ray, claim.prim))?;
                let nearer = self
                    .ray_candidates(ray)
                    .into_iter()
                    .filter(|&(prim, _)| prim != claim.prim)
                    .any(|(prim, position)| {
                        self.hit_by_ray(ray, prim, position)
                            && position.and_then(|p| claim.steady[p]).unwrap_or_else(|| {
                                self.exact(|| {
                                    let other = self.corners_in(self.oracle, prim);
                                    compare_hits(ray, &other, &corners)
                                })
                            }) == Ordering::Less
                    });
                Some((t, nearer))
            }
            Change::Vertex(moved) => {
                let oracle = self.oracle.with_vertex_moved(*moved);
                let order = |p: usize, claimed: &Corners| {
                    claim.steady[p].unwrap_or_else(|| {
                        self.exact(|| {
                            let other = self.corners_in(&oracle, self.candidates[p]);
                            compare_hits(&self.ray, &other, claimed)
                        })
                    })
                };
                let others = |p: &usize| self.candidates[*p] != claim.prim;
                if !claim.vertices.contains(&moved.index) {
                    let t = claim.base_t?;
                    let dropped = self
                        .around(moved.index)
                        .filter(|&p| claim.base_nearer[p])
                        .count();
                    let nearer = claim.nearer > dropped
                        || self.around(moved.index).filter(others).any(|p| {
                            self.hit_moved(&oracle, p) && order(p, &corners) == Ordering::Less
                        });
                    return Some((t, nearer));
                }
                let t = self.exact(|| oracle.hit(&self.ray, claim.prim))?;
                let moved_corners = oracle.corners(claim.prim as usize)?;
                let around: Vec<usize> = self.around(moved.index).collect();
                let nearer = (0..self.candidates.len()).filter(others).any(|p| {
                    let hit = if around.contains(&p) {
                        self.hit_moved(&oracle, p)
                    } else {
                        self.contacts[p].t.is_some()
                    };
                    hit && order(p, &moved_corners) == Ordering::Less
                });
                Some((t, nearer))
            }
        }
    }

    /// Whether candidate `p` is hit once a vertex moved (`oracle`): its
    /// contact when steady, else decided again.
    fn hit_moved(&self, oracle: &Oracle, p: usize) -> bool {
        let contact = self.contacts[p];
        if contact.steady {
            contact.t.is_some()
        } else {
            self.exact(|| oracle.hit(&self.ray, self.candidates[p]).is_some())
        }
    }

    /// The candidates of a ray one ulp away, each with its position among
    /// this ray's candidates, if it is one.
    fn ray_candidates(&self, ray: &Ray) -> Vec<(u32, Option<usize>)> {
        let mut next = 0;
        self.oracle
            .candidates(ray)
            .into_iter()
            .map(|prim| {
                next += self.candidates[next..].partition_point(|&c| c < prim);
                let position = (self.candidates.get(next) == Some(&prim)).then_some(next);
                (prim, position)
            })
            .collect()
    }

    /// Whether a ray one ulp away hits `prim` (at `position` among this
    /// ray's candidates, if it is one): a steady contact as it is, any
    /// other decided again.
    fn hit_by_ray(&self, ray: &Ray, prim: u32, position: Option<usize>) -> bool {
        match position.map(|p| self.contacts[p]) {
            Some(contact) if contact.steady => contact.t.is_some(),
            _ => self.exact(|| self.oracle.hit(ray, prim).is_some()),
        }
    }
}
