//! One stability case's rays through every selected backend at once, every
//! disagreement (and a sample of the agreements) judged by the exact
//! referee, counted per backend in rays.

use super::{Context, Recorder};
use crate::backends::Backend;
use crate::bvh::wide::WideBvh;
use crate::bvh::{BuildOptions, Bvh};
use crate::check::Checked;
use crate::check::exact::Oracle;
use crate::geometry::{Ray, TriangleMesh};
use crate::results::Verdicts;
use crate::trace::Intersector;
use rayon::prelude::*;

/// The selected backends over one mesh, and our own trees for the checks
/// that are about our tracer alone (traversal against brute force, the
/// lowest primID of a tie, where our hit lies).
pub struct Backends<'a> {
    pub mesh: &'a TriangleMesh,
    /// Every selected backend's name, in order.
    names: Vec<String>,
    /// Those that could be built over the mesh.
    selected: Vec<Box<dyn Backend>>,
    recorder: Option<&'a Recorder>,
    /// Our wide BVH, the tracer `ours` names.
    pub ours: WideBvh,
    /// Our binary SAH BVH, which also holds the loop over all triangles.
    pub binary: Bvh,
}

impl<'a> Backends<'a> {
    /// Builds every selected backend over `mesh`; one that cannot be built
    /// over it (a crate refusing or panicking on its vertices) answers none
    /// of its rays and is counted as a build failure. Embree or our own
    /// trees failing to build is an error.
    pub fn new(context: &Context<'a>, mesh: &'a TriangleMesh) -> anyhow::Result<Self> {
        let mut selected = Vec::new();
        for name in context.backends {
            match name.build(mesh, context.build) {
                Ok(backend) => selected.push(backend),
                Err(error) if name.is_third_party() => {
                    eprintln!("note: {name} skipped on one mesh: {error:#}");
                }
                Err(error) => return Err(error),
            }
        }
        anyhow::ensure!(
            !selected.is_empty(),
            "no selected backend could be built over the case's mesh"
        );
        Ok(Self {
            mesh,
            names: context.backends.iter().map(|n| n.to_string()).collect(),
            selected,
            recorder: context.recorder,
            ours: WideBvh::build(mesh),
            binary: Bvh::build(mesh, &BuildOptions::sah()),
        })
    }

    /// Asks every backend the closest-hit and the any-hit query of each ray
    /// and judges every disagreement and the sampled agreements.
    pub fn trace(&self, rays: &[Ray]) -> Verdicts {
        if let Some(recorder) = self.recorder {
            recorder
                .lock()
                .unwrap_or_else(|poisoned| poisoned.into_inner())
                .push((self.mesh.clone(), rays.to_vec()));
        }
        let checked = Checked::new(self.selected.iter().map(|b| b.as_ref()).collect());
        rays.par_iter().for_each(|ray| {
            checked.intersect(ray);
            checked.occluded(ray);
        });
        Verdicts::judge(&checked.into_log(), self.mesh, rays.len() as u64).over(&self.names)
    }

    /// [`Backends::trace`] for rays that had to hit, with each backend's
    /// leaks: its misses on rays the exact oracle finds a hit for. (Where
    /// f32 cannot represent a placement the mesh collapses or rounds into
    /// another shape, and a ray may truly miss it: no leak.)
    pub fn trace_must_hit(&self, rays: &[Ray]) -> Verdicts {
        let mut verdicts = self.trace(rays);
        let oracle = Oracle::new(self.mesh);
        for backend in &self.selected {
            let leaks = rays
                .par_iter()
                .filter(|ray| backend.intersect(ray).is_none() && oracle.any_hit(ray))
                .count() as u64;
            let name = backend.name();
            if let Some(tally) = verdicts.backends.iter_mut().find(|b| b.name == name) {
                tally.leaks = leaks;
            }
        }
        verdicts
    }
}
