//! What each way of building the BVH costs and buys on one scene: build
//! time, time per frame of the scene's own render, SAH cost, memory; and
//! from build and frame times, how many frames each choice needs to pay
//! for its build ([`super::break_even`]).

use super::break_even::{Cost, FrontierSpan, Overtaking, frontier, overtaking};
use crate::backends::{Backend, embree};
use crate::bvh::wide::{BLOCK_WIDTH, Child, WIDTH, WideBvh, WideNode};
use crate::bvh::{BuildOptions, Builder, Bvh, INTERSECTION_COST, TRAVERSAL_COST};
use crate::geometry::{Aabb, TriangleMesh};
use crate::parallel::Workers;
use crate::perf::measure::Stat;
use crate::render::{RenderSettings, render};
use crate::scene::Scene;
use raycheck_reference::{BuildQuality, Device, SceneOptions};
use serde::Serialize;
use std::time::Instant;

/// One way to build the acceleration structure.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BvhChoice {
    /// Our binary BVH, median split or binned SAH, with its limits.
    Binary(BuildOptions),
    /// Our 8-wide SIMD BVH (binned SAH, collapsed).
    Wide,
    /// Embree 4.4 at a build quality, not robust.
    Embree(BuildQuality),
}

impl BvhChoice {
    /// A median split to `max_depth` with leaves of `leaf` triangles.
    pub fn median(max_depth: u32, leaf: u32) -> Self {
        BvhChoice::Binary(BuildOptions {
            max_depth,
            max_leaf_size: leaf,
            ..BuildOptions::median()
        })
    }

    /// A binned SAH build with `bins` bins per axis.
    pub fn sah(bins: u32) -> Self {
        BvhChoice::Binary(BuildOptions {
            sah_bins: bins,
            ..BuildOptions::sah()
        })
    }

    /// The choices of a full sweep, or of a quick one.
    pub fn all(quick: bool) -> Vec<Self> {
        let unlimited = crate::bvh::MAX_DEPTH;
        if quick {
            return vec![
                Self::median(unlimited, 4),
                Self::median(12, 4),
                Self::sah(4),
                Self::sah(32),
                BvhChoice::Wide,
                BvhChoice::Embree(BuildQuality::Low),
                BvhChoice::Embree(BuildQuality::Medium),
            ];
        }
        vec![
            Self::median(unlimited, 1),
            Self::median(unlimited, 4),
            Self::median(unlimited, 16),
            Self::median(12, 4),
            Self::median(16, 4),
            Self::sah(4),
            Self::sah(8),
            Self::sah(16),
            Self::sah(32),
            BvhChoice::Wide,
            BvhChoice::Embree(BuildQuality::Low),
            BvhChoice::Embree(BuildQuality::Medium),
            BvhChoice::Embree(BuildQuality::High),
        ]
    }

    /// Its name in tables and legends.
    pub fn label(&self) -> String {
        match self {
            BvhChoice::Binary(o) if o.builder == Builder::Median => {
                let depth = if o.max_depth >= crate::bvh::MAX_DEPTH {
                    String::new()
                } else {
                    format!(", depth ≤ {}", o.max_depth)
                };
                format!("median, leaf ≤ {}{depth}", o.max_leaf_size)
            }
            BvhChoice::Binary(o) => format!("SAH, {} bins", o.sah_bins),
            BvhChoice::Wide => "wide (8-wide SAH)".into(),
            BvhChoice::Embree(quality) => format!("Embree {}", quality_name(*quality)),
        }
    }

    fn build(&self, mesh: &TriangleMesh, device: &Device) -> anyhow::Result<Built> {
        Ok(match self {
            BvhChoice::Binary(options) => Built::Binary(Bvh::build(mesh, options)),
            BvhChoice::Wide => Built::Wide(WideBvh::build(mesh)),
            BvhChoice::Embree(quality) => {
                Built::Embree(embree::build_scene(device, mesh, embree_options(*quality))?)
            }
        })
    }
}

fn embree_options(quality: BuildQuality) -> SceneOptions {
    SceneOptions {
        quality,
        robust: false,
    }
}

fn quality_name(quality: BuildQuality) -> &'static str {
    match quality {
        BuildQuality::Low => "LOW",
        BuildQuality::Medium => "MEDIUM",
        BuildQuality::High => "HIGH",
    }
}

/// A built choice, keeping its type for its statistics.
enum Built {
    Binary(Bvh),
    Wide(WideBvh),
    Embree(raycheck_reference::Scene),
}

impl Built {
    fn backend(&self) -> &dyn Backend {
        match self {
            Built::Binary(b) => b,
            Built::Wide(w) => w,
            Built::Embree(e) => e,
        }
    }
}

/// Whose cost model a SAH cost is in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SahModel {
    /// Ours: 1 per node visited (a binary node's two boxes, or a wide
    /// node's four in one SIMD test), 1 per triangle tested, each weighted
    /// by the box's area over the root's.
    Ours,
    /// Embree's own, from its build statistics (its BVH8 nodes and
    /// 4-triangle leaf blocks, its constants): comparable between Embree's
    /// qualities, not with ours.
    Embree,
}

/// How big the measurement of one scene is.
#[derive(Clone, Debug)]
pub struct BvhPlan {
    pub choices: Vec<BvhChoice>,
    /// The side of the frames rendered.
    pub frame_resolution: u32,
    /// Timed builds and timed frames per choice (after one untimed of each).
    pub runs: usize,
}

/// Every choice on one scene; the JSON of the BVH part.
#[derive(Clone, Debug, Serialize)]
pub struct BvhScene {
    pub scene: String,
    pub triangles: usize,
    pub frame_resolution: u32,
    pub choices: Vec<ChoiceResult>,
    /// The cheapest choice in total at every frame count, as spans of
    /// frame counts; `choice` indexes `choices`.
    pub frontier: Vec<FrontierSpan>,
}

/// One choice on one scene.
#[derive(Clone, Debug, Serialize)]
pub struct ChoiceResult {
    pub choice: String,
    /// Build wall time, ms, over the timed runs.
    pub build_ms: Stat,
    /// Wall time of one frame of the scene's render, ms.
    pub frame_ms: Stat,
    pub sah_cost: f64,
    pub sah_model: SahModel,
    /// Bytes of the acceleration structure (Embree's: what its memory
    /// monitor saw the scene allocate).
    pub bytes: Option<usize>,
    /// How it compares with the next cheaper build (`next_cheaper`
    /// indexes `choices`); `None` for the cheapest build.
    pub overtaking: Option<Overtaking>,
}

impl ChoiceResult {
    /// Its build and frame time, as medians.
    pub fn cost(&self) -> Cost {
        Cost {
            build_seconds: self.build_ms.median / 1e3,
            frame_seconds: self.frame_ms.median / 1e3,
        }
    }
}

/// Measures every choice of `plan` on `scene` (without moving meshes) on
/// `workers`.
///
/// # Errors
/// The scene has moving meshes, or a build fails.
pub fn measure_scene(
    scene: &Scene,
    plan: &BvhPlan,
    workers: &Workers,
    progress: &dyn Fn(&str),
) -> anyhow::Result<BvhScene> {
    let (pool, device) = (workers.pool(), workers.device());
    anyhow::ensure!(
        scene.moving.is_empty(),
        "{}: BVH choices are measured on scenes without moving meshes",
        scene.name
    );
    let settings = RenderSettings::square(plan.frame_resolution);
    let threads = pool.current_num_threads();
    let mut choices = Vec::new();
    for choice in &plan.choices {
        progress(&format!("{}: {}", scene.name, choice.label()));
        let mut build_ms = Vec::new();
        let mut built = None;
        for run in 0..=plan.runs {
            // Drop the previous build first, so only one is alive.
            drop(built.take());
            let b = pool.install(|| choice.build(&scene.mesh, device))?;
            if run > 0 {
                build_ms.push(b.backend().build_time().as_secs_f64() * 1e3);
            }
            built = Some(b);
        }
        let built = built.expect("at least one build");
        let mut frame_ms = Vec::new();
        for run in 0..=plan.runs {
            let started = Instant::now();
            let image = pool.install(|| render(scene, built.backend(), &settings));
            std::hint::black_box(image);
            if run > 0 {
                frame_ms.push(started.elapsed().as_secs_f64() * 1e3);
            }
        }
        let (sah_cost, sah_model) = match &built {
            Built::Binary(bvh) => (bvh.stats().sah_cost, SahModel::Ours),
            Built::Wide(wide) => (wide_sah_cost(wide), SahModel::Ours),
            Built::Embree(_) => {
                let BvhChoice::Embree(quality) = choice else {
                    unreachable!("only an Embree choice builds an Embree scene")
                };
                let stats =
                    embree::bvh_statistics(Some(threads), &scene.mesh, embree_options(*quality))?;
                (stats.sah_cost, SahModel::Embree)
            }
        };
        choices.push(ChoiceResult {
            choice: choice.label(),
            build_ms: Stat::of(build_ms),
            frame_ms: Stat::of(frame_ms),
            sah_cost,
            sah_model,
            bytes: built.backend().bytes(),
            overtaking: None,
        });
    }
    let costs: Vec<Cost> = choices.iter().map(ChoiceResult::cost).collect();
    for (choice, over) in choices.iter_mut().zip(overtaking(&costs)) {
        choice.overtaking = over;
    }
    Ok(BvhScene {
        scene: scene.name.clone(),
        triangles: scene.mesh.triangle_count(),
        frame_resolution: plan.frame_resolution,
        frontier: frontier(&costs),
        choices,
    })
}

/// The wide tree's SAH cost in our model ([`SahModel::Ours`]): every node
/// visited costs [`TRAVERSAL_COST`] and every triangle of a leaf
/// [`INTERSECTION_COST`], weighted by the area of the node's or leaf's
/// box over the root's (by 1 when the root's box has no area).
pub fn wide_sah_cost(bvh: &WideBvh) -> f64 {
    let nodes = bvh.nodes();
    let Some(root) = nodes.first() else {
        return 0.0;
    };
    let root_area = occupied(root)
        .fold(Aabb::EMPTY, |b, (_, bounds)| b.union(bounds))
        .surface_area() as f64;
    let weight = |area: f64| {
        if root_area > 0.0 {
            area / root_area
        } else {
            1.0
        }
    };
    // Nodes come parent first, so each node's area is known when reached.
    let mut area = vec![0.0; nodes.len()];
    area[0] = root_area;
    let mut cost = 0.0;
    for (index, node) in nodes.iter().enumerate() {
        cost += TRAVERSAL_COST * weight(area[index]);
        for (child, bounds) in occupied(node) {
            let child_area = bounds.surface_area() as f64;
            match child {
                Child::Inner(next) => area[next] = child_area,
                Child::Leaf(block) => {
                    let block = &bvh.blocks()[block];
                    let triangles = (0..BLOCK_WIDTH)
                        .filter(|&lane| block.prim(lane).is_some())
                        .count();
                    cost += INTERSECTION_COST * triangles as f64 * weight(child_area);
                }
                Child::Empty => {}
            }
        }
    }
    cost
}

/// The children of `node` with their boxes.
fn occupied(node: &WideNode) -> impl Iterator<Item = (Child, Aabb)> + '_ {
    (0..WIDTH).filter_map(move |s| match node.child(s) {
        Child::Empty => None,
        child => Some((child, node.child_bounds(s))),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::TriangleMesh;
    use glam::Vec3;

    #[test]
    fn a_wide_tree_of_one_leaf_costs_its_visit_and_its_triangles() {
        // Four triangles fit one leaf: the root (weight 1) and 4 triangles
        // in a box the size of the root's.
        let tris: Vec<[Vec3; 3]> = (0..4)
            .map(|i| {
                let x = i as f32;
                [
                    Vec3::new(x, 0.0, 0.0),
                    Vec3::new(x + 1.0, 0.0, 0.0),
                    Vec3::new(x, 1.0, 1.0),
                ]
            })
            .collect();
        let wide = WideBvh::build(&TriangleMesh::soup(&tris));
        assert_eq!(
            wide_sah_cost(&wide),
            TRAVERSAL_COST + 4.0 * INTERSECTION_COST
        );
        // More triangles: more nodes and leaves, and a cost between the
        // binary SAH tree's and a flat list's.
        let many: Vec<[Vec3; 3]> = (0..64)
            .map(|i| {
                let x = (i % 8) as f32 * 2.0;
                let y = (i / 8) as f32 * 2.0;
                [
                    Vec3::new(x, y, 0.0),
                    Vec3::new(x + 1.0, y, 0.0),
                    Vec3::new(x, y + 1.0, 0.0),
                ]
            })
            .collect();
        let mesh = TriangleMesh::soup(&many);
        let cost = wide_sah_cost(&WideBvh::build(&mesh));
        assert!(
            cost > TRAVERSAL_COST && cost < 64.0 * INTERSECTION_COST,
            "{cost}"
        );
    }

    #[test]
    fn labels_name_every_choice() {
        let labels: Vec<String> = BvhChoice::all(false).iter().map(BvhChoice::label).collect();
        assert_eq!(labels[0], "median, leaf ≤ 1");
        assert_eq!(labels[3], "median, leaf ≤ 4, depth ≤ 12");
        assert_eq!(labels[5], "SAH, 4 bins");
        assert_eq!(labels[12], "Embree HIGH");
        let unique: std::collections::BTreeSet<&String> = labels.iter().collect();
        assert_eq!(unique.len(), labels.len());
    }
}
