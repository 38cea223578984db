//! Diffuse texture images, decoded once when a textured scene is loaded.

use super::error::SceneError;
use glam::Vec3;
use serde::Deserialize;
use std::path::Path;

/// How a texture is sampled between its texels.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TextureFilter {
    /// The texel the point falls in.
    Nearest,
    /// The four nearest texel centres, weighted by distance.
    #[default]
    Bilinear,
}

/// A decoded image in linear RGB, rows top to bottom.
#[derive(Clone, Debug, PartialEq)]
pub struct TextureImage {
    pub width: u32,
    pub height: u32,
    pub texels: Vec<Vec3>,
}

impl TextureImage {
    /// Decodes an image file (PNG); 8-bit values are sRGB-encoded.
    pub fn load(path: &Path) -> Result<Self, SceneError> {
        let decoded = image::open(path)
            .map_err(|e| SceneError::in_file(path, format!("cannot decode texture: {e}")))?
            .to_rgb8();
        let (width, height) = decoded.dimensions();
        if width == 0 || height == 0 {
            return Err(SceneError::in_file(path, "texture has no pixels"));
        }
        let texels = decoded
            .pixels()
            .map(|p| Vec3::from_array(p.0.map(decode_srgb)))
            .collect();
        Ok(Self {
            width,
            height,
            texels,
        })
    }

    /// The texel at column `x`, row `y` (row 0 at the top).
    pub fn texel(&self, x: u32, y: u32) -> Vec3 {
        self.texels[(y * self.width + x) as usize]
    }
}

/// The IEC 61966-2-1 sRGB decoding curve.
fn decode_srgb(value: u8) -> f32 {
    let c = value as f32 / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decodes_png_to_linear_and_reports_bad_files() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.png");
        image::save_buffer(
            &path,
            &[255, 0, 0, 0, 0, 0],
            2,
            1,
            image::ExtendedColorType::Rgb8,
        )
        .unwrap();
        let t = TextureImage::load(&path).unwrap();
        assert_eq!((t.width, t.height), (2, 1));
        assert_eq!(t.texel(0, 0), Vec3::X);
        assert_eq!(t.texel(1, 0), Vec3::ZERO);
        assert_eq!(decode_srgb(118), 0.18116423);
        std::fs::write(&path, b"not a png").unwrap();
        let err = TextureImage::load(&path).unwrap_err().to_string();
        assert!(err.contains("t.png: cannot decode texture"), "{err}");
    }
}
