//! The rays `raycheck rays` writes: a scene's primary, shadow, reflection
//! or diffuse rays (the very rays `perf` times), or a stability case's
//! rays, with the mesh they were made for.

use crate::backends::BuildContext;
use crate::backends::ours::OURS;
use crate::check::RaySet;
use crate::geometry::{Ray, TriangleMesh};
use crate::perf::rays::RaySets;
use crate::scene::Scene;
use crate::stability::{self, CASES, Context, Recorder};

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
        RaySet::StabilityCase => anyhow::bail!("a scene has no stability case rays"),
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

/// The rays stability case `name` judges (its quick form unless `full`),
/// with its meshes in one: the mesh of each trial in the order the case
/// judged them, so that face `offset_k + j` is triangle `j` of trial `k`.
/// Every ray is traced against the whole mesh.
pub fn case_rays(name: &str, build: BuildContext, full: bool) -> anyhow::Result<Exported> {
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
    let trials = recorder
        .into_inner()
        .unwrap_or_else(|poisoned| poisoned.into_inner());
    let mut mesh = TriangleMesh::default();
    let mut rays = Vec::new();
    let mut offsets = Vec::new();
    for (trial, trial_rays) in &trials {
        anyhow::ensure!(
            trial.positions.iter().all(|p| p.is_finite()),
            "stability case {name} has vertices with NaN or infinite coordinates, which \
             the mesh loaders refuse as bad input, so it cannot be exported"
        );
        offsets.push(mesh.triangle_count());
        mesh.append(trial, 0);
        rays.extend_from_slice(trial_rays);
    }
    let offsets: Vec<String> = offsets.iter().map(|o| o.to_string()).collect();
    Ok(Exported {
        set: RaySet::StabilityCase,
        mesh,
        rays,
        note: format!(
            "rays of stability case {name} ({} form); its {} meshes in the order judged, \
             starting at primIDs {}",
            if full { "full" } else { "quick" },
            trials.len(),
            offsets.join(", ")
        ),
    })
}
