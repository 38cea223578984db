//! `raycheck trace` and `raycheck judge`: a rays file (or every rays file
//! of a bundle) traced by any backend into hits files, and hits files
//! judged by the exact referee beside built-in backends, as `compare` and
//! `stability` judge a tracer.

use super::bundle::{Bundle, hits_path, is_bundle};
use super::files::{HitsFile, RaysFile};
use super::program::runner;
use super::recorded::Recorded;
use crate::backends::{Backend, BackendName, BuildContext};
use crate::check::{Answer, Checked};
use crate::results::{CompareSummary, Table, Verdicts, tally};
use crate::run::RunContext;
use crate::scene::Scene;
use crate::stability::harness::{ask, build_over};
use crate::trace::Intersector;
use indicatif::{ProgressBar, ProgressStyle};
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

/// Traces every rays file of `bundle` with `backend`, built over each
/// pair's mesh (or a program run on each pair's files), into the folder
/// `out` (created if need be), each hits file named as [`hits_path`] says.
/// Returns how many it wrote.
pub fn trace_bundle(
    bundle: &Bundle,
    backend: &BackendName,
    build: BuildContext,
    out: &Path,
) -> anyhow::Result<usize> {
    std::fs::create_dir_all(out)
        .map_err(|e| anyhow::anyhow!("{}: cannot create the folder: {e}", out.display()))?;
    let program = match backend.program() {
        Some(program) => Some((program, super::program::prepare(program)?)),
        None => None,
    };
    let mut written = 0;
    for (index, pair) in bundle.manifest.pairs.iter().enumerate() {
        let loaded = bundle.load(index)?;
        let files = [
            (&loaded.closest, &pair.closest),
            (&loaded.any_hit, &pair.any_hit),
        ];
        if let Some((program, command)) = &program {
            for (_, file) in files {
                let rays = bundle.dir.join(file);
                runner::trace_file(program, command, &loaded.mesh, &rays, &hits_path(out, file))?;
            }
        } else {
            let built = backend.build(&loaded.mesh, build)?;
            for (rays, file) in files {
                trace(built.as_ref(), rays).write(&hits_path(out, file))?;
            }
        }
        written += files.len();
    }
    Ok(written)
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
    build: BuildContext,
) -> anyhow::Result<CompareSummary> {
    hits.check_answers(rays, scene.mesh.triangle_count())?;
    let recorded = Recorded::new(name, &[(rays, hits)])?;
    let built = build_over(beside, &scene.mesh, build)?;
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
    build: BuildContext,
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
            hits.check_answers(rays, triangles)
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
        let built = build_over(beside, &loaded.mesh, build)?;
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
        let title = format!(
            "{} ({} form): {} pairs, {} rays, {} judged, {} ambiguous",
            self.case,
            self.form,
            self.pairs.len(),
            v.rays,
            v.judged,
            v.ambiguous
        );
        tally::catalogue_table(&title, v, caption)
    }
}

/// What `raycheck judge` judged: one hits file, or a bundle's folder of
/// them; its `--json`.
#[derive(Clone, Debug, Serialize)]
#[serde(untagged)]
pub enum Judged {
    File(CompareSummary),
    Bundle(BundleSummary),
}

impl Judged {
    /// The referee's verdicts, the hits first.
    pub fn verdicts(&self) -> &Verdicts {
        match self {
            Judged::File(summary) => &summary.verdicts,
            Judged::Bundle(summary) => &summary.verdicts,
        }
    }

    pub fn table(&self, caption: &str) -> Table {
        match self {
            Judged::File(summary) => summary.table(caption),
            Judged::Bundle(summary) => summary.table(caption),
        }
    }
}

/// The name a hits file or folder goes by in the verdicts: its own.
fn hits_name(path: &Path) -> String {
    path.file_name()
        .map_or("hits".into(), |n| n.to_string_lossy().into_owned())
}

/// `raycheck trace`: `inputs` are SCENE RAYS (the rays file traced by
/// `backend` over the scene's mesh, its hits written to `out`) or BUNDLE
/// (every rays file of the bundle traced, into the folder `out`), on the
/// run's workers. Returns what it wrote.
pub fn trace_files(
    run: &RunContext,
    inputs: &[String],
    backend: &BackendName,
    out: &Path,
) -> anyhow::Result<String> {
    match inputs {
        [folder] => {
            let bundle = Bundle::open(Path::new(folder))?;
            let written =
                run.install(|| trace_bundle(&bundle, backend, run.build_context(), out))?;
            Ok(format!("wrote {written} hits files into {}", out.display()))
        }
        [scene, rays] => {
            let scene = crate::scene::load(scene)?;
            let rays = Path::new(rays);
            if let Some(program) = backend.program() {
                let command = super::program::prepare(program)?;
                runner::trace_file(program, &command, &scene.mesh, rays, out)?;
            } else {
                let rays = RaysFile::read(rays)?;
                let backend = backend.build(&scene.mesh, run.build_context())?;
                run.install(|| trace(backend.as_ref(), &rays)).write(out)?;
            }
            Ok(format!("wrote {}", out.display()))
        }
        _ => anyhow::bail!("trace takes SCENE RAYS or a bundle's folder"),
    }
}

/// `raycheck judge`: `inputs` are SCENE RAYS HITS ([`judge`]) or BUNDLE
/// HITS ([`judge_bundle`]), judged on the run's workers beside `beside`,
/// the hits named after their file or folder.
pub fn judge_files(
    run: &RunContext,
    inputs: &[String],
    beside: &[BackendName],
) -> anyhow::Result<Judged> {
    if let Some(program) = beside.iter().find(|b| b.program().is_some()) {
        anyhow::bail!(
            "{program} is a program: judge takes built-in backends beside the hits; \
             write its hits with `raycheck trace --backend {program}` and judge those"
        );
    }
    let build = run.build_context();
    match inputs {
        [folder, hits] if is_bundle(Path::new(folder)) => {
            let bundle = Bundle::open(Path::new(folder))?;
            let hits = Path::new(hits);
            let summary =
                run.install(|| judge_bundle(&bundle, hits, &hits_name(hits), beside, build))?;
            Ok(Judged::Bundle(summary))
        }
        [scene, rays, hits] => {
            let scene = crate::scene::load(scene)?;
            let rays = RaysFile::read(Path::new(rays))?;
            let hits_path = Path::new(hits);
            let hits = HitsFile::read(hits_path)?;
            let name = hits_name(hits_path);
            let summary = run.install(|| judge(&scene, &rays, &hits, &name, beside, build))?;
            Ok(Judged::File(summary))
        }
        [folder, _] => anyhow::bail!(
            "{folder}: not a bundle (no {} in it); judge takes SCENE RAYS HITS or BUNDLE HITS",
            super::bundle::MANIFEST
        ),
        _ => anyhow::bail!("judge takes SCENE RAYS HITS or BUNDLE HITS"),
    }
}
