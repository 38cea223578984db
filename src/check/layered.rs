//! Scenes with several mesh layers (a static mesh and moving ones, see
//! [`crate::render::motion_blur`]): every backend is built per layer, and
//! a checked render keeps one [`Checked`] run per layer, so each layer's
//! records are judged against that layer's mesh.

use super::checked::{CheckLog, Checked};
use crate::backends::{Backend, BackendName, OurBuilder};
use crate::bvh::wide::WideBvh;
use crate::bvh::{Bvh, BvhView};
use crate::render::debug::{DebugImage, DebugView, render_debug};
use crate::render::image::Image;
use crate::render::{RenderSettings, render_layers};
use crate::scene::Scene;
use raycheck_reference::Device;

/// One backend over every layer of a scene.
pub struct LayeredBackend {
    pub name: BackendName,
    /// One per mesh layer, in [`Scene::meshes`] order.
    pub layers: Vec<Box<dyn Backend>>,
}

impl LayeredBackend {
    /// Builds `name` over every layer of `scene`.
    pub fn build(name: BackendName, scene: &Scene, device: &Device) -> anyhow::Result<Self> {
        let layers = scene
            .meshes()
            .into_iter()
            .map(|mesh| name.build(mesh, device))
            .collect::<anyhow::Result<_>>()?;
        Ok(Self { name, layers })
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

/// Our tree of every layer of `scene`, built by `builder`: what the debug
/// views that read BVH nodes draw, and an intersector of its own.
pub fn our_trees(builder: OurBuilder, scene: &Scene) -> Vec<Box<dyn BvhView>> {
    scene
        .meshes()
        .into_iter()
        .map(|mesh| -> Box<dyn BvhView> {
            match builder.binary_options() {
                None => Box::new(WideBvh::build(mesh)),
                Some(options) => Box::new(Bvh::build(mesh, &options)),
            }
        })
        .collect()
}

/// Draws debug `view` of `scene` on backend `name`: on our trees
/// themselves for ours, so the views that read BVH nodes see the very tree
/// that traces; on the backend's layers for others, where those views are
/// refused with a message saying so.
pub fn render_debug_view(
    name: BackendName,
    scene: &Scene,
    device: &Device,
    view: DebugView,
    settings: &RenderSettings,
) -> anyhow::Result<DebugImage> {
    match name {
        BackendName::Ours(builder) => {
            let trees = our_trees(builder, scene);
            let layers: Vec<&dyn BvhView> = trees.iter().map(|t| t.as_ref()).collect();
            render_debug(scene, &layers, Some(&layers), view, settings)
        }
        other => {
            let backend = LayeredBackend::build(other, scene, device)?;
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
