//! The passes a scene's render runs, derived from the features its manifest
//! lists: nothing the scene does not ask for is computed.

use crate::scene::{Feature, Scene};
use std::fmt;

/// Which parts of the shading run for a scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Passes {
    /// Phong shading from every light (otherwise surfaces show their
    /// diffuse colour).
    pub shading: bool,
    /// One shadow ray per light and shading point.
    pub hard_shadows: bool,
    /// Mirror reflection rays from materials with a mirror reflectance.
    pub reflection: bool,
}

impl Passes {
    pub fn for_scene(scene: &Scene) -> Self {
        let has = |f: Feature| scene.features.contains(&f);
        Self {
            shading: has(Feature::Shading),
            hard_shadows: has(Feature::HardShadows),
            reflection: has(Feature::Reflection),
        }
    }
}

impl fmt::Display for Passes {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let names = [
            (true, "primary rays (1 per pixel)"),
            (self.shading, "phong shading"),
            (
                self.hard_shadows,
                "hard shadows (1 occlusion ray per light)",
            ),
            (self.reflection, "mirror reflection"),
        ];
        let list: Vec<&str> = names
            .iter()
            .filter(|(on, _)| *on)
            .map(|(_, n)| *n)
            .collect();
        write!(f, "{}", list.join(", "))
    }
}
