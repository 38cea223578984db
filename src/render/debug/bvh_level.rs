//! The boxes of one BVH level drawn over the render: each node at that
//! depth (root = 0) as the 12 edges of its box, seen by the scene camera,
//! in colours that cycle so that neighbouring boxes can be told apart.

use super::{DebugImage, display, draw};
use crate::bvh::Bvh;
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

/// The boxes of the nodes at depth `level` (root = 0), left to right.
pub fn boxes_at_level(bvh: &Bvh, level: u32) -> Vec<Aabb> {
    let nodes = bvh.nodes();
    let mut boxes = Vec::new();
    let mut stack = if nodes.is_empty() {
        vec![]
    } else {
        vec![(0usize, 0u32)]
    };
    while let Some((index, depth)) = stack.pop() {
        let node = &nodes[index];
        if depth == level {
            boxes.push(node.bounds());
        } else if let Some([left, right]) = node.children() {
            stack.extend([(right, depth + 1), (left, depth + 1)]);
        }
    }
    boxes
}

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
    bvhs: &[Bvh],
    level: u32,
) -> anyhow::Result<DebugImage> {
    let levels = bvhs.iter().map(|b| b.stats().levels).max().unwrap_or(0);
    if level >= levels {
        anyhow::bail!(
            "BVH level {level} is beyond the tree of {}: its levels are 0 to {}",
            scene.name,
            levels.saturating_sub(1)
        );
    }
    let boxes: Vec<Aabb> = bvhs.iter().flat_map(|b| boxes_at_level(b, level)).collect();
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
    use crate::bvh::BuildOptions;
    use crate::geometry::TriangleMesh;

    #[test]
    fn a_box_has_12_distinct_unit_edges() {
        let edges = box_edges(&Aabb {
            min: Vec3::ZERO,
            max: Vec3::ONE,
        });
        assert_eq!(edges.len(), 12);
        assert!(edges.iter().all(|[p, q]| (*p - *q).length() == 1.0));
    }

    #[test]
    fn each_level_covers_the_triangles_below_it() {
        let mut mesh = TriangleMesh::default();
        for i in 0..64 {
            let base = Vec3::new(i as f32, (i % 5) as f32, 0.0);
            let n = mesh.positions.len() as u32;
            mesh.positions
                .extend([base, base + Vec3::X * 0.5, base + Vec3::Y * 0.5]);
            mesh.indices.push([n, n + 1, n + 2]);
            mesh.materials.push(0);
        }
        let bvh = Bvh::build(&mesh, &BuildOptions::median());
        assert_eq!(boxes_at_level(&bvh, 0), vec![bvh.nodes()[0].bounds()]);
        assert_eq!(boxes_at_level(&bvh, 1).len(), 2);
        let deepest = bvh.stats().levels - 1;
        assert!(!boxes_at_level(&bvh, deepest).is_empty());
        assert!(boxes_at_level(&bvh, deepest + 1).is_empty());
    }
}
