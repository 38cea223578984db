//! Binary glTF (GLB) triangle meshes, plain or Draco-compressed
//! (`KHR_draco_mesh_compression`, decoded by `draco-core`).
//!
//! Read: the 12-byte header, the JSON chunk and the BIN chunk (the only
//! buffer); every triangle primitive (mode 4) reachable from the default
//! scene, with its node transforms applied; `POSITION`, `NORMAL` and
//! `TEXCOORD_0`. Texture coordinates are flipped to OBJ's convention
//! (v up: `v' = 1 - v`). A material's base colour becomes its `kd`; its
//! alpha becomes the opacity as the material's `alphaMode` says (glTF 2.0,
//! 3.9.4): ignored for `OPAQUE` (the default), the opacity for `BLEND`,
//! and for `MASK` fully opaque at or above `alphaCutoff` (default 0.5),
//! fully transparent below.

use crate::geometry::TriangleMesh;
use crate::scene::LoadedMesh;
use crate::scene::error::{SceneError, read_file};
use crate::scene::material::Material;
use crate::scene::transform::transform_mesh;
use glam::{Mat4, Quat, Vec2, Vec3};
use serde::Deserialize;
use std::collections::HashMap;
use std::path::Path;

/// Loads a `.glb` file.
pub fn load(path: &Path) -> Result<LoadedMesh, SceneError> {
    parse(path, &read_file(path)?)
}

/// Parses GLB bytes; `path` only names the source in errors.
pub fn parse(path: &Path, bytes: &[u8]) -> Result<LoadedMesh, SceneError> {
    let err = |msg: String| SceneError::in_file(path, msg);
    let (json, bin) = split_chunks(bytes).map_err(err)?;
    let gltf: Gltf =
        serde_json::from_slice(json).map_err(|e| err(format!("invalid glTF JSON: {e}")))?;
    let mut materials: Vec<Material> = gltf
        .materials
        .iter()
        .enumerate()
        .map(convert_material)
        .collect();
    let default_material = materials.len() as u32;
    let mut mesh = TriangleMesh::default();
    for (node, transform) in gltf.mesh_nodes().map_err(err)? {
        let node_mesh = gltf
            .meshes
            .get(node)
            .ok_or_else(|| err(format!("node refers to mesh {node}, which does not exist")))?;
        for (p, primitive) in node_mesh.primitives.iter().enumerate() {
            if primitive.mode.unwrap_or(4) != 4 {
                continue;
            }
            let mut part = gltf
                .primitive(primitive, bin)
                .map_err(|e| err(format!("mesh {node} primitive {p}: {e}")))?;
            let material = match primitive.material {
                None => default_material,
                Some(m) if m < gltf.materials.len() => m as u32,
                Some(m) => {
                    return Err(err(format!("mesh {node} primitive {p}: no material {m}")));
                }
            };
            part.materials = vec![material; part.indices.len()];
            transform_mesh(&mut part, transform);
            mesh.append(&part, 0);
        }
    }
    if mesh.indices.is_empty() {
        return Err(err("no triangle meshes in the default scene".into()));
    }
    if let Some(v) = mesh.positions.iter().position(|p| !p.is_finite()) {
        return Err(err(format!(
            "vertex {v} is at {}, not a finite point",
            mesh.positions[v]
        )));
    }
    if mesh.materials.contains(&default_material) {
        materials.push(Material::default());
    }
    mesh.check().map_err(err)?;
    Ok(LoadedMesh {
        mesh,
        materials,
        warnings: Vec::new(),
    })
}

/// The JSON and BIN chunks of a GLB container.
fn split_chunks(bytes: &[u8]) -> Result<(&[u8], &[u8]), String> {
    let word = |at: usize| {
        bytes
            .get(at..at + 4)
            .map(|w| u32::from_le_bytes(w.try_into().unwrap()) as usize)
            .ok_or_else(|| format!("truncated GLB: {} bytes", bytes.len()))
    };
    if bytes.get(..4) != Some(b"glTF") {
        return Err("not a GLB file (no `glTF` magic)".into());
    }
    if word(4)? != 2 {
        return Err(format!(
            "GLB version {} is not supported (only 2)",
            word(4)?
        ));
    }
    if word(8)? > bytes.len() {
        return Err(format!(
            "GLB header says {} bytes, the file has {}",
            word(8)?,
            bytes.len()
        ));
    }
    let mut chunks = Vec::new();
    let mut at = 12;
    while at + 8 <= bytes.len() {
        let (len, kind) = (word(at)?, word(at + 4)?);
        let data = bytes
            .get(at + 8..(at + 8).saturating_add(len))
            .ok_or_else(|| format!("chunk at byte {at} runs past the end of the file"))?;
        chunks.push((kind, data));
        at += 8 + len;
    }
    const JSON: usize = 0x4E4F_534A;
    const BIN: usize = 0x004E_4942;
    match chunks.as_slice() {
        [(JSON, json), (BIN, bin), ..] => Ok((json, bin)),
        [(JSON, json)] => Ok((json, &[])),
        _ => Err("the first GLB chunk is not JSON".into()),
    }
}

#[derive(Deserialize)]
#[serde(rename_all = "camelCase")]
struct Gltf {
    #[serde(default)]
    accessors: Vec<Accessor>,
    #[serde(default)]
    buffer_views: Vec<BufferView>,
    #[serde(default)]
    meshes: Vec<GltfMesh>,
    #[serde(default)]
    nodes: Vec<Node>,
    #[serde(default)]
    scenes: Vec<GltfScene>,
    scene: Option<usize>,
    #[serde(default)]
    materials: Vec<GltfMaterial>,
}

#[derive(Deserialize)]
#[serde(rename_all = "camelCase")]
struct Accessor {
    buffer_view: Option<usize>,
    #[serde(default)]
    byte_offset: usize,
    component_type: u32,
    count: usize,
    #[serde(rename = "type")]
    kind: String,
}

#[derive(Deserialize)]
#[serde(rename_all = "camelCase")]
struct BufferView {
    #[serde(default)]
    buffer: usize,
    #[serde(default)]
    byte_offset: usize,
    byte_length: usize,
    byte_stride: Option<usize>,
}

#[derive(Deserialize)]
struct GltfMesh {
    primitives: Vec<Primitive>,
}

#[derive(Deserialize)]
struct Primitive {
    attributes: HashMap<String, usize>,
    indices: Option<usize>,
    mode: Option<u32>,
    material: Option<usize>,
    #[serde(default)]
    extensions: PrimitiveExtensions,
}

#[derive(Deserialize, Default)]
struct PrimitiveExtensions {
    #[serde(rename = "KHR_draco_mesh_compression")]
    draco: Option<DracoExtension>,
}

#[derive(Deserialize)]
#[serde(rename_all = "camelCase")]
struct DracoExtension {
    buffer_view: usize,
    attributes: HashMap<String, u32>,
}

#[derive(Deserialize)]
struct Node {
    mesh: Option<usize>,
    #[serde(default)]
    children: Vec<usize>,
    matrix: Option<[f32; 16]>,
    translation: Option<[f32; 3]>,
    rotation: Option<[f32; 4]>,
    scale: Option<[f32; 3]>,
}

impl Node {
    fn local_transform(&self) -> Mat4 {
        match self.matrix {
            Some(m) => Mat4::from_cols_array(&m),
            None => Mat4::from_scale_rotation_translation(
                self.scale.map_or(Vec3::ONE, Vec3::from),
                self.rotation.map_or(Quat::IDENTITY, Quat::from_array),
                self.translation.map_or(Vec3::ZERO, Vec3::from),
            ),
        }
    }
}

#[derive(Deserialize)]
struct GltfScene {
    #[serde(default)]
    nodes: Vec<usize>,
}

#[derive(Deserialize)]
#[serde(rename_all = "camelCase")]
struct GltfMaterial {
    name: Option<String>,
    pbr_metallic_roughness: Option<Pbr>,
    #[serde(default)]
    alpha_mode: AlphaMode,
    alpha_cutoff: Option<f32>,
}

#[derive(Deserialize, Default, Clone, Copy)]
#[serde(rename_all = "UPPERCASE")]
enum AlphaMode {
    #[default]
    Opaque,
    Mask,
    Blend,
}

#[derive(Deserialize)]
#[serde(rename_all = "camelCase")]
struct Pbr {
    base_color_factor: Option<[f32; 4]>,
}

fn convert_material((index, m): (usize, &GltfMaterial)) -> Material {
    let mut material =
        Material::named(&m.name.clone().unwrap_or_else(|| format!("material{index}")));
    if let Some([r, g, b, a]) = m
        .pbr_metallic_roughness
        .as_ref()
        .and_then(|p| p.base_color_factor)
    {
        material.kd = Vec3::new(r, g, b);
        material.opacity = match m.alpha_mode {
            AlphaMode::Opaque => 1.0,
            AlphaMode::Blend => a,
            AlphaMode::Mask if a >= m.alpha_cutoff.unwrap_or(0.5) => 1.0,
            AlphaMode::Mask => 0.0,
        };
    }
    material
}

impl Gltf {
    /// Every (mesh index, world transform) reachable from the default scene,
    /// or from all root nodes when the file names no scene.
    fn mesh_nodes(&self) -> Result<Vec<(usize, Mat4)>, String> {
        let roots: Vec<usize> = match self.scenes.get(self.scene.unwrap_or(0)) {
            Some(scene) => scene.nodes.clone(),
            None => {
                let children: Vec<usize> =
                    self.nodes.iter().flat_map(|n| n.children.clone()).collect();
                (0..self.nodes.len())
                    .filter(|i| !children.contains(i))
                    .collect()
            }
        };
        let mut found = Vec::new();
        let mut visited = vec![false; self.nodes.len()];
        let mut stack: Vec<(usize, Mat4)> =
            roots.into_iter().map(|r| (r, Mat4::IDENTITY)).collect();
        while let Some((index, parent)) = stack.pop() {
            let node = self.nodes.get(index).ok_or(format!("no node {index}"))?;
            // A tree visits each node once; a cycle or a shared child would
            // repeat (or multiply) work without end.
            if std::mem::replace(&mut visited[index], true) {
                return Err(format!(
                    "node {index} is reached twice (glTF nodes must form a tree)"
                ));
            }
            let world = parent * node.local_transform();
            if let Some(mesh) = node.mesh {
                found.push((mesh, world));
            }
            stack.extend(node.children.iter().map(|&c| (c, world)));
        }
        Ok(found)
    }

    fn primitive(&self, primitive: &Primitive, bin: &[u8]) -> Result<TriangleMesh, String> {
        match &primitive.extensions.draco {
            Some(draco) => self.draco_primitive(draco, bin),
            None => self.plain_primitive(primitive, bin),
        }
    }

    fn view<'a>(&self, index: usize, bin: &'a [u8]) -> Result<(&'a [u8], Option<usize>), String> {
        let view = self
            .buffer_views
            .get(index)
            .ok_or(format!("no bufferView {index}"))?;
        if view.buffer != 0 {
            return Err(format!(
                "bufferView {index} uses buffer {}; only the GLB's own buffer is read",
                view.buffer
            ));
        }
        let data = bin
            .get(view.byte_offset..view.byte_offset.saturating_add(view.byte_length))
            .ok_or(format!(
                "bufferView {index} runs past the end of the BIN chunk"
            ))?;
        Ok((data, view.byte_stride))
    }

    fn draco_primitive(&self, draco: &DracoExtension, bin: &[u8]) -> Result<TriangleMesh, String> {
        let (data, _) = self.view(draco.buffer_view, bin)?;
        let mut decoded = draco_core::Mesh::new();
        draco_core::MeshDecoder::new()
            .decode(&mut draco_core::DecoderBuffer::new(data), &mut decoded)
            .map_err(|e| format!("Draco decoding failed: {e}"))?;
        let points = decoded.num_points();
        let read = |name: &str, components: usize| -> Result<Option<Vec<f32>>, String> {
            let Some(&id) = draco.attributes.get(name) else {
                return Ok(None);
            };
            let attribute = decoded
                .attribute_by_unique_id(id)
                .ok_or(format!("the Draco data has no attribute {id} for {name}"))?;
            Ok(Some(attribute.read_f32s(points, components)))
        };
        let positions = read("POSITION", 3)?.ok_or("the primitive has no POSITION")?;
        let normals = read("NORMAL", 3)?;
        let texcoords = read("TEXCOORD_0", 2)?;
        let indices = decoded.faces().iter().map(|f| f.map(|p| p.0)).collect();
        Ok(TriangleMesh {
            positions: to_vec3(&positions),
            indices,
            normals: normals.map(|n| to_vec3(&n)),
            texcoords: texcoords.map(|t| to_uv(&t)),
            materials: Vec::new(),
        })
    }

    fn plain_primitive(&self, primitive: &Primitive, bin: &[u8]) -> Result<TriangleMesh, String> {
        let read = |name: &str, kind: &str| -> Result<Option<Vec<f32>>, String> {
            primitive
                .attributes
                .get(name)
                .map(|&a| {
                    self.read_floats(a, kind, bin)
                        .map_err(|e| format!("{name}: {e}"))
                })
                .transpose()
        };
        let positions = to_vec3(&read("POSITION", "VEC3")?.ok_or("the primitive has no POSITION")?);
        let indices: Vec<u32> = match primitive.indices {
            Some(a) => self
                .read_indices(a, bin)
                .map_err(|e| format!("indices: {e}"))?,
            None => (0..positions.len() as u32).collect(),
        };
        if !indices.len().is_multiple_of(3) {
            return Err(format!(
                "{} indices is not a whole number of triangles",
                indices.len()
            ));
        }
        Ok(TriangleMesh {
            indices: indices
                .chunks_exact(3)
                .map(|t| [t[0], t[1], t[2]])
                .collect(),
            normals: read("NORMAL", "VEC3")?.map(|n| to_vec3(&n)),
            texcoords: read("TEXCOORD_0", "VEC2")?.map(|t| to_uv(&t)),
            positions,
            materials: Vec::new(),
        })
    }

    /// The elements of accessor `index`, each `size` bytes, as byte slices.
    fn elements<'a>(
        &self,
        index: usize,
        size: usize,
        bin: &'a [u8],
    ) -> Result<Vec<&'a [u8]>, String> {
        let accessor = self
            .accessors
            .get(index)
            .ok_or(format!("no accessor {index}"))?;
        let view = accessor
            .buffer_view
            .ok_or(format!("accessor {index} has no bufferView"))?;
        let (data, stride) = self.view(view, bin)?;
        let stride = stride.unwrap_or(size);
        if stride < size {
            return Err(format!(
                "bufferView {view} has byteStride {stride}, less than the {size}-byte elements of accessor {index}"
            ));
        }
        // Checked before anything is allocated: a lying count must not
        // reserve memory or loop for elements the data cannot hold.
        let end = match accessor.count {
            0 => Some(0),
            n => (n - 1)
                .checked_mul(stride)
                .and_then(|last| last.checked_add(accessor.byte_offset))
                .and_then(|last| last.checked_add(size)),
        };
        if end.is_none_or(|end| end > data.len()) {
            return Err(format!(
                "accessor {index} has {} elements, more than its bufferView of {} bytes holds",
                accessor.count,
                data.len()
            ));
        }
        Ok((0..accessor.count)
            .map(|i| {
                let start = accessor.byte_offset + i * stride;
                &data[start..start + size]
            })
            .collect())
    }

    fn read_floats(&self, index: usize, kind: &str, bin: &[u8]) -> Result<Vec<f32>, String> {
        let accessor = self
            .accessors
            .get(index)
            .ok_or(format!("no accessor {index}"))?;
        let components = if kind == "VEC3" { 3 } else { 2 };
        if accessor.kind != kind || accessor.component_type != 5126 {
            return Err(format!(
                "expected float {kind}, found {} of component type {}",
                accessor.kind, accessor.component_type
            ));
        }
        Ok(self
            .elements(index, 4 * components, bin)?
            .iter()
            .flat_map(|e| {
                e.chunks_exact(4)
                    .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
            })
            .collect())
    }

    fn read_indices(&self, index: usize, bin: &[u8]) -> Result<Vec<u32>, String> {
        let accessor = self
            .accessors
            .get(index)
            .ok_or(format!("no accessor {index}"))?;
        let size = match accessor.component_type {
            5121 => 1,
            5123 => 2,
            5125 => 4,
            other => return Err(format!("component type {other} is not an index type")),
        };
        Ok(self
            .elements(index, size, bin)?
            .iter()
            .map(|e| match e.len() {
                1 => e[0] as u32,
                2 => u16::from_le_bytes([e[0], e[1]]) as u32,
                _ => u32::from_le_bytes([e[0], e[1], e[2], e[3]]),
            })
            .collect())
    }
}

fn to_vec3(values: &[f32]) -> Vec<Vec3> {
    values.chunks_exact(3).map(Vec3::from_slice).collect()
}

/// glTF texture coordinates (v down) in OBJ's convention (v up).
fn to_uv(values: &[f32]) -> Vec<Vec2> {
    values
        .chunks_exact(2)
        .map(|t| Vec2::new(t[0], 1.0 - t[1]))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A GLB holding one uncompressed triangle under a translated node.
    fn plain_glb() -> Vec<u8> {
        let mut bin = Vec::new();
        for v in [
            0.0f32, 0., 0., 1., 0., 0., 0., 1., 0., 0., 0., 1., 0., 0., 0.25,
        ] {
            bin.extend(v.to_le_bytes());
        }
        for i in [0u16, 1, 2, 0] {
            bin.extend(i.to_le_bytes());
        }
        let json = r#"{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],
            "nodes":[{"translation":[10,0,0],"children":[1]},{"mesh":0}],
            "meshes":[{"primitives":[{"attributes":{"POSITION":0,"TEXCOORD_0":1},"indices":2}]}],
            "buffers":[{"byteLength":66}],
            "bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":36},
                           {"buffer":0,"byteOffset":36,"byteLength":24},
                           {"buffer":0,"byteOffset":60,"byteLength":6}],
            "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"},
                         {"bufferView":1,"componentType":5126,"count":3,"type":"VEC2"},
                         {"bufferView":2,"componentType":5123,"count":3,"type":"SCALAR"}]}"#;
        let mut json = json.as_bytes().to_vec();
        json.resize(json.len().next_multiple_of(4), b' ');
        let total = 12 + 8 + json.len() + 8 + bin.len();
        let mut out = b"glTF".to_vec();
        for word in [2, total, json.len(), 0x4E4F_534A] {
            out.extend((word as u32).to_le_bytes());
        }
        out.extend(&json);
        for word in [bin.len(), 0x004E_4942] {
            out.extend((word as u32).to_le_bytes());
        }
        out.extend(&bin);
        out
    }

    #[test]
    fn plain_glb_triangles_get_node_transforms() {
        let loaded = parse(Path::new("t.glb"), &plain_glb()).unwrap();
        let mesh = loaded.mesh;
        assert_eq!(mesh.indices, vec![[0, 1, 2]]);
        assert_eq!(mesh.positions[1], Vec3::new(11.0, 0.0, 0.0));
        assert_eq!(loaded.materials.len(), 1);
        // v flipped to point up.
        let uv = mesh.texcoords.unwrap();
        assert_eq!(uv[0], Vec2::new(0.0, 1.0));
        assert_eq!(uv[2], Vec2::new(0.0, 0.75));
    }

    #[test]
    fn base_colour_alpha_counts_only_as_the_alpha_mode_says() {
        let opacity = |json: &str| {
            let material: GltfMaterial = serde_json::from_str(json).unwrap();
            convert_material((0, &material)).opacity
        };
        let colour = r#""pbrMetallicRoughness":{"baseColorFactor":[1,1,1,0.4]}"#;
        assert_eq!(opacity(&format!("{{{colour}}}")), 1.0);
        assert_eq!(
            opacity(&format!(r#"{{{colour},"alphaMode":"OPAQUE"}}"#)),
            1.0
        );
        assert_eq!(
            opacity(&format!(r#"{{{colour},"alphaMode":"BLEND"}}"#)),
            0.4
        );
        assert_eq!(opacity(&format!(r#"{{{colour},"alphaMode":"MASK"}}"#)), 0.0);
        assert_eq!(
            opacity(&format!(
                r#"{{{colour},"alphaMode":"MASK","alphaCutoff":0.25}}"#
            )),
            1.0
        );
        assert!(serde_json::from_str::<GltfMaterial>(r#"{"alphaMode":"GLASS"}"#).is_err());
    }

    #[test]
    fn every_truncation_of_a_glb_is_an_error() {
        let glb = plain_glb();
        for len in 0..glb.len() {
            let err = parse(Path::new("t.glb"), &glb[..len]).unwrap_err();
            assert!(err.to_string().starts_with("t.glb: "), "{err}");
        }
    }
}
