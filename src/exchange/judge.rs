//! `raycheck trace` and `raycheck judge`: a rays file (or every rays file
//! of a bundle) traced by any backend into hits files, and hits files
//! judged by the exact referee beside built-in backends, as `compare` and
//! `stability` judge a tracer.

use super::bundle::{Bundle, hits_path};
use super::files::{HitsFile, RaysFile};
use super::recorded::Recorded;
use crate::backends::{Backend, BackendName};
use crate::check::{Answer, Checked};
use crate::results::{Cell, CompareSummary, Table, Verdicts};
use crate::scene::Scene;
use crate::stability::harness::{ask, build_over};
use crate::trace::Intersector;
use indicatif::{ProgressBar, ProgressStyle};
use raycheck_reference::Device;
use rayon::prelude::*;
use serde::Serialize;
use std::path::Path;

/// The answers of `backend` to every ray of `rays`, in order: closest hits,
/// or occlusion for an any-hit set.
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

/// Traces every rays file of `bundle` with `name`, built over each pair's
/// mesh, into the folder `out` (created if need be), each hits file named
/// as [`hits_path`] says. Returns how many it wrote.
pub fn trace_bundle(
    bundle: &Bundle,
    name: BackendName,
    device: &Device,
    out: &Path,
) -> anyhow::Result<usize> {
    std::fs::create_dir_all(out)
        .map_err(|e| anyhow::anyhow!("{}: cannot create the folder: {e}", out.display()))?;
    let mut written = 0;
    for (index, pair) in bundle.manifest.pairs.iter().enumerate() {
        let loaded = bundle.load(index)?;
        let backend = name.build(&loaded.mesh, device)?;
        for (rays, file) in [
            (&loaded.closest, &pair.closest),
            (&loaded.any_hit, &pair.any_hit),
        ] {
            trace(backend.as_ref(), rays).write(&hits_path(out, file))?;
            written += 1;
        }
    }
    Ok(written)
}

/// Checks that `hits` answers every ray of `rays`, of the same set, with
/// primIDs of the mesh's `triangles`.
fn check_answers(rays: &RaysFile, hits: &HitsFile, triangles: usize) -> anyhow::Result<()> {
    anyhow::ensure!(
        hits.set == rays.set && hits.answers.len() == rays.rays.len(),
        "the hits file answers {} rays of the {} set, the rays file holds {} rays of the {} set",
        hits.answers.len(),
        hits.set.name(),
        rays.rays.len(),
        rays.set.name()
    );
    for (index, answer) in hits.answers.iter().enumerate() {
        if let Answer::Closest(Some(hit)) = answer {
            anyhow::ensure!(
                (hit.prim as usize) < triangles,
                "answer {index}: primID {} is beyond the mesh's {triangles} triangles",
                hit.prim
            );
        }
    }
    Ok(())
}

/// A progress bar over `records` answers to judge, with the rate; drawn
/// on a terminal only.
fn judging_bar(records: u64) -> anyhow::Result<ProgressBar> {
    let bar = ProgressBar::new(records);
    bar.set_style(
        ProgressStyle::with_template(
            "{elapsed:>4} [{bar:30}] {pos}/{len} rays judged, {per_sec}, {eta} to go",
        )?
        .progress_chars("=> "),
    );
    Ok(bar)
}

/// Judges `hits` (named `name` in the summary) against the rays of `rays`
/// on `scene`'s mesh, beside the backends of `beside`: every answer on
/// which two of them differ, and 1% of the others, go to the referee.
pub fn judge(
    scene: &Scene,
    rays: &RaysFile,
    hits: &HitsFile,
    name: &str,
    beside: &[BackendName],
    device: &Device,
) -> anyhow::Result<CompareSummary> {
    check_answers(rays, hits, scene.mesh.triangle_count())?;
    let recorded = Recorded::new(name, &[(rays, hits)])?;
    let built = beside
        .iter()
        .map(|b| b.build(&scene.mesh, device))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let backends: Vec<&dyn Backend> = std::iter::once(&recorded as &dyn Backend)
        .chain(built.iter().map(|b| b.as_ref()))
        .collect();
    let checked = Checked::new(backends);
    rays.rays.par_iter().for_each(|ray| {
        if rays.set.is_any_hit() {
            checked.occluded(ray);
        } else {
            checked.intersect(ray);
        }
    });
    let log = checked.into_log();
    let bar = judging_bar(log.records.len() as u64)?;
    let judgements = log.judge_reporting(&scene.mesh, &|| bar.inc(1));
    bar.finish_and_clear();
    Ok(CompareSummary::from_judged(
        scene,
        0,
        vec![(rays.set, log)],
        vec![judgements],
    ))
}

/// What `judge` found over a bundle; its `--json`.
#[derive(Clone, Debug, Serialize)]
pub struct BundleSummary {
    pub case: String,
    /// `quick` or `full`.
    pub form: String,
    /// The hits' name, then the backends judged beside them.
    pub backends: Vec<String>,
    /// Summed over the pairs, counted as the case counts them in process.
    pub verdicts: Verdicts,
    /// Each pair's own, in the manifest's order.
    pub pairs: Vec<PairVerdicts>,
}

/// One pair's verdicts.
#[derive(Clone, Debug, Serialize)]
pub struct PairVerdicts {
    pub mesh: String,
    pub closest: String,
    pub verdicts: Verdicts,
}

/// Judges the hits in `hits_dir` (named `name`) of every pair of
/// `bundle`, beside the backends of `beside` built over each pair's mesh,
/// exactly as the stability harness judges the case's batches: both
/// queries, leaks where the rays had to hit, a build failure where a
/// third-party backend cannot be built over a mesh.
pub fn judge_bundle(
    bundle: &Bundle,
    hits_dir: &Path,
    name: &str,
    beside: &[BackendName],
    device: &Device,
) -> anyhow::Result<BundleSummary> {
    let names: Vec<String> = std::iter::once(name.to_string())
        .chain(beside.iter().map(|b| b.to_string()))
        .collect();
    let mut asked = Vec::new();
    for (index, pair) in bundle.manifest.pairs.iter().enumerate() {
        let loaded = bundle.load(index)?;
        let triangles = loaded.mesh.triangle_count();
        let read = |rays: &RaysFile, file: &str| -> anyhow::Result<HitsFile> {
            let path = hits_path(hits_dir, file);
            let hits = HitsFile::read(&path)?;
            check_answers(rays, &hits, triangles)
                .map_err(|e| anyhow::anyhow!("{}: {e:#}", path.display()))?;
            Ok(hits)
        };
        let closest = read(&loaded.closest, &pair.closest)?;
        let any_hit = read(&loaded.any_hit, &pair.any_hit)?;
        let recorded = Recorded::new(
            name,
            &[(&loaded.closest, &closest), (&loaded.any_hit, &any_hit)],
        )
        .map_err(|e| anyhow::anyhow!("{}: {e:#}", hits_path(hits_dir, &pair.closest).display()))?;
        let built = build_over(beside, &loaded.mesh, device)?;
        let backends: Vec<&dyn Backend> = std::iter::once(&recorded as &dyn Backend)
            .chain(built.iter().map(|b| b.as_ref()))
            .collect();
        let queries = ask(
            &backends,
            &loaded.mesh,
            &loaded.closest.rays,
            &loaded.any_hit.rays,
            loaded.must_hit,
        );
        asked.push((loaded.mesh, queries));
    }
    let records = asked.iter().map(|(_, a)| a.log.records.len() as u64).sum();
    let bar = judging_bar(records)?;
    let mut verdicts = Verdicts::default();
    let mut pairs = Vec::new();
    for ((mesh, queries), pair) in asked.iter().zip(&bundle.manifest.pairs) {
        let pair_verdicts = queries.judge(mesh, &names, &|| bar.inc(1));
        verdicts += &pair_verdicts;
        pairs.push(PairVerdicts {
            mesh: pair.mesh.clone(),
            closest: pair.closest.clone(),
            verdicts: pair_verdicts,
        });
    }
    bar.finish_and_clear();
    Ok(BundleSummary {
        case: bundle.manifest.case.clone(),
        form: bundle.manifest.form.clone(),
        backends: names,
        verdicts,
        pairs,
    })
}

impl BundleSummary {
    /// One row per backend: the referee's verdicts over every pair.
    pub fn table(&self, caption: &str) -> Table {
        let v = &self.verdicts;
        let mut table = Table::new(
            &format!(
                "{} ({} form): {} pairs, {} rays, {} judged, {} ambiguous",
                self.case,
                self.form,
                self.pairs.len(),
                v.rays,
                v.judged,
                v.ambiguous
            ),
            &[
                "backend",
                "wrong",
                "undecided",
                "t off",
                "NaN outputs",
                "misses",
                "leaks",
                "meshes it could not build over",
            ],
            caption,
        );
        for b in &v.backends {
            table.push([
                Cell::from(b.name.as_str()),
                Cell::wrong_count(b.wrong),
                Cell::undecided_count(b.undecided),
                Cell::wrong_count(b.t_off),
                Cell::wrong_count(b.nan_outputs),
                b.misses.to_string().into(),
                Cell::wrong_count(b.leaks),
                Cell::wrong_count(b.build_failures),
            ]);
        }
        table
    }
}
