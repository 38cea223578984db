//! Embree 4 as an [`Intersector`] and a [`Backend`]: our rays and hits
//! converted to and from `raycheck_reference`'s, field for field (both use
//! Embree's conventions).

use super::{Answers, Backend};
use crate::geometry::{Hit, Ray, TriangleMesh};
use crate::trace::Intersector;
use glam::Vec3;
use raycheck_reference::{
    BuildQuality, BvhStatistics, Device, EmbreeError, EmbreeHit, RayQuery, Scene, SceneOptions,
    TriangleMeshRef,
};
use std::time::Duration;

/// Builds an Embree scene holding `mesh` as its one geometry (geomID 0), so
/// Embree's primIDs are our triangle indices.
pub fn build_scene(
    device: &Device,
    mesh: &TriangleMesh,
    options: SceneOptions,
) -> Result<Scene, EmbreeError> {
    with_embree_mesh(mesh, |meshes| device.build_scene(meshes, options))
}

/// Embree's own statistics of the BVH it builds for `mesh` on `threads`.
pub fn bvh_statistics(
    threads: Option<usize>,
    mesh: &TriangleMesh,
    options: SceneOptions,
) -> Result<BvhStatistics, EmbreeError> {
    with_embree_mesh(mesh, |meshes| {
        raycheck_reference::bvh_statistics(threads, meshes, options)
    })
}

/// Calls `f` with `mesh` in the layout Embree's buffers take.
fn with_embree_mesh<R>(mesh: &TriangleMesh, f: impl FnOnce(&[TriangleMeshRef]) -> R) -> R {
    let positions: Vec<[f32; 3]> = mesh.positions.iter().map(|p| p.to_array()).collect();
    f(&[TriangleMeshRef {
        positions: &positions,
        indices: &mesh.indices,
    }])
}

impl Intersector for Scene {
    fn intersect(&self, ray: &Ray) -> Option<Hit> {
        Scene::intersect(self, &query(ray)).map(|h: EmbreeHit| Hit {
            t: h.t,
            u: h.u,
            v: h.v,
            prim: h.prim_id,
            ng: Vec3::from_array(h.ng),
        })
    }

    fn occluded(&self, ray: &Ray) -> bool {
        Scene::occluded(self, &query(ray))
    }
}

fn query(ray: &Ray) -> RayQuery {
    RayQuery {
        origin: ray.origin.to_array(),
        dir: ray.dir.to_array(),
        tnear: ray.tnear,
        tfar: ray.tfar,
    }
}

impl Backend for Scene {
    fn name(&self) -> String {
        name(self.options())
    }
    fn answers(&self) -> Answers {
        Answers::ALL
    }
    fn build_time(&self) -> Duration {
        Scene::build_time(self)
    }
    fn bytes(&self) -> Option<usize> {
        Some(Scene::bytes(self))
    }
}

/// The `--backends` name of Embree with `options`: `embree`, then the
/// quality unless it is MEDIUM, then `-robust` for `RTC_SCENE_FLAG_ROBUST`.
pub fn name(options: SceneOptions) -> String {
    let quality = match options.quality {
        BuildQuality::Low => "-low",
        BuildQuality::Medium => "",
        BuildQuality::High => "-high",
    };
    let robust = if options.robust { "-robust" } else { "" };
    format!("embree{quality}{robust}")
}

/// The options a name of [`name`]'s form (or with `-medium` spelled out)
/// stands for.
pub fn parse_name(text: &str) -> Option<SceneOptions> {
    let rest = text.strip_prefix("embree")?;
    let (rest, robust) = match rest.strip_suffix("-robust") {
        Some(rest) => (rest, true),
        None => (rest, false),
    };
    let quality = match rest {
        "" | "-medium" => BuildQuality::Medium,
        "-low" => BuildQuality::Low,
        "-high" => BuildQuality::High,
        _ => return None,
    };
    Some(SceneOptions { quality, robust })
}
