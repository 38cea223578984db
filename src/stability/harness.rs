//! One stability case's rays through every selected backend at once, every
//! disagreement (and a sample of the agreements) judged by the exact
//! referee, counted per backend in rays.

use super::{Batch, Context, Recorder};
use crate::backends::{Backend, BackendName, BuildContext};
use crate::bvh::wide::WideBvh;
use crate::bvh::{BuildOptions, Bvh};
use crate::check::exact::Oracle;
use crate::check::{CheckLog, Checked};
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

/// Builds every backend of `names` over `mesh`; one that cannot be built
/// over it (a crate refusing or panicking on its vertices) is left out,
/// with a note, and [`Asked::judge`] counts it as a build failure. Embree
/// or our own trees failing to build is an error.
pub fn build_over(
    names: &[BackendName],
    mesh: &TriangleMesh,
    build: BuildContext,
) -> anyhow::Result<Vec<Box<dyn Backend>>> {
    let mut built = Vec::new();
    for name in names {
        match name.build(mesh, build) {
            Ok(backend) => built.push(backend),
            Err(error) if name.is_third_party() => {
                eprintln!("note: {name} skipped on one mesh: {error:#}");
            }
            Err(error) => return Err(error),
        }
    }
    Ok(built)
}

/// A batch's queries asked of every backend, before the referee judges.
pub struct Asked {
    /// Every disagreement and sampled agreement.
    pub log: CheckLog,
    /// The rays the batch asks.
    pub rays: u64,
    /// Per backend (by name), its leaks, where the batch's rays had to hit.
    leaks: Option<Vec<(String, u64)>>,
}

/// Asks every one of `backends` the closest hit of each ray of `closest`
/// and the any-hit query of each ray of `any_hit`, over `mesh`; where
/// `must_hit`, also counts each backend's leaks: its misses of closest-hit
/// rays the exact oracle finds a hit for. (Where f32 cannot represent a
/// placement the mesh collapses or rounds into another shape, and a ray
/// may truly miss it: no leak.)
pub fn ask(
    backends: &[&dyn Backend],
    mesh: &TriangleMesh,
    closest: &[Ray],
    any_hit: &[Ray],
    must_hit: bool,
) -> Asked {
    let checked = Checked::new(backends.to_vec());
    closest.par_iter().for_each(|ray| {
        checked.intersect(ray);
    });
    any_hit.par_iter().for_each(|ray| {
        checked.occluded(ray);
    });
    let leaks = must_hit.then(|| {
        let oracle = Oracle::new(mesh);
        backends
            .iter()
            .map(|backend| {
                let leaks = closest
                    .par_iter()
                    .filter(|ray| backend.intersect(ray).is_none() && oracle.any_hit(ray))
                    .count() as u64;
                (backend.name(), leaks)
            })
            .collect()
    });
    Asked {
        log: checked.into_log(),
        rays: closest.len().max(any_hit.len()) as u64,
        leaks,
    }
}

impl Asked {
    /// The referee's verdicts on the log, judged against `mesh` (calling
    /// `judged` after each record), over every backend of `names` in that
    /// order (one that could not be built over the mesh gets one build
    /// failure).
    pub fn judge(
        &self,
        mesh: &TriangleMesh,
        names: &[String],
        judged: &(dyn Fn() + Sync),
    ) -> Verdicts {
        let judgements = self.log.judge_reporting(mesh, judged);
        let mut verdicts = Verdicts::count(&self.log, &judgements, self.rays).over(names);
        for (name, leaks) in self.leaks.iter().flatten() {
            if let Some(tally) = verdicts.backends.iter_mut().find(|b| &b.name == name) {
                tally.leaks = *leaks;
            }
        }
        verdicts
    }
}

impl<'a> Backends<'a> {
    /// Builds every selected backend over `mesh` ([`build_over`]) and our
    /// own trees.
    pub fn new(context: &Context<'a>, mesh: &'a TriangleMesh) -> anyhow::Result<Self> {
        let selected = build_over(context.backends, mesh, context.build)?;
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
        self.judge(rays, false)
    }

    /// [`Backends::trace`] for rays that had to hit, with each backend's
    /// leaks ([`ask`]).
    pub fn trace_must_hit(&self, rays: &[Ray]) -> Verdicts {
        self.judge(rays, true)
    }

    fn judge(&self, rays: &[Ray], must_hit: bool) -> Verdicts {
        if let Some(recorder) = self.recorder {
            recorder.record(Batch::both_queries(self.mesh, rays, must_hit));
        }
        let backends: Vec<&dyn Backend> = self.selected.iter().map(|b| b.as_ref()).collect();
        ask(&backends, self.mesh, rays, rays, must_hit).judge(self.mesh, &self.names, &|| {})
    }
}
