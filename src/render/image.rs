//! Linear RGB images and their files: PNG (sRGB, 8 bit) for viewing, EXR
//! (linear, 32-bit float) for the values themselves.

use crate::jobs::one_job_each;
use anyhow::Context;
use glam::Vec3;
use rayon::prelude::*;
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

    /// The image whose pixel (x, y) is `shade(x, y)`, rows in parallel.
    pub fn par_from_fn(width: u32, height: u32, shade: impl Fn(u32, u32) -> Vec3 + Sync) -> Self {
        Self::par_from_rows(width, height, |y, row| {
            for (x, pixel) in row.iter_mut().enumerate() {
                *pixel = shade(x as u32, y);
            }
        })
    }

    /// The image whose row `y` is written by `fill(y, row)`, rows in
    /// parallel.
    pub fn par_from_rows(width: u32, height: u32, fill: impl Fn(u32, &mut [Vec3]) + Sync) -> Self {
        let mut image = Self::new(width, height);
        one_job_each(image.pixels.par_chunks_mut(width as usize))
            .enumerate()
            .for_each(|(y, row)| fill(y as u32, row));
        image
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
        self.save_stamped(path, &[])
    }

    /// Writes a PNG or an EXR carrying `stamp` (key, text) pairs: PNG
    /// (UTF-8 `iTXt`) chunks, EXR header text attributes. The report stamps every figure
    /// with the machine, date, commit and thread count this way, so an image
    /// says where it came from even apart from its page.
    pub fn save_stamped(&self, path: &Path, stamp: &[(&str, String)]) -> anyhow::Result<()> {
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
        let result = match ext.to_ascii_lowercase().as_str() {
            "png" => self.write_png(path, stamp),
            "exr" => self.write_exr(path, stamp),
            _ => anyhow::bail!("{}: unknown image type (use .png or .exr)", path.display()),
        };
        result.with_context(|| format!("writing {}", path.display()))
    }

    fn write_png(&self, path: &Path, stamp: &[(&str, String)]) -> anyhow::Result<()> {
        let file = std::io::BufWriter::new(std::fs::File::create(path)?);
        let mut encoder = png::Encoder::new(file, self.width, self.height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
        for (key, text) in stamp {
            encoder.add_itxt_chunk(key.to_string(), text.clone())?;
        }
        let mut writer = encoder.write_header()?;
        writer.write_image_data(&self.to_srgb8())?;
        writer.finish()?;
        Ok(())
    }

    fn write_exr(&self, path: &Path, stamp: &[(&str, String)]) -> anyhow::Result<()> {
        use exr::prelude::*;
        let channels = SpecificChannels::rgb(|pos: Vec2<usize>| {
            let p = self.get(pos.x() as u32, pos.y() as u32);
            (p.x, p.y, p.z)
        });
        let mut attributes = LayerAttributes::default();
        for (key, text) in stamp {
            attributes.other.insert(
                Text::from(*key),
                AttributeValue::Text(Text::from(text.as_str())),
            );
        }
        let size = (self.width as usize, self.height as usize);
        let layer = Layer::new(size, attributes, Encoding::FAST_LOSSLESS, channels);
        Image::from_layer(layer).write().to_file(path)?;
        Ok(())
    }
}

/// The linear value whose 8-bit sRGB encoding shows `display` (in [0, 1]):
/// debug views pick display colours and store them through this.
pub fn decode_srgb(display: f32) -> f32 {
    let c = display.clamp(0.0, 1.0);
    if c <= 0.040_45 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
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
    fn decoding_inverts_the_8_bit_encoding() {
        for byte in 0..=255u8 {
            let display = byte as f32 / 255.0;
            assert_eq!(encode_srgb(decode_srgb(display)), byte);
        }
    }

    #[test]
    fn png_carries_its_stamp() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.png");
        let stamp = [("Comment", "machine X · commit abc".to_string())];
        Image::new(2, 2).save_stamped(&path, &stamp).unwrap();
        let decoder =
            png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&path).unwrap()));
        let reader = decoder.read_info().unwrap();
        let texts = &reader.info().utf8_text;
        assert_eq!(texts.len(), 1);
        assert_eq!(texts[0].keyword, "Comment");
        assert_eq!(texts[0].get_text().unwrap(), "machine X · commit abc");
    }

    #[test]
    fn exr_round_trips_linear_values() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.exr");
        let mut img = Image::new(3, 2);
        img.pixels[4] = Vec3::new(2.5, 0.125, 7.0);
        img.save_stamped(&path, &[("Comment", "commit abc".to_string())])
            .unwrap();
        let read = exr::prelude::read_first_rgba_layer_from_file(
            &path,
            |res, _| vec![Vec3::ZERO; res.width() * res.height()],
            |px: &mut Vec<Vec3>, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
                px[pos.y() * 3 + pos.x()] = Vec3::new(r, g, b)
            },
        )
        .unwrap();
        assert_eq!(read.layer_data.channel_data.pixels, img.pixels);
        let key = exr::meta::attribute::Text::from("Comment");
        let comment = read.layer_data.attributes.other.get(&key);
        assert_eq!(
            comment,
            Some(&exr::meta::attribute::AttributeValue::Text(
                "commit abc".into()
            ))
        );
    }
}
