//! One stability case's rays through our BVH, Embree in default mode and
//! Embree in robust mode, every difference judged by the exact referee.

use crate::backends::embree;
use crate::bvh::{BuildOptions, Bvh};
use crate::check::{Checked, Difference, Verdict, VerdictCounts};
use crate::geometry::{Hit, Ray, TriangleMesh};
use crate::trace::Intersector;
use raycheck_reference::{BuildQuality, Device, Scene, SceneOptions};
use rayon::prelude::*;
use std::collections::BTreeSet;
use std::sync::atomic::{AtomicU64, Ordering};

/// An intersector that counts its own misses and non-finite outputs.
struct Watched<'a, I: ?Sized> {
    inner: &'a I,
    misses: AtomicU64,
    nan_outputs: AtomicU64,
}

impl<'a, I: Intersector + ?Sized> Watched<'a, I> {
    fn new(inner: &'a I) -> Self {
        Self {
            inner,
            misses: AtomicU64::new(0),
            nan_outputs: AtomicU64::new(0),
        }
    }
}

fn is_finite_hit(hit: &Hit) -> bool {
    hit.t.is_finite() && hit.u.is_finite() && hit.v.is_finite() && hit.ng.is_finite()
}

impl<I: Intersector + ?Sized> Intersector for Watched<'_, I> {
    fn intersect(&self, ray: &Ray) -> Option<Hit> {
        let hit = self.inner.intersect(ray);
        match &hit {
            None => _ = self.misses.fetch_add(1, Ordering::Relaxed),
            Some(h) if !is_finite_hit(h) => _ = self.nan_outputs.fetch_add(1, Ordering::Relaxed),
            Some(_) => {}
        }
        hit
    }

    fn occluded(&self, ray: &Ray) -> bool {
        self.inner.occluded(ray)
    }
}

/// Per backend: our BVH, Embree default, Embree robust.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct PerBackend {
    pub ours: u64,
    pub embree: u64,
    pub embree_robust: u64,
}

impl std::ops::AddAssign for PerBackend {
    fn add_assign(&mut self, o: Self) {
        self.ours += o.ours;
        self.embree += o.embree;
        self.embree_robust += o.embree_robust;
    }
}

/// What one batch of rays showed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Tally {
    pub rays: u64,
    /// Rays on which our answer (closest or any hit) is not admissible.
    pub ours_wrong: u64,
    pub embree_wrong: u64,
    pub embree_robust_wrong: u64,
    /// Rays with a difference where both answers are admissible.
    pub ambiguous: u64,
    /// Same triangle, our `t` beyond the distance tolerance.
    pub ours_t_off: u64,
    /// Hits with a non-finite `t`, `u`, `v` or normal, per backend.
    pub nan_outputs: PerBackend,
    /// Closest-hit queries answered with a miss.
    pub misses: PerBackend,
}

impl std::ops::AddAssign for Tally {
    fn add_assign(&mut self, o: Self) {
        self.rays += o.rays;
        self.ours_wrong += o.ours_wrong;
        self.embree_wrong += o.embree_wrong;
        self.embree_robust_wrong += o.embree_robust_wrong;
        self.ambiguous += o.ambiguous;
        self.ours_t_off += o.ours_t_off;
        self.nan_outputs += o.nan_outputs;
        self.misses += o.misses;
    }
}

/// The three backends over one mesh.
pub struct Backends<'a> {
    pub mesh: &'a TriangleMesh,
    pub bvh: Bvh,
    embree: Scene,
    embree_robust: Scene,
}

impl<'a> Backends<'a> {
    pub fn new(device: &Device, mesh: &'a TriangleMesh) -> anyhow::Result<Self> {
        let options = |robust| SceneOptions {
            quality: BuildQuality::Medium,
            robust,
        };
        Ok(Self {
            mesh,
            bvh: Bvh::build(mesh, &BuildOptions::sah()),
            embree: embree::build_scene(device, mesh, options(false))?,
            embree_robust: embree::build_scene(device, mesh, options(true))?,
        })
    }

    /// Asks every backend the closest-hit and the any-hit query of each ray
    /// and judges every difference.
    pub fn trace(&self, rays: &[Ray]) -> Tally {
        let ours = Watched::new(&self.bvh);
        let embree = Watched::new(&self.embree);
        let robust = Watched::new(&self.embree_robust);
        let against_default = Checked::new(&ours, &embree);
        let against_robust = Checked::new(&self.bvh, &robust);
        rays.par_iter().for_each(|ray| {
            against_default.intersect(ray);
            against_default.occluded(ray);
            against_robust.intersect(ray);
            against_robust.occluded(ray);
        });
        let default_log = against_default.into_log();
        let robust_log = against_robust.into_log();
        let default_verdicts = default_log.judge(self.mesh);
        let robust_verdicts = robust_log.judge(self.mesh);
        let rays_with = |verdict: Verdict, distance: bool| {
            let mut set = BTreeSet::new();
            for (log, verdicts) in [
                (&default_log, &default_verdicts),
                (&robust_log, &robust_verdicts),
            ] {
                for (d, v) in log.differences.iter().zip(verdicts) {
                    let is_distance =
                        d.kind() == crate::check::difference::DifferenceKind::Distance;
                    if *v == verdict && (distance == is_distance || verdict == Verdict::Ambiguous) {
                        set.insert(ray_bits(d));
                    }
                }
            }
            set.len() as u64
        };
        let default_counts = VerdictCounts::tally(&default_log.differences, &default_verdicts);
        let robust_counts = VerdictCounts::tally(&robust_log.differences, &robust_verdicts);
        Tally {
            rays: rays.len() as u64,
            ours_wrong: rays_with(Verdict::OursWrong, false),
            embree_wrong: default_counts.embree_wrong,
            embree_robust_wrong: robust_counts.embree_wrong,
            ambiguous: rays_with(Verdict::Ambiguous, false),
            ours_t_off: rays_with(Verdict::OursWrong, true),
            nan_outputs: PerBackend {
                ours: ours.nan_outputs.into_inner(),
                embree: embree.nan_outputs.into_inner(),
                embree_robust: robust.nan_outputs.into_inner(),
            },
            misses: PerBackend {
                ours: ours.misses.into_inner(),
                embree: embree.misses.into_inner(),
                embree_robust: robust.misses.into_inner(),
            },
        }
    }
}

fn ray_bits(d: &Difference) -> [u32; 8] {
    d.sort_key().1
}
