//! Embree 4 as an [`Intersector`] and a [`Backend`]: our rays and hits
//! converted to and from `raycheck_reference`'s, field for field (both use
//! Embree's conventions). Its kinds are `embree`, then the build quality
//! unless it is MEDIUM (`-low`, `-high`), then `-robust` for
//! `RTC_SCENE_FLAG_ROBUST`.

use super::{Answers, Backend, BackendName, BuildContext, Group, Kind, Label, TreeShape};
use crate::geometry::{Hit, Ray, TriangleMesh};
use crate::trace::Intersector;
use glam::Vec3;
use raycheck_reference::{
    BuildQuality, BvhStatistics, Device, EmbreeError, EmbreeHit, RayQuery, Scene, SceneOptions,
    TriangleMeshRef,
};
use std::time::Duration;

/// Embree's default configuration: MEDIUM, not robust.
pub const MEDIUM: SceneOptions = SceneOptions {
    quality: BuildQuality::Medium,
    robust: false,
};

/// MEDIUM with `RTC_SCENE_FLAG_ROBUST`: watertight like ours, the
/// configuration that checks ours by default.
pub const ROBUST: SceneOptions = SceneOptions {
    quality: BuildQuality::Medium,
    robust: true,
};

/// Embree with one configuration, as `--backends` names it.
struct Embree {
    label: Label<'static>,
    options: SceneOptions,
}

const fn options(quality: BuildQuality, robust: bool) -> SceneOptions {
    SceneOptions { quality, robust }
}

/// Every configuration `--backends` names.
static CONFIGS: [Embree; 6] = [
    Embree {
        label: Label {
            name: "embree",
            aliases: &["embree-medium"],
            about: "Embree MEDIUM (binned SAH, BVH8), its default",
        },
        options: MEDIUM,
    },
    Embree {
        label: Label {
            name: "embree-robust",
            aliases: &["embree-medium-robust"],
            about: "Embree MEDIUM with RTC_SCENE_FLAG_ROBUST (watertight)",
        },
        options: ROBUST,
    },
    Embree {
        label: Label {
            name: "embree-low",
            aliases: &[],
            about: "Embree LOW (Morton build)",
        },
        options: options(BuildQuality::Low, false),
    },
    Embree {
        label: Label {
            name: "embree-low-robust",
            aliases: &[],
            about: "Embree LOW, robust",
        },
        options: options(BuildQuality::Low, true),
    },
    Embree {
        label: Label {
            name: "embree-high",
            aliases: &[],
            about: "Embree HIGH (spatial splits)",
        },
        options: options(BuildQuality::High, false),
    },
    Embree {
        label: Label {
            name: "embree-high-robust",
            aliases: &[],
            about: "Embree HIGH, robust (plain SAH: robust mode has no spatial splits)",
        },
        options: options(BuildQuality::High, true),
    },
];

pub(super) const KINDS: &[&dyn Kind] = &[
    &CONFIGS[0],
    &CONFIGS[1],
    &CONFIGS[2],
    &CONFIGS[3],
    &CONFIGS[4],
    &CONFIGS[5],
];

/// `embree`: MEDIUM, Embree's default.
pub const EMBREE: BackendName = BackendName::of(&CONFIGS[0]);
/// `embree-robust`: MEDIUM + ROBUST.
pub const EMBREE_ROBUST: BackendName = BackendName::of(&CONFIGS[1]);

impl Kind for Embree {
    fn label(&self) -> Label<'_> {
        self.label
    }
    fn group(&self) -> Group {
        Group::Embree
    }

    fn build(
        &self,
        mesh: &TriangleMesh,
        context: BuildContext,
    ) -> anyhow::Result<Box<dyn Backend>> {
        Ok(Box::new(build_scene(context.device, mesh, self.options)?))
    }

    /// Embree's own statistics of the tree, from a build on a private
    /// verbose device with as many threads as the current pool.
    fn tree_shape(
        &self,
        mesh: &TriangleMesh,
        _: BuildContext,
    ) -> Option<anyhow::Result<TreeShape>> {
        let threads = rayon::current_num_threads();
        Some(
            bvh_statistics(Some(threads), mesh, self.options)
                .map(|stats| TreeShape {
                    levels: stats.depth,
                    max_leaf_triangles: format!(
                        "≤ {} ({})",
                        4 * stats.leaf_histogram_percent.len(),
                        stats.bvh_type
                    ),
                    nodes: (stats.inner_nodes() + stats.leaf_nodes()) as u64,
                    bytes: stats.bytes as u64,
                    sah_cost: Some(stats.sah_cost),
                })
                .map_err(Into::into),
        )
    }
}

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

/// The query for `ray`, each field read on its own: copied whole, the ray
/// is read in 16-byte loads that the narrower stores which wrote it cannot
/// forward, and the query waits for them to reach the cache (see
/// `raycheck_reference`'s `ray.rs`).
fn query(ray: &Ray) -> RayQuery {
    // SAFETY: each is a field of `ray`, an aligned, initialized f32.
    // Volatile keeps the compiler from merging the reads.
    let read = |field: &f32| unsafe { std::ptr::read_volatile(field) };
    RayQuery {
        origin: [
            read(&ray.origin.x),
            read(&ray.origin.y),
            read(&ray.origin.z),
        ],
        dir: [read(&ray.dir.x), read(&ray.dir.y), read(&ray.dir.z)],
        tnear: read(&ray.tnear),
        tfar: read(&ray.tfar),
    }
}

impl Backend for Scene {
    fn name(&self) -> String {
        let options = self.options();
        CONFIGS
            .iter()
            .find(|config| config.options == options)
            .map_or_else(
                || format!("embree {options:?}"),
                |config| config.label.name.into(),
            )
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
