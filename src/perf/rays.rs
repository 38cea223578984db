//! The fixed ray sets every speed measurement traces: primary rays through
//! the pixel centres of an N×N view, and from each primary hit a shadow ray
//! to the first light, a cosine-distributed diffuse bounce and the mirror
//! reflection (which `raycheck rays` exports; `perf` does not time it).
//!
//! They depend only on the scene and N (the bounce directions come from a
//! hash of the pixel index), are traced identically by both backends, and
//! are saved once per scene in the asset cache so every run, benchmark and
//! backend sees the very same rays.

use crate::bvh::wide::WideBvh;
use crate::geometry::Ray;
use crate::random::mix;
use crate::render::surface::SurfacePoint;
use crate::scene::{Scene, assets};
use crate::trace::Intersector;
use glam::Vec3;
use rayon::prelude::*;
use std::path::PathBuf;

/// The ray sets of one scene.
#[derive(Clone, Debug, PartialEq)]
pub struct RaySets {
    pub primary: Vec<Ray>,
    /// Any-hit queries.
    pub shadow: Vec<Ray>,
    pub diffuse: Vec<Ray>,
    pub reflection: Vec<Ray>,
}

/// A primary hit's shadow ray (if the scene has a light), diffuse ray and
/// reflection ray.
type Secondary = (Option<Ray>, Ray, Ray);

/// Bumped whenever the way the rays are made changes.
const FORMAT_VERSION: u32 = 2;

impl RaySets {
    /// Generates the ray sets of `scene` at `resolution`², finding the
    /// primary hits with `intersector` (every backend gives the same hits
    /// up to ties, which leave the rays' positions unchanged).
    pub fn generate<I: Intersector + ?Sized>(
        scene: &Scene,
        intersector: &I,
        resolution: u32,
    ) -> Self {
        let pixels = resolution as usize * resolution as usize;
        let per_pixel: Vec<(Ray, Option<Secondary>)> = (0..pixels)
            .into_par_iter()
            .map(|pixel| {
                let (x, y) = (pixel as u32 % resolution, pixel as u32 / resolution);
                let ray = scene
                    .camera
                    .ray(x as f32 + 0.5, y as f32 + 0.5, resolution, resolution);
                let secondary = intersector.intersect(&ray).map(|hit| {
                    let surface = SurfacePoint::new(&scene.mesh, &ray, &hit);
                    let shadow = scene
                        .lights
                        .first()
                        .map(|light| surface.shadow_ray(light.representative_point()));
                    let dir = cosine_direction(surface.normal, pixel as u64);
                    let diffuse = Ray::new(surface.spawn_origin(), dir);
                    (shadow, diffuse, surface.reflection_ray())
                });
                (ray, secondary)
            })
            .collect();
        let primary = per_pixel.iter().map(|(ray, _)| *ray).collect();
        let secondary: Vec<Secondary> = per_pixel.iter().filter_map(|(_, s)| *s).collect();
        RaySets {
            primary,
            shadow: secondary.iter().filter_map(|s| s.0).collect(),
            diffuse: secondary.iter().map(|s| s.1).collect(),
            reflection: secondary.iter().map(|s| s.2).collect(),
        }
    }

    /// The cached ray sets of `scene` at `resolution`, generated (through
    /// our wide BVH, built only then) and saved on first use. A cache that
    /// cannot be read or written is not an error: the rays are generated
    /// again.
    pub fn cached(scene: &Scene, resolution: u32) -> Self {
        let path = cache_path(scene, resolution);
        if let Some(sets) = path.as_ref().and_then(|p| Self::read(p)) {
            return sets;
        }
        let sets = Self::generate(scene, &WideBvh::build(&scene.mesh), resolution);
        if let Some(path) = path {
            let written = path
                .parent()
                .is_some_and(|dir| std::fs::create_dir_all(dir).is_ok())
                && std::fs::write(&path, sets.to_bytes()).is_ok();
            if !written {
                eprintln!("note: could not cache the ray sets at {}", path.display());
            }
        }
        sets
    }

    /// Little-endian: version, four counts, then each ray as origin, dir,
    /// tnear, tfar.
    fn to_bytes(&self) -> Vec<u8> {
        let sets = [&self.primary, &self.shadow, &self.diffuse, &self.reflection];
        let mut words = vec![FORMAT_VERSION];
        words.extend(sets.iter().map(|s| s.len() as u32));
        for ray in sets.into_iter().flatten() {
            let floats = [ray.origin.to_array(), ray.dir.to_array()].concat();
            words.extend(
                floats
                    .iter()
                    .chain(&[ray.tnear, ray.tfar])
                    .map(|f| f.to_bits()),
            );
        }
        words.iter().flat_map(|w| w.to_le_bytes()).collect()
    }

    fn read(path: &std::path::Path) -> Option<Self> {
        let bytes = std::fs::read(path).ok()?;
        let words: Vec<u32> = bytes
            .chunks_exact(4)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect();
        let (&[version, primary, shadow, diffuse, reflection], rest) =
            words.split_first_chunk::<5>()?;
        let counts = [primary, shadow, diffuse, reflection].map(|c| c as usize);
        if version != FORMAT_VERSION || rest.len() != 8 * counts.iter().sum::<usize>() {
            return None;
        }
        let mut rays = rest.chunks_exact(8).map(|w| {
            let f: [f32; 8] = std::array::from_fn(|i| f32::from_bits(w[i]));
            Ray::segment(
                Vec3::new(f[0], f[1], f[2]),
                Vec3::new(f[3], f[4], f[5]),
                f[6],
                f[7],
            )
        });
        let [primary, shadow, diffuse, reflection] =
            counts.map(|n| rays.by_ref().take(n).collect());
        Some(RaySets {
            primary,
            shadow,
            diffuse,
            reflection,
        })
    }
}

/// `cache/rays/<scene>-<triangles>-<N>.bin`, or `None` without a cache.
fn cache_path(scene: &Scene, resolution: u32) -> Option<PathBuf> {
    let name = assets::file_safe(&scene.name);
    let file = format!(
        "{name}-{}-{resolution}-v{FORMAT_VERSION}.bin",
        scene.mesh.triangle_count()
    );
    Some(assets::cache_dir().ok()?.join("rays").join(file))
}

/// A cosine-distributed direction around the unit `normal` (Malley's
/// method: uniform on the disk, projected up), from a hash of `seed`.
fn cosine_direction(normal: Vec3, seed: u64) -> Vec3 {
    let bits = mix(seed);
    let unit = |b: u64| (b >> 40) as f32 / (1u64 << 24) as f32;
    let (r, phi) = (unit(bits).sqrt(), std::f32::consts::TAU * unit(bits << 24));
    let (tangent, bitangent) = normal.any_orthonormal_pair();
    let (x, y) = (r * phi.cos(), r * phi.sin());
    let z = (1.0 - x * x - y * y).max(0.0).sqrt();
    x * tangent + y * bitangent + z * normal
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::wide::WideBvh;

    #[test]
    fn ray_sets_round_trip_through_bytes_and_are_reproducible() {
        let scene = crate::scene::load("cornell").unwrap();
        let bvh = WideBvh::build(&scene.mesh);
        let sets = RaySets::generate(&scene, &bvh, 24);
        assert_eq!(sets.primary.len(), 24 * 24);
        assert!(!sets.shadow.is_empty() && sets.diffuse.len() == sets.shadow.len());
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("rays.bin");
        std::fs::write(&path, sets.to_bytes()).unwrap();
        assert_eq!(RaySets::read(&path), Some(sets.clone()));
        assert_eq!(RaySets::generate(&scene, &bvh, 24), sets);
        // Diffuse rays leave on the side of the surface they start from.
        for (ray, shadow) in sets.diffuse.iter().zip(&sets.shadow) {
            assert!(ray.dir.is_finite() && ray.dir.length() > 0.99, "{ray:?}");
            assert_eq!(ray.origin, shadow.origin);
        }
    }
}
