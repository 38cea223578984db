//! Scenes with several mesh layers (a static mesh and moving ones, see
//! [`crate::render::motion_blur`]): every backend is built per layer, and
//! a checked render keeps one [`Checked`] run per layer, so each layer's
//! records are judged against that layer's mesh.

use super::checked::{CheckLog, Checked};
use crate::backends::{Backend, BackendName};
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
