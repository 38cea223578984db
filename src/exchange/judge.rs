//! `raycheck trace` and `raycheck judge`: a rays file traced by any
//! backend into a hits file, and a hits file judged by the exact referee
//! beside Embree, as `compare` judges a tracer.

use super::files::{HitsFile, RaysFile};
use super::recorded::Recorded;
use crate::backends::embree::EMBREE_ROBUST;
use crate::backends::{Backend, BackendName, BuildContext};
use crate::check::{Answer, Checked};
use crate::results::CompareSummary;
use crate::run::RunContext;
use crate::scene::Scene;
use crate::trace::Intersector;
use rayon::prelude::*;
use std::path::Path;

/// The answers of `backend` to every ray of `rays`, in order: closest hits,
/// or occlusion for a shadow set.
pub fn trace(backend: &dyn Backend, rays: &RaysFile) -> HitsFile {
    let any_hit = rays.set.is_any_hit();
    let answers = rays
        .rays
        .par_iter()
        .map(|ray| {
            if any_hit {
                Answer::Occluded(backend.occluded(ray))
            } else {
                Answer::Closest(backend.intersect(ray))
            }
        })
        .collect();
    HitsFile {
        set: rays.set,
        gives_uv: backend.answers().uv,
        answers,
    }
}

/// Judges `hits` (named `name` in the summary) against the rays of `rays`
/// on `scene`'s mesh: every answer on which it and Embree (MEDIUM,
/// ROBUST) differ, and 1% of the others, go to the referee.
pub fn judge(
    scene: &Scene,
    rays: &RaysFile,
    hits: &HitsFile,
    name: &str,
    build: BuildContext,
) -> anyhow::Result<CompareSummary> {
    anyhow::ensure!(
        hits.set == rays.set && hits.answers.len() == rays.rays.len(),
        "the hits file answers {} rays of the {} set, the rays file holds {} rays of the {} set",
        hits.answers.len(),
        hits.set.name(),
        rays.rays.len(),
        rays.set.name()
    );
    let triangles = scene.mesh.triangle_count();
    for (index, answer) in hits.answers.iter().enumerate() {
        if let Answer::Closest(Some(hit)) = answer {
            anyhow::ensure!(
                (hit.prim as usize) < triangles,
                "answer {index}: primID {} is beyond the mesh's {triangles} triangles",
                hit.prim
            );
        }
    }
    let recorded = Recorded::new(name, rays, hits)?;
    let embree = EMBREE_ROBUST.build(&scene.mesh, build)?;
    let checked = Checked::new(vec![&recorded, embree.as_ref()]);
    rays.rays.par_iter().for_each(|ray| {
        if rays.set.is_any_hit() {
            checked.occluded(ray);
        } else {
            checked.intersect(ray);
        }
    });
    Ok(CompareSummary::new(
        scene,
        0,
        vec![(rays.set, checked.into_log())],
    ))
}

/// `raycheck trace`: the rays file at `rays` on `scene` traced by
/// `backend` on the run's workers, its hits written to `out`.
pub fn trace_files(
    run: &RunContext,
    scene: &str,
    rays: &Path,
    backend: &BackendName,
    out: &Path,
) -> anyhow::Result<()> {
    let scene = crate::scene::load(scene)?;
    if let Some(program) = backend.program() {
        let command = super::program::prepare(program)?;
        super::program::runner::trace_file(program, &command, &scene.mesh, rays, out)?;
        return Ok(());
    }
    let rays = RaysFile::read(rays)?;
    let backend = backend.build(&scene.mesh, run.build_context())?;
    run.install(|| trace(backend.as_ref(), &rays)).write(out)?;
    Ok(())
}

/// `raycheck judge`: the hits file at `hits` for the rays file at `rays`
/// on `scene`, judged on the run's workers (see [`judge`]), named after
/// the hits file.
pub fn judge_files(
    run: &RunContext,
    scene: &str,
    rays: &Path,
    hits: &Path,
) -> anyhow::Result<CompareSummary> {
    let scene = crate::scene::load(scene)?;
    let rays_file = RaysFile::read(rays)?;
    let hits_file = HitsFile::read(hits)?;
    let name = hits
        .file_name()
        .map_or("hits".into(), |n| n.to_string_lossy());
    run.install(|| judge(&scene, &rays_file, &hits_file, &name, run.build_context()))
}
