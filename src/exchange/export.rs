//! `raycheck rays`: a ray set of a scene and the exact mesh it was made
//! for, or a stability case as a bundle of (mesh, rays) pairs, written to
//! files for another tracer.

use super::bundle;
use super::files::RaysFile;
use super::sets::{SetName, case_batches, merged, scene_rays};
use crate::run::RunContext;
use crate::scene;
use anyhow::Context;
use std::path::Path;

/// What to export.
pub struct ExportRequest<'a> {
    /// A scene name or mesh path; `None` for a stability case.
    pub scene: Option<&'a str>,
    /// `primary`, `shadow`, `reflection`, `diffuse` or a stability case.
    pub set: &'a str,
    /// Primary rays per side of the view (scene sets).
    pub resolution: u32,
    /// Where the rays go; for a stability case, the bundle's folder.
    pub out: &'a Path,
    /// Where the mesh goes, as binary PLY. For a stability case: every
    /// mesh merged into this one and every closest-hit ray into `out`,
    /// traced against all of it (another problem than the case's).
    pub mesh_out: Option<&'a Path>,
}

/// Writes the rays of `request` and, when asked, its mesh, on the run's
/// workers (a stability case's full form in a full run); returns a line
/// for each file written.
pub fn export(run: &RunContext, request: &ExportRequest) -> anyhow::Result<Vec<String>> {
    if let Some(path) = request.mesh_out {
        anyhow::ensure!(
            path.extension().is_some_and(|e| e == "ply"),
            "{}: the mesh is written as PLY; name it .ply",
            path.display()
        );
    }
    let exported = match (request.set.parse::<SetName>()?, request.scene) {
        (SetName::Scene(set), Some(scene)) => {
            run.install(|| scene_rays(&scene::load(scene)?, set, request.resolution))?
        }
        (SetName::Scene(set), None) => anyhow::bail!("the {} set needs a scene", set.name()),
        (SetName::Case(case), None) => {
            let full = run.form().is_full();
            let batches = run.install(|| case_batches(case, run.build_context(), full))?;
            if request.mesh_out.is_none() {
                let manifest = bundle::write(request.out, case, full, &batches)?;
                return Ok(vec![format!(
                    "wrote {} ({} pairs of stability case {case}, as it judges them)",
                    request.out.display(),
                    manifest.pairs.len()
                )]);
            }
            merged(case, full, &batches)
        }
        (SetName::Case(case), Some(_)) => {
            anyhow::bail!("stability case {case} brings its own meshes: give no scene")
        }
    };
    RaysFile {
        set: exported.set,
        rays: exported.rays,
    }
    .write(request.out)?;
    let mut written = vec![format!(
        "wrote {} ({})",
        request.out.display(),
        exported.note
    )];
    if let Some(path) = request.mesh_out {
        let bytes = super::ply::to_bytes(&exported.mesh, &[exported.note]);
        std::fs::write(path, bytes).with_context(|| format!("writing {}", path.display()))?;
        written.push(format!("wrote {}", path.display()));
    }
    Ok(written)
}
