//! One stability case's rays through every selected backend at once, every
//! disagreement (and a sample of the agreements) judged by the exact
//! referee, counted per backend in rays.

use super::{Context, Recorder};
use crate::backends::Backend;
use crate::bvh::wide::WideBvh;
use crate::bvh::{BuildOptions, Bvh};
use crate::check::Checked;
use crate::geometry::{Ray, TriangleMesh};
use crate::results::Verdicts;
use crate::trace::Intersector;
use rayon::prelude::*;

/// The selected backends over one mesh, and our own trees for the checks
/// that are about our tracer alone (traversal against brute force, the
/// lowest primID of a tie, where our hit lies).
pub struct Backends<'a> {
    pub mesh: &'a TriangleMesh,
    selected: Vec<Box<dyn Backend>>,
    recorder: Option<&'a Recorder>,
    /// Our wide BVH, the tracer `ours` names.
    pub ours: WideBvh,
    /// Our binary SAH BVH, which also holds the loop over all triangles.
    pub binary: Bvh,
}

impl<'a> Backends<'a> {
    pub fn new(context: &Context<'a>, mesh: &'a TriangleMesh) -> anyhow::Result<Self> {
        let selected = context
            .backends
            .iter()
            .map(|name| name.build(mesh, context.device))
            .collect::<anyhow::Result<_>>()?;
        Ok(Self {
            mesh,
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
        Verdicts::judge(&checked.into_log(), self.mesh, rays.len() as u64)
    }
}
