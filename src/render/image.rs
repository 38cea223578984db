//! Linear RGB images and their files: PNG (sRGB, 8 bit) for viewing, EXR
//! (linear, 32-bit float) for the values themselves.

use anyhow::Context;
use glam::Vec3;
use std::path::Path;

/// A linear-light RGB image, rows top to bottom.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<Vec3>,
}

impl Image {
    pub fn new(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            pixels: vec![Vec3::ZERO; width as usize * height as usize],
        }
    }

    pub fn get(&self, x: u32, y: u32) -> Vec3 {
        self.pixels[(y * self.width + x) as usize]
    }

    /// 8-bit sRGB bytes (clamped to [0, 1], IEC 61966-2-1 transfer curve).
    pub fn to_srgb8(&self) -> Vec<u8> {
        self.pixels
            .iter()
            .flat_map(|p| p.to_array().map(encode_srgb))
            .collect()
    }

    /// Writes a PNG or an EXR, chosen by the file's extension.
    pub fn save(&self, path: &Path) -> anyhow::Result<()> {
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
        match ext.to_ascii_lowercase().as_str() {
            "png" => self.save_png(path),
            "exr" => self.save_exr(path),
            _ => anyhow::bail!("{}: unknown image type (use .png or .exr)", path.display()),
        }
    }

    pub fn save_png(&self, path: &Path) -> anyhow::Result<()> {
        image::save_buffer(
            path,
            &self.to_srgb8(),
            self.width,
            self.height,
            image::ExtendedColorType::Rgb8,
        )
        .with_context(|| format!("writing {}", path.display()))
    }

    pub fn save_exr(&self, path: &Path) -> anyhow::Result<()> {
        exr::prelude::write_rgb_file(path, self.width as usize, self.height as usize, |x, y| {
            let p = self.get(x as u32, y as u32);
            (p.x, p.y, p.z)
        })
        .with_context(|| format!("writing {}", path.display()))
    }
}

fn encode_srgb(linear: f32) -> u8 {
    let c = linear.clamp(0.0, 1.0);
    let encoded = if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (encoded * 255.0 + 0.5) as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_endpoints_and_midpoint() {
        assert_eq!(encode_srgb(0.0), 0);
        assert_eq!(encode_srgb(1.0), 255);
        assert_eq!(encode_srgb(2.0), 255);
        assert_eq!(encode_srgb(-1.0), 0);
        // 18% grey encodes to about 118 in sRGB.
        assert_eq!(encode_srgb(0.18), 118);
    }

    #[test]
    fn exr_round_trips_linear_values() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.exr");
        let mut img = Image::new(3, 2);
        img.pixels[4] = Vec3::new(2.5, 0.125, 7.0);
        img.save(&path).unwrap();
        let read = exr::prelude::read_first_rgba_layer_from_file(
            &path,
            |res, _| vec![Vec3::ZERO; res.width() * res.height()],
            |px: &mut Vec<Vec3>, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
                px[pos.y() * 3 + pos.x()] = Vec3::new(r, g, b)
            },
        )
        .unwrap();
        assert_eq!(read.layer_data.channel_data.pixels, img.pixels);
    }
}
