//! Motion blur (Cook, Porter, Carpenter 1984): each camera sample has a
//! time in the shutter interval [0, 1), and a moving mesh is where its
//! constant velocity puts it at that time.
//!
//! Every mesh keeps one static acceleration structure (our BVH or an Embree
//! scene): instead of moving the mesh, a ray is moved into the mesh's own
//! frame, its origin shifted by `-velocity·time`. A translation keeps the
//! direction, so `t` means the same in every frame and the closest hit over
//! all meshes is the smallest `t`. Each mesh's queries go to its own
//! intersector, so a checked render checks every layer against its own mesh.

use super::sampling::{SampleStream, Sampler};
use crate::geometry::{Hit, Ray};
use crate::scene::Scene;
use crate::trace::Intersector;
use glam::Vec3;
use std::borrow::Cow;

/// The closest hit over all layers (layer 0 is `scene.mesh`, layer `i + 1`
/// is `scene.moving[i]`) at shutter time `time`, with its layer and the
/// layer's displacement at that time.
pub fn intersect<I: Intersector + ?Sized>(
    scene: &Scene,
    layers: &[&I],
    ray: &Ray,
    time: f32,
) -> Option<LayerHit> {
    let mut best: Option<LayerHit> = None;
    for (layer, intersector) in layers.iter().enumerate() {
        let shift = displacement(scene, layer, time);
        let mut local = into_frame(ray, shift);
        if let Some(b) = &best {
            local.to_mut().tfar = b.hit.t;
        }
        if let Some(hit) = intersector.intersect(&local) {
            // Ties keep the lower layer.
            if best.is_none_or(|b| hit.t < b.hit.t) {
                best = Some(LayerHit { layer, hit, shift });
            }
        }
    }
    best
}

/// Whether anything on any layer blocks `ray` at shutter time `time`.
pub fn occluded<I: Intersector + ?Sized>(
    scene: &Scene,
    layers: &[&I],
    ray: &Ray,
    time: f32,
) -> bool {
    layers
        .iter()
        .enumerate()
        .any(|(layer, i)| i.occluded(&into_frame(ray, displacement(scene, layer, time))))
}

/// A hit on one layer, in that layer's frame.
#[derive(Clone, Copy, Debug)]
pub struct LayerHit {
    pub layer: usize,
    pub hit: Hit,
    /// Where the layer's mesh is, relative to its rest position.
    pub shift: Vec3,
}

/// How far layer `layer` has moved at `time`.
pub fn displacement(scene: &Scene, layer: usize, time: f32) -> Vec3 {
    match layer {
        0 => Vec3::ZERO,
        i => time * scene.moving[i - 1].velocity,
    }
}

/// `ray` as seen from a mesh displaced by `shift`: `ray` itself where the
/// mesh has not moved, as its maker stored it. A copy read it in 16-byte
/// loads that its maker's narrower stores cannot forward, and its own two
/// 16-byte stores could not forward to our kernels' first 8-byte load of
/// the direction either: each stall waits for the stores to reach the
/// cache (the Cornell box's render at 800² took ours 10% and Embree 3%
/// longer, AMD EPYC).
fn into_frame(ray: &Ray, shift: Vec3) -> Cow<'_, Ray> {
    if shift == Vec3::ZERO {
        return Cow::Borrowed(ray);
    }
    Cow::Owned(Ray {
        origin: ray.origin - shift,
        ..*ray
    })
}

/// The shutter time of camera sample `index` of `count`, placed in [0, 1)
/// by `sampler`. Stratified times visit the strata in a scrambled order
/// (index × a stride coprime to the count) so that time is not tied to the
/// sample's position stratum.
pub fn shutter_time(index: u32, count: u32, sampler: Sampler, stream: &mut SampleStream) -> f32 {
    let stride = (count * 5 / 8..count + 1)
        .find(|&s| gcd(s, count) == 1)
        .unwrap_or(1);
    sampler.sample_1d(index * stride % count, count, stream)
}

fn gcd(a: u32, b: u32) -> u32 {
    if b == 0 { a } else { gcd(b, a % b) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shutter_times_fill_every_stratum_once() {
        for count in [1u32, 2, 4, 9, 16, 30] {
            let mut stream = SampleStream::new(0, 0, 0);
            let mut seen: Vec<u32> = (0..count)
                .map(|i| {
                    let time = shutter_time(i, count, Sampler::Stratified, &mut stream);
                    (time * count as f32) as u32
                })
                .collect();
            seen.sort();
            assert_eq!(seen, (0..count).collect::<Vec<_>>(), "count {count}");
        }
    }
}
