//! Converged references, rendered once and cached on disk.
//!
//! A reference is rendered as two independent halves A and B (same sample
//! count, different seeds) and is their mean R = (A + B)/2. Their
//! difference tells how far R itself is from converged: per pixel
//! Var(R) = Var(A)/2 = E[(A − B)²]/4, and A − R = (A − B)/2, so
//! `rel_mse(A, R)` estimates R's own relMSE. A swept render measured
//! against R has the expected relMSE of the render plus R's, so R must
//! be well below the smallest error swept.
//!
//! The cache key holds everything that determines the image: the scene's
//! content, the render settings of both halves, the sample count, the
//! file format and [`RENDER_VERSION`], so a changed scene or renderer
//! renders its reference again instead of reading a stale one.

use super::metrics::rel_mse;
use crate::check::layered::LayeredBackend;
use crate::render::image::Image;
use crate::render::sampling::Sampler;
use crate::render::{RENDER_VERSION, RenderSettings};
use crate::scene::{Scene, assets};
use anyhow::Context;
use glam::Vec3;
use serde::Serialize;
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// How the halves' samples are placed: stratified, the sweep's better
/// sampler, so the reference converges at least as fast as any render it
/// is compared with.
pub const SAMPLER: Sampler = Sampler::Stratified;

/// The seeds of the two halves: far from the sweep's seeds 0, 1, 2, …
pub const HALF_SEEDS: [u64; 2] = [0x5EED_0000_0000_000A, 0x5EED_0000_0000_000B];

/// Bumped whenever the file layout changes.
const FORMAT_VERSION: u32 = 1;
const MAGIC: &[u8; 8] = b"RCSWEEPR";

/// A converged image and how well converged it is.
#[derive(Clone, Debug)]
pub struct Reference {
    /// The mean of the two halves.
    pub image: Image,
    pub summary: ReferenceSummary,
}

/// What the sweep reports of a reference.
#[derive(Clone, Debug, Serialize)]
pub struct ReferenceSummary {
    /// Samples of the swept count per pixel, both halves together.
    pub samples: u32,
    /// The reference's own relMSE, estimated from its two halves.
    pub rel_mse: f64,
    /// Wall time of rendering both halves, whenever they were rendered.
    pub seconds: f64,
    /// Whether this run read it from the cache rather than rendering it.
    pub cached: bool,
    /// Where it is cached.
    pub file: PathBuf,
}

/// The folder references are cached in: `sweep/` in the asset cache.
pub fn cache_folder() -> anyhow::Result<PathBuf> {
    Ok(assets::cache_dir()
        .map_err(anyhow::Error::msg)?
        .join("sweep"))
}

/// Renders the two halves of `scene` through `backend`, or reads them from
/// `folder`; `configure` gives the scene and settings of the half with a
/// seed, with `samples_per_half` of the swept count.
///
/// # Errors
/// The folder or the file cannot be written.
pub fn reference(
    scene: &Scene,
    backend: &LayeredBackend,
    folder: &Path,
    samples_per_half: u32,
    configure: &dyn Fn(u64) -> (Scene, RenderSettings),
) -> anyhow::Result<Reference> {
    let halves: Vec<(Scene, RenderSettings)> = HALF_SEEDS.iter().map(|&s| configure(s)).collect();
    let key = cache_key(&halves, samples_per_half);
    let resolution = halves[0].1.width;
    let file = folder.join(format!(
        "{}-{resolution}-{}.bin",
        assets::file_safe(&scene.name),
        &assets::hex(&key)[..16]
    ));
    let cached = read(&file, &key);
    let ([a, b], seconds, cached) = match cached {
        Some((halves, seconds)) => (halves, seconds, true),
        None => {
            let started = Instant::now();
            let rendered: Vec<Image> = halves.iter().map(|(s, r)| backend.render(s, r)).collect();
            let seconds = started.elapsed().as_secs_f64();
            let [a, b]: [Image; 2] = rendered.try_into().expect("two halves");
            std::fs::create_dir_all(folder)
                .with_context(|| format!("creating {}", folder.display()))?;
            write(&file, &key, [&a, &b], seconds)?;
            ([a, b], seconds, false)
        }
    };
    let image = mean(&a, &b);
    let own = rel_mse(&a, &image)?;
    Ok(Reference {
        image,
        summary: ReferenceSummary {
            samples: 2 * samples_per_half,
            rel_mse: own,
            seconds,
            cached,
            file,
        },
    })
}

/// SHA-256 of everything that determines the two halves, with this
/// renderer's version.
fn cache_key(halves: &[(Scene, RenderSettings)], samples_per_half: u32) -> [u8; 32] {
    key_of_version(RENDER_VERSION, halves, samples_per_half)
}

/// [`cache_key`] as renderer version `render_version` makes it.
fn key_of_version(
    render_version: u32,
    halves: &[(Scene, RenderSettings)],
    samples_per_half: u32,
) -> [u8; 32] {
    let mut hash = Sha256::new();
    hash.update(format!("render version {render_version}, format {FORMAT_VERSION}, {samples_per_half} samples per half\n"));
    for (scene, settings) in halves {
        hash.update(scene_content(scene));
        hash.update(format!("{settings:?}\n"));
    }
    hash.finalize().into()
}

/// The scene's `Debug` form, which holds every field a render reads
/// (meshes, materials, decoded textures, camera, lights, features,
/// parameters), without what it does not read: where the files were and
/// the description. A moved checkout keeps its cache.
fn scene_content(scene: &Scene) -> String {
    let mut scene = scene.clone();
    scene.source = PathBuf::new();
    scene.description.clear();
    for material in &mut scene.materials {
        material.diffuse_texture = None;
    }
    format!("{scene:?}\n")
}

fn mean(a: &Image, b: &Image) -> Image {
    Image {
        width: a.width,
        height: a.height,
        pixels: a
            .pixels
            .iter()
            .zip(&b.pixels)
            .map(|(x, y)| 0.5 * (*x + *y))
            .collect(),
    }
}

/// Little-endian: magic, format, key, width, height, seconds (f64), then
/// both halves' pixels as f32 RGB, rows top to bottom.
fn write(path: &Path, key: &[u8; 32], halves: [&Image; 2], seconds: f64) -> anyhow::Result<()> {
    let mut bytes = MAGIC.to_vec();
    bytes.extend(FORMAT_VERSION.to_le_bytes());
    bytes.extend(key);
    bytes.extend(halves[0].width.to_le_bytes());
    bytes.extend(halves[0].height.to_le_bytes());
    bytes.extend(seconds.to_le_bytes());
    for image in halves {
        for p in &image.pixels {
            for c in p.to_array() {
                bytes.extend(c.to_le_bytes());
            }
        }
    }
    // Written under another name, then renamed: a reader never sees half a file.
    let partial = path.with_extension(format!("partial-{}", std::process::id()));
    std::fs::write(&partial, bytes).with_context(|| format!("writing {}", partial.display()))?;
    std::fs::rename(&partial, path).with_context(|| format!("writing {}", path.display()))
}

/// The halves cached at `path` under `key`, or `None` when the file is
/// missing, from another key or damaged.
fn read(path: &Path, key: &[u8; 32]) -> Option<([Image; 2], f64)> {
    let bytes = std::fs::read(path).ok()?;
    let (magic, rest) = bytes.split_first_chunk::<8>()?;
    let (format, rest) = rest.split_first_chunk::<4>()?;
    let (stored_key, rest) = rest.split_first_chunk::<32>()?;
    let (width, rest) = rest.split_first_chunk::<4>()?;
    let (height, rest) = rest.split_first_chunk::<4>()?;
    let (seconds, rest) = rest.split_first_chunk::<8>()?;
    let (width, height) = (u32::from_le_bytes(*width), u32::from_le_bytes(*height));
    let pixels = width as usize * height as usize;
    if magic != MAGIC
        || u32::from_le_bytes(*format) != FORMAT_VERSION
        || stored_key != key
        || rest.len() != 2 * pixels * 12
    {
        return None;
    }
    let values: Vec<f32> = rest
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    let image = |half: &[f32]| Image {
        width,
        height,
        pixels: half.chunks_exact(3).map(Vec3::from_slice).collect(),
    };
    let (a, b) = values.split_at(3 * pixels);
    Some(([image(a), image(b)], f64::from_le_bytes(*seconds)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backends::ours::OURS;
    use crate::parallel::{InstructionSets, Workers};
    use crate::sweep::swept::SweptCount;

    #[test]
    fn a_reference_is_cached_under_its_key_and_estimates_its_own_error() {
        let scene = crate::scene::load("analytic-area").unwrap();
        let workers = Workers::new(Some(1), InstructionSets::default()).unwrap();
        let ours = LayeredBackend::build(&OURS, &scene, workers.build_context()).unwrap();
        let configure = |count: u32| {
            let scene = scene.clone();
            move |seed: u64| SweptCount::LightSamples.configure(&scene, count, 16, SAMPLER, seed)
        };
        let folder = tempfile::tempdir().unwrap();
        let folder = folder.path();
        let first = reference(&scene, &ours, folder, 4, &configure(4)).unwrap();
        assert!(!first.summary.cached);
        let again = reference(&scene, &ours, folder, 4, &configure(4)).unwrap();
        assert!(again.summary.cached);
        assert_eq!(again.image, first.image);
        assert_eq!(again.summary.rel_mse, first.summary.rel_mse);
        // Another count is another key: rendered, not read.
        let more = reference(&scene, &ours, folder, 16, &configure(16)).unwrap();
        assert!(!more.summary.cached);
        assert_ne!(more.summary.file, first.summary.file);
        // Four times the samples, stratified on a smooth integrand: the
        // error falls at least four times.
        assert!(
            more.summary.rel_mse < first.summary.rel_mse / 4.0,
            "{} vs {}",
            more.summary.rel_mse,
            first.summary.rel_mse
        );
        // A damaged file is rendered again.
        std::fs::write(&first.summary.file, b"RCSWEEPR").unwrap();
        let healed = reference(&scene, &ours, folder, 4, &configure(4)).unwrap();
        assert!(!healed.summary.cached);
        assert_eq!(healed.image, first.image);
    }

    #[test]
    fn the_key_changes_with_the_scene_and_not_with_where_it_was_loaded() {
        let scene = crate::scene::load("analytic-area").unwrap();
        let halves = |scene: &Scene| -> Vec<(Scene, RenderSettings)> {
            HALF_SEEDS
                .iter()
                .map(|&s| SweptCount::LightSamples.configure(scene, 4, 8, SAMPLER, s))
                .collect()
        };
        let key = cache_key(&halves(&scene), 4);
        let mut moved = scene.clone();
        moved.source = PathBuf::from("/elsewhere/analytic-area.toml");
        assert_eq!(cache_key(&halves(&moved), 4), key);
        let mut dimmer = scene.clone();
        dimmer.materials[0].kd *= 0.5;
        assert_ne!(cache_key(&halves(&dimmer), 4), key);
        assert_ne!(cache_key(&halves(&scene), 16), key);
        // A renderer whose version changed never reads the old reference.
        let next = RENDER_VERSION + 1;
        assert_ne!(key_of_version(next, &halves(&scene), 4), key);
        assert_eq!(key_of_version(RENDER_VERSION, &halves(&scene), 4), key);
    }
}
