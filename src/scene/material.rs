//! Surface materials: a Blinn-Phong diffuse + specular model with a mirror
//! term, opacity and an optional diffuse texture.

use super::texture::TextureFilter;
use glam::Vec3;
use std::path::PathBuf;

#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    pub name: String,
    /// Diffuse reflectance.
    pub kd: Vec3,
    /// Specular (highlight) reflectance.
    pub ks: Vec3,
    /// Phong exponent of the highlight.
    pub shininess: f32,
    /// Perfect-mirror reflectance; zero for a non-mirror.
    pub mirror: Vec3,
    /// Spread of the reflection around the mirror direction (`glossy`):
    /// 0 is a perfect mirror.
    pub roughness: f32,
    /// 1 is opaque, 0 fully transparent.
    pub opacity: f32,
    /// Image whose colour replaces `kd`, resolved to a path that exists.
    pub diffuse_texture: Option<PathBuf>,
    pub texture_filter: TextureFilter,
}

impl Default for Material {
    /// A plain grey diffuse surface.
    fn default() -> Self {
        Self {
            name: "default".to_string(),
            kd: Vec3::splat(0.7),
            ks: Vec3::ZERO,
            shininess: 1.0,
            mirror: Vec3::ZERO,
            roughness: 0.0,
            opacity: 1.0,
            diffuse_texture: None,
            texture_filter: TextureFilter::default(),
        }
    }
}

impl Material {
    /// The default material under another name.
    pub fn named(name: &str) -> Self {
        Self {
            name: name.to_string(),
            ..Self::default()
        }
    }
}
