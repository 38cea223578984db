//! Checking renders of scenes with several mesh layers (a static mesh and
//! moving ones, see [`crate::render::motion_blur`]): each layer has its own
//! BVH, its own Embree scene and its own [`Checked`] pair, and each layer's
//! differences are judged against that layer's mesh.

use super::checked::{CheckLog, Checked, VerdictCounts};
use crate::backends::embree;
use crate::bvh::{BuildOptions, Bvh};
use crate::render::image::Image;
use crate::render::{RenderSettings, render_layers};
use crate::scene::Scene;
use raycheck_reference::{Device, EmbreeError, SceneOptions};

/// Our BVH of every layer of `scene`.
pub fn build_bvhs(scene: &Scene, options: &BuildOptions) -> Vec<Bvh> {
    scene
        .meshes()
        .into_iter()
        .map(|mesh| Bvh::build(mesh, options))
        .collect()
}

/// Embree's scene of every layer of `scene`.
pub fn build_embree_scenes(
    device: &Device,
    scene: &Scene,
    options: SceneOptions,
) -> Result<Vec<raycheck_reference::Scene>, EmbreeError> {
    scene
        .meshes()
        .into_iter()
        .map(|mesh| embree::build_scene(device, mesh, options))
        .collect()
}

/// A render through checked pairs, with what the check saw.
pub struct CheckedRender {
    /// Our render (the checked pair returns our answers).
    pub image: Image,
    /// One log per layer.
    pub logs: Vec<CheckLog>,
    /// The referee's verdicts over all layers.
    pub verdicts: VerdictCounts,
}

/// Renders `scene` asking both backends every query, layer by layer.
pub fn render_checked(
    scene: &Scene,
    ours: &[Bvh],
    reference: &[raycheck_reference::Scene],
    settings: &RenderSettings,
) -> CheckedRender {
    let pairs: Vec<_> = ours
        .iter()
        .zip(reference)
        .map(|(a, b)| Checked::new(a, b))
        .collect();
    let layers: Vec<&_> = pairs.iter().collect();
    let image = render_layers(scene, &layers, settings);
    let logs: Vec<CheckLog> = pairs.into_iter().map(Checked::into_log).collect();
    let verdicts = judge(scene, &logs);
    CheckedRender {
        image,
        logs,
        verdicts,
    }
}

/// The verdicts on every layer's differences, each judged on its own mesh.
pub fn judge(scene: &Scene, logs: &[CheckLog]) -> VerdictCounts {
    logs.iter()
        .zip(scene.meshes())
        .map(|(log, mesh)| VerdictCounts::tally(&log.differences, &log.judge(mesh)))
        .fold(VerdictCounts::default(), |a, b| VerdictCounts {
            ours_wrong: a.ours_wrong + b.ours_wrong,
            embree_wrong: a.embree_wrong + b.embree_wrong,
            ambiguous: a.ambiguous + b.ambiguous,
            ours_t_off: a.ours_t_off + b.ours_t_off,
            embree_t_off: a.embree_t_off + b.embree_t_off,
        })
}
