//! Indexed triangle meshes: what every loader produces and every backend consumes.

use super::aabb::Aabb;
use glam::{Vec2, Vec3};

/// An indexed triangle mesh with optional per-vertex attributes and a
/// material per triangle.
///
/// Invariants (checked by [`TriangleMesh::check`]): every index is below
/// `positions.len()`; `normals` and `texcoords`, when present, have one entry
/// per position; `materials` has one entry per triangle.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriangleMesh {
    pub positions: Vec<Vec3>,
    pub indices: Vec<[u32; 3]>,
    pub normals: Option<Vec<Vec3>>,
    pub texcoords: Option<Vec<Vec2>>,
    pub materials: Vec<u32>,
}

impl TriangleMesh {
    /// A mesh of bare triangles: no normals or texcoords, material 0 on all.
    pub fn new(positions: Vec<Vec3>, indices: Vec<[u32; 3]>) -> Self {
        let materials = vec![0; indices.len()];
        Self {
            positions,
            indices,
            materials,
            ..Default::default()
        }
    }

    /// Triangles given corner by corner, none sharing a vertex.
    pub fn soup(triangles: &[[Vec3; 3]]) -> Self {
        Self::new(
            triangles.iter().flatten().copied().collect(),
            (0..triangles.len() as u32)
                .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
                .collect(),
        )
    }

    pub fn triangle_count(&self) -> usize {
        self.indices.len()
    }

    /// The three corners of triangle `prim`.
    pub fn triangle(&self, prim: usize) -> [Vec3; 3] {
        let [a, b, c] = self.indices[prim];
        [
            self.positions[a as usize],
            self.positions[b as usize],
            self.positions[c as usize],
        ]
    }

    pub fn bounds(&self) -> Aabb {
        self.indices
            .iter()
            .flatten()
            .fold(Aabb::EMPTY, |b, &i| b.grow(self.positions[i as usize]))
    }

    /// Appends `other`, offsetting its indices and material ids.
    pub fn append(&mut self, other: &TriangleMesh, material_offset: u32) {
        let base = self.positions.len() as u32;
        let own_vertices = self.positions.len();
        self.positions.extend_from_slice(&other.positions);
        self.indices
            .extend(other.indices.iter().map(|t| t.map(|i| i + base)));
        self.materials
            .extend(other.materials.iter().map(|m| m + material_offset));
        merge_attribute(
            &mut self.normals,
            &other.normals,
            own_vertices,
            other.positions.len(),
        );
        merge_attribute(
            &mut self.texcoords,
            &other.texcoords,
            own_vertices,
            other.positions.len(),
        );
    }

    /// Checks the invariants above, naming the first violation.
    pub fn check(&self) -> Result<(), String> {
        let n = self.positions.len();
        if let Some((t, idx)) = self
            .indices
            .iter()
            .enumerate()
            .find(|(_, idx)| idx.iter().any(|&i| i as usize >= n))
        {
            return Err(format!(
                "triangle {t} has index {idx:?} but the mesh has {n} vertices"
            ));
        }
        if self.normals.as_ref().is_some_and(|v| v.len() != n) {
            return Err("normal count differs from vertex count".into());
        }
        if self.texcoords.as_ref().is_some_and(|v| v.len() != n) {
            return Err("texcoord count differs from vertex count".into());
        }
        if self.materials.len() != self.indices.len() {
            return Err("material count differs from triangle count".into());
        }
        Ok(())
    }
}

/// Merges a per-vertex attribute; a side without it contributes default
/// values (a zero normal means "use the geometric normal"), so an appended
/// mesh never leaves the merged array short.
fn merge_attribute<T: Clone + Default>(
    own: &mut Option<Vec<T>>,
    other: &Option<Vec<T>>,
    own_vertices: usize,
    other_vertices: usize,
) {
    if own.is_none() && other.is_none() {
        return;
    }
    let merged = own.get_or_insert_with(|| vec![T::default(); own_vertices]);
    match other {
        Some(values) => merged.extend_from_slice(values),
        None => merged.resize(own_vertices + other_vertices, T::default()),
    }
}
