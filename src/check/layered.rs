//! Scenes with several mesh layers (a static mesh and moving ones, see
//! [`crate::render::motion_blur`]): every backend is built per layer, and
//! a checked render keeps one [`Checked`] run per layer, so each layer's
//! records are judged against that layer's mesh.

use super::checked::{CheckLog, Checked};
use crate::backends::{Backend, BackendName, BuildContext};
use crate::bvh::BvhView;
use crate::render::debug::{DebugImage, DebugView, render_debug};
use crate::render::image::Image;
use crate::render::{RenderSettings, render_layers};
use crate::scene::Scene;

/// One backend over every layer of a scene.
pub struct LayeredBackend {
    pub name: BackendName,
    /// One per mesh layer, in [`Scene::meshes`] order.
    pub layers: Vec<Box<dyn Backend>>,
}

impl LayeredBackend {
    /// Builds `name` over every layer of `scene`.
    pub fn build(name: &BackendName, scene: &Scene, context: BuildContext) -> anyhow::Result<Self> {
        let layers = scene
            .meshes()
            .into_iter()
            .map(|mesh| name.build(mesh, context))
            .collect::<anyhow::Result<_>>()?;
        Ok(Self {
            name: name.clone(),
            layers,
        })
    }

    /// The layers as the renderer takes them.
    pub fn intersectors(&self) -> Vec<&dyn Backend> {
        self.layers.iter().map(|b| b.as_ref()).collect()
    }

    /// Renders `scene` through this backend.
    pub fn render(&self, scene: &Scene, settings: &RenderSettings) -> Image {
        render_layers(scene, &self.intersectors(), settings)
    }
}

/// The tree of every layer of `scene` as backend `name` builds it, where
/// the harness can read it (ours): what the debug views that read BVH
/// nodes draw, and an intersector of its own.
pub fn bvh_views(
    name: &BackendName,
    scene: &Scene,
) -> Option<anyhow::Result<Vec<Box<dyn BvhView>>>> {
    scene
        .meshes()
        .into_iter()
        .map(|mesh| name.bvh_view(mesh))
        .collect::<Option<Vec<_>>>()
        .map(|trees| trees.into_iter().collect())
}

/// Draws debug `view` of `scene` on backend `name`: on our trees
/// themselves for ours, so the views that read BVH nodes see the very tree
/// that traces; on the backend's layers for others, where those views are
/// refused with a message saying so.
pub fn render_debug_view(
    name: &BackendName,
    scene: &Scene,
    context: BuildContext,
    view: DebugView,
    settings: &RenderSettings,
) -> anyhow::Result<DebugImage> {
    match bvh_views(name, scene).transpose()? {
        Some(trees) => {
            let layers: Vec<&dyn BvhView> = trees.iter().map(|t| t.as_ref()).collect();
            render_debug(scene, &layers, Some(&layers), view, settings)
        }
        None => {
            let backend = LayeredBackend::build(name, scene, context)?;
            render_debug(scene, &backend.intersectors(), None, view, settings)
        }
    }
}

/// A render through every backend at once, with what the check saw.
pub struct CheckedRender {
    /// The first backend's render (the check returns its answers).
    pub image: Image,
    /// One log per layer.
    pub logs: Vec<CheckLog>,
}

/// Renders `scene` asking every backend every query, layer by layer; the
/// image is the first backend's.
///
/// # Panics
/// If `backends` is empty.
pub fn render_checked(
    scene: &Scene,
    backends: &[LayeredBackend],
    settings: &RenderSettings,
) -> CheckedRender {
    let checks: Vec<Checked> = (0..scene.meshes().len())
        .map(|layer| Checked::new(backends.iter().map(|b| b.layers[layer].as_ref()).collect()))
        .collect();
    let layers: Vec<&Checked> = checks.iter().collect();
    let image = render_layers(scene, &layers, settings);
    CheckedRender {
        image,
        logs: checks.into_iter().map(Checked::into_log).collect(),
    }
}
