//! The rays `raycheck rays` writes: a scene's primary, shadow, reflection
//! or diffuse rays (the very rays `perf` times), or a stability case's
//! rays, with the mesh they were made for.

use crate::backends::BuildContext;
use crate::backends::ours::OURS;
use crate::check::RaySet;
use crate::geometry::{Ray, TriangleMesh};
use crate::perf::rays::RaySets;
use crate::scene::Scene;
use crate::stability::{self, Batch, CASES, Context, Recorder};

/// What `--set` names: one of a scene's sets, or a stability case.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SetName {
    Scene(RaySet),
    /// The full name of a stability case.
    Case(&'static str),
}

impl std::str::FromStr for SetName {
    type Err = anyhow::Error;

    fn from_str(text: &str) -> anyhow::Result<Self> {
        Ok(match text {
            "primary" => SetName::Scene(RaySet::Primary),
            "shadow" => SetName::Scene(RaySet::Shadow),
            "reflection" => SetName::Scene(RaySet::Reflection),
            "diffuse" => SetName::Scene(RaySet::Diffuse),
            _ => {
                let cases: Vec<&str> = CASES.iter().map(|(name, _)| *name).collect();
                let matching: Vec<&&str> = cases.iter().filter(|n| n.contains(text)).collect();
                match matching.as_slice() {
                    [one] => SetName::Case(one),
                    _ => anyhow::bail!(
                        "unknown ray set '{text}': expected primary, shadow, reflection, diffuse \
                         or one stability case of: {}",
                        cases.join(", ")
                    ),
                }
            }
        })
    }
}

/// Rays and the one mesh they are traced against.
pub struct Exported {
    pub set: RaySet,
    pub mesh: TriangleMesh,
    pub rays: Vec<Ray>,
    /// How the mesh's primIDs map to what it was made from.
    pub note: String,
}

/// The rays of `set` of `scene` at `resolution`² primary rays: the rays
/// `perf` traces (its cached sets), with the reflection rays beside them.
/// Scenes with moving meshes cannot be exported: their rays meet a mesh
/// that depends on the ray's time.
pub fn scene_rays(scene: &Scene, set: RaySet, resolution: u32) -> anyhow::Result<Exported> {
    anyhow::ensure!(
        scene.moving.is_empty(),
        "{} has moving meshes: its rays meet a mesh that depends on each ray's time, \
         which a rays file and one mesh cannot express, so it cannot be exported",
        scene.name
    );
    let sets = RaySets::cached(scene, resolution);
    let rays = match set {
        RaySet::Primary => sets.primary,
        RaySet::Shadow => sets.shadow,
        RaySet::Reflection => sets.reflection,
        RaySet::Diffuse => sets.diffuse,
        RaySet::StabilityCase | RaySet::StabilityCaseAnyHit => {
            anyhow::bail!("a scene has no stability case rays")
        }
    };
    Ok(Exported {
        set,
        mesh: scene.mesh.clone(),
        rays,
        note: format!(
            "{} rays of {}, {resolution}x{resolution} primary rays; face i is primID i",
            set.name(),
            scene.name
        ),
    })
}

/// The batches stability case `name` judges (its quick form unless
/// `full`), each a mesh and the rays asked of it, in the order judged,
/// recorded from a run with our tracer. Meshes with NaN or infinite
/// vertices (`nan_and_inf`) cannot be exported: the mesh loaders refuse
/// them as bad input.
pub fn case_batches(name: &str, build: BuildContext, full: bool) -> anyhow::Result<Vec<Batch>> {
    let recorder = Recorder::default();
    let context = Context {
        backends: &[OURS],
        build,
        quick: !full,
        recorder: Some(&recorder),
    };
    let result = stability::run_catalogue(&context, Some(name))
        .into_iter()
        .find(|r| r.name == name)
        .ok_or_else(|| anyhow::anyhow!("no stability case named {name}"))?;
    if let Some(failure) = result.failure {
        anyhow::bail!("stability case {name} failed: {failure}");
    }
    let batches = recorder.into_batches();
    anyhow::ensure!(
        batches
            .iter()
            .all(|b| b.mesh.positions.iter().all(|p| p.is_finite())),
        "stability case {name} has vertices with NaN or infinite coordinates, which \
         the mesh loaders refuse as bad input, so it cannot be exported"
    );
    Ok(batches)
}

/// A case's batches merged into one problem: every mesh one after
/// another in one mesh (face `offset_k + j` is triangle `j` of batch `k`)
/// and every closest-hit ray traced against the whole of it. Nested and
/// overlapping placements then meet each other's rays, so this is not the
/// problem the case judges (a bundle is, [`super::bundle`]); it stays as
/// a scene of its own: nested, nearly coincident geometry at extreme
/// scales, on which the referee's cost must stay bounded.
pub fn merged(name: &str, full: bool, batches: &[Batch]) -> Exported {
    let mut mesh = TriangleMesh::default();
    let mut rays = Vec::new();
    let mut offsets = Vec::new();
    for batch in batches {
        offsets.push(mesh.triangle_count().to_string());
        mesh.append(&batch.mesh, 0);
        rays.extend_from_slice(&batch.closest);
    }
    Exported {
        set: RaySet::StabilityCase,
        mesh,
        rays,
        note: format!(
            "rays of stability case {name} ({} form), merged into one problem: its {} meshes \
             in the order judged, starting at primIDs {}",
            if full { "full" } else { "quick" },
            batches.len(),
            offsets.join(", ")
        ),
    }
}
