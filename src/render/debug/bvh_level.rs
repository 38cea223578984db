//! The boxes of one BVH level drawn over the render: each box at that
//! depth (root = 0, see [`BvhView`] for what a level of the wide BVH is)
//! as its 12 edges, seen by the scene camera, in colours that cycle so that
//! neighbouring boxes can be told apart.

use super::{DebugImage, display, draw};
use crate::bvh::BvhView;
use crate::geometry::Aabb;
use crate::render::image::Image;
use crate::scene::Scene;
use glam::Vec3;

/// Box colours, cycled by node (display values).
const COLOURS: [Vec3; 6] = [
    Vec3::new(1.0, 0.85, 0.0),
    Vec3::new(0.0, 0.9, 1.0),
    Vec3::new(1.0, 0.3, 0.9),
    Vec3::new(0.4, 1.0, 0.3),
    Vec3::new(1.0, 0.5, 0.1),
    Vec3::new(0.6, 0.6, 1.0),
];

/// The 12 edges of `b`: corner pairs that differ along one axis.
pub fn box_edges(b: &Aabb) -> Vec<[Vec3; 2]> {
    let corner = |i: usize| {
        Vec3::new(
            if i & 1 == 0 { b.min.x } else { b.max.x },
            if i & 2 == 0 { b.min.y } else { b.max.y },
            if i & 4 == 0 { b.min.z } else { b.max.z },
        )
    };
    (0..8)
        .flat_map(|i| [1, 2, 4].map(move |axis| (i, i | axis)))
        .filter(|&(i, j)| i != j)
        .map(|(i, j)| [corner(i), corner(j)])
        .collect()
}

/// `render` with the boxes of level `level` of every layer's BVH drawn on
/// it (moving layers at their rest position, shutter time 0).
pub fn draw(
    scene: &Scene,
    mut render: Image,
    bvhs: &[&dyn BvhView],
    level: u32,
) -> anyhow::Result<DebugImage> {
    let levels = bvhs.iter().map(|b| b.levels()).max().unwrap_or(0);
    if level >= levels {
        anyhow::bail!(
            "BVH level {level} is beyond the tree of {}: its levels are 0 to {}",
            scene.name,
            levels.saturating_sub(1)
        );
    }
    let boxes: Vec<Aabb> = bvhs.iter().flat_map(|b| b.boxes_at_level(level)).collect();
    for (index, b) in boxes.iter().enumerate() {
        let colour = display(COLOURS[index % COLOURS.len()]);
        for [p, q] in box_edges(b) {
            draw::segment(&mut render, &scene.camera, p, q, colour);
        }
    }
    Ok(DebugImage {
        image: render,
        legend: format!(
            "the {} node boxes at BVH level {level} (root 0, deepest {}) over the render",
            boxes.len(),
            levels - 1
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_box_has_12_distinct_unit_edges() {
        let edges = box_edges(&Aabb {
            min: Vec3::ZERO,
            max: Vec3::ONE,
        });
        assert_eq!(edges.len(), 12);
        assert!(edges.iter().all(|[p, q]| (*p - *q).length() == 1.0));
    }
}
