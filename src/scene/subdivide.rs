//! Midpoint subdivision of a mesh, for scenes larger than any packaged
//! mesh: each level splits every triangle into four at its edges'
//! midpoints (shared edges share their midpoint, so the mesh stays
//! watertight), keeping its material, with per-vertex normals and texture
//! coordinates averaged at the new vertices. The surface does not change,
//! only its triangle count, by 4 per level.
//!
//! The result is cached in `<cache>/subdivided/` (the asset cache, see
//! [`assets::cache_dir`]) under a SHA-256 of the source mesh's data and the
//! level count, so editing the source or the levels makes a new one; a
//! cache that cannot be read or written is not an error, the mesh is
//! subdivided again.

use super::assets;
use super::error::SceneError;
use crate::geometry::TriangleMesh;
use glam::{Vec2, Vec3};
use sha2::{Digest, Sha256};
use std::collections::HashMap;
use std::io::{BufReader, BufWriter, Read, Write};
use std::path::{Path, PathBuf};

/// The most levels a manifest may ask for: 4⁶ = 4096 times the triangles.
pub const MAX_LEVELS: u32 = 6;

/// Bumped whenever the subdivision or the cache format changes.
const FORMAT_VERSION: u32 = 1;

/// `mesh` subdivided `levels` times, from the cache when it holds it.
/// `source` names the mesh's file in errors.
pub fn subdivided(
    mesh: &TriangleMesh,
    levels: u32,
    source: &Path,
) -> Result<TriangleMesh, SceneError> {
    check_size(mesh.indices.len(), mesh.positions.len(), levels, source)?;
    let cache = assets::cache_dir().ok().map(|dir| dir.join("subdivided"));
    Ok(subdivided_in(cache.as_deref(), mesh, levels))
}

/// [`subdivided`] with the cache in `cache` (none when `None`).
fn subdivided_in(cache: Option<&Path>, mesh: &TriangleMesh, levels: u32) -> TriangleMesh {
    let path = cache.map(|dir| dir.join(format!("{}.bin", cache_key(mesh, levels))));
    if let Some(cached) = path.as_deref().and_then(read) {
        return cached;
    }
    let mut result = mesh.clone();
    for _ in 0..levels {
        result = subdivide(&result);
    }
    if let Some(path) = path
        && write(&path, &result).is_err()
    {
        eprintln!(
            "note: could not cache the subdivided mesh at {}",
            path.display()
        );
    }
    result
}

/// Whether `levels` of subdivision of a mesh of `triangles` triangles and
/// `vertices` vertices stay within a mesh's u32 indices: the error names
/// the levels and the counts.
fn check_size(
    triangles: usize,
    vertices: usize,
    levels: u32,
    source: &Path,
) -> Result<(), SceneError> {
    if levels > MAX_LEVELS {
        return Err(SceneError::in_file(
            source,
            format!("subdivide = {levels}: at most {MAX_LEVELS} levels"),
        ));
    }
    let triangles = (triangles as u64) << (2 * levels);
    // Each level adds one vertex per edge, at most 1.5 per triangle.
    let vertices = vertices as u64 + triangles * 3 / 2;
    if triangles > u64::from(u32::MAX) || vertices > u64::from(u32::MAX) {
        return Err(SceneError::in_file(
            source,
            format!(
                "subdivide = {levels} would make {triangles} triangles and up to {vertices} \
                 vertices, beyond the {} a mesh can index",
                u32::MAX
            ),
        ));
    }
    Ok(())
}

/// One level: every triangle into four.
pub fn subdivide(mesh: &TriangleMesh) -> TriangleMesh {
    let mut out = TriangleMesh {
        positions: mesh.positions.clone(),
        indices: Vec::with_capacity(4 * mesh.indices.len()),
        normals: mesh.normals.clone(),
        texcoords: mesh.texcoords.clone(),
        materials: Vec::with_capacity(4 * mesh.materials.len()),
    };
    // The midpoint vertex of each edge, by its ends in increasing order;
    // numbered in the order edges are first met, so the result depends on
    // the mesh alone.
    let mut midpoints: HashMap<(u32, u32), u32> =
        HashMap::with_capacity(mesh.indices.len() * 3 / 2);
    let mut midpoint = |a: u32, b: u32, out: &mut TriangleMesh| {
        *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
            let (a, b) = (a as usize, b as usize);
            out.positions
                .push(average(mesh.positions[a], mesh.positions[b]));
            if let Some(normals) = &mut out.normals {
                normals.push((normals[a] + normals[b]).normalize_or_zero());
            }
            if let Some(texcoords) = &mut out.texcoords {
                texcoords.push(0.5 * (texcoords[a] + texcoords[b]));
            }
            out.positions.len() as u32 - 1
        })
    };
    for (&[a, b, c], &material) in mesh.indices.iter().zip(&mesh.materials) {
        let ab = midpoint(a, b, &mut out);
        let bc = midpoint(b, c, &mut out);
        let ca = midpoint(c, a, &mut out);
        out.indices
            .extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
        out.materials.extend([material; 4]);
    }
    out
}

/// The midpoint of `p` and `q`, the same bits either way round.
fn average(p: Vec3, q: Vec3) -> Vec3 {
    0.5 * (p + q)
}

/// A SHA-256 of everything the result depends on, in hex.
fn cache_key(mesh: &TriangleMesh, levels: u32) -> String {
    let mut hash = Sha256::new();
    hash.update(FORMAT_VERSION.to_le_bytes());
    hash.update(levels.to_le_bytes());
    let mut write_words = |words: &mut dyn Iterator<Item = u32>| {
        words.for_each(|w| hash.update(w.to_le_bytes()));
    };
    write_words(
        &mut [mesh.positions.len(), mesh.indices.len()]
            .iter()
            .map(|&n| n as u32),
    );
    write_words(
        &mut mesh
            .positions
            .iter()
            .flat_map(|p| p.to_array())
            .map(f32::to_bits),
    );
    write_words(&mut mesh.indices.iter().flatten().copied());
    write_words(&mut mesh.materials.iter().copied());
    for attribute in [
        mesh.normals
            .as_ref()
            .map(|n| n.iter().flat_map(|v| v.to_array()).collect::<Vec<_>>()),
        mesh.texcoords
            .as_ref()
            .map(|t| t.iter().flat_map(|v| v.to_array()).collect::<Vec<_>>()),
    ] {
        let values = attribute.unwrap_or_default();
        write_words(&mut std::iter::once(values.len() as u32));
        write_words(&mut values.iter().map(|x| x.to_bits()));
    }
    super::assets::hex(&hash.finalize())
}

/// The magic first bytes of a cached mesh.
const MAGIC: &[u8; 8] = b"RCSUBDIV";

/// Little-endian: magic, version, vertex and triangle counts, whether
/// normals and texcoords follow, then positions, indices, materials,
/// normals, texcoords. Written to a temporary file renamed into place, so
/// a reader never sees half a file.
fn write(path: &Path, mesh: &TriangleMesh) -> std::io::Result<()> {
    let dir = path.parent().unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir)?;
    let partial = temporary_path(path);
    {
        let mut out = BufWriter::new(std::fs::File::create(&partial)?);
        out.write_all(MAGIC)?;
        let flags = u32::from(mesh.normals.is_some()) | u32::from(mesh.texcoords.is_some()) << 1;
        for word in [
            FORMAT_VERSION,
            mesh.positions.len() as u32,
            mesh.indices.len() as u32,
            flags,
        ] {
            out.write_all(&word.to_le_bytes())?;
        }
        let floats = mesh.positions.iter().flat_map(|p| p.to_array());
        let normals = mesh.normals.iter().flatten().flat_map(|n| n.to_array());
        let texcoords = mesh.texcoords.iter().flatten().flat_map(|t| t.to_array());
        let words = floats
            .map(f32::to_bits)
            .chain(mesh.indices.iter().flatten().copied())
            .chain(mesh.materials.iter().copied())
            .chain(normals.map(f32::to_bits))
            .chain(texcoords.map(f32::to_bits));
        for word in words {
            out.write_all(&word.to_le_bytes())?;
        }
        out.flush()?;
    }
    std::fs::rename(&partial, path)
}

/// A name next to `path` no other process writes to.
fn temporary_path(path: &Path) -> PathBuf {
    let mut name = path.file_name().unwrap_or_default().to_os_string();
    name.push(format!(".{}.partial", std::process::id()));
    path.with_file_name(name)
}

/// The mesh cached at `path`, or `None` when it is missing, of another
/// version, short or long, or breaks a mesh invariant.
fn read(path: &Path) -> Option<TriangleMesh> {
    let mut input = Words(BufReader::new(std::fs::File::open(path).ok()?));
    let mut magic = [0u8; 8];
    input.0.read_exact(&mut magic).ok()?;
    let [version, vertices, triangles, flags] =
        [input.word()?, input.word()?, input.word()?, input.word()?];
    if &magic != MAGIC || version != FORMAT_VERSION {
        return None;
    }
    let (vertices, triangles) = (vertices as usize, triangles as usize);
    let positions = input.vec3s(vertices)?;
    let indices = (0..triangles)
        .map(|_| Some([input.word()?, input.word()?, input.word()?]))
        .collect::<Option<Vec<_>>>()?;
    let materials = (0..triangles)
        .map(|_| input.word())
        .collect::<Option<Vec<_>>>()?;
    let normals = match flags & 1 {
        0 => None,
        _ => Some(input.vec3s(vertices)?),
    };
    let texcoords = match flags & 2 {
        0 => None,
        _ => Some(
            (0..vertices)
                .map(|_| Some(Vec2::new(input.float()?, input.float()?)))
                .collect::<Option<Vec<_>>>()?,
        ),
    };
    if input.word().is_some() {
        return None;
    }
    let mesh = TriangleMesh {
        positions,
        indices,
        normals,
        texcoords,
        materials,
    };
    mesh.check().ok().map(|()| mesh)
}

/// Little-endian words from a reader.
struct Words<R: Read>(R);

impl<R: Read> Words<R> {
    fn word(&mut self) -> Option<u32> {
        let mut bytes = [0u8; 4];
        self.0.read_exact(&mut bytes).ok()?;
        Some(u32::from_le_bytes(bytes))
    }

    fn float(&mut self) -> Option<f32> {
        self.word().map(f32::from_bits)
    }

    fn vec3s(&mut self, count: usize) -> Option<Vec<Vec3>> {
        (0..count)
            .map(|_| Some(Vec3::new(self.float()?, self.float()?, self.float()?)))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_triangle() -> TriangleMesh {
        TriangleMesh::soup(&[[Vec3::ZERO, Vec3::X, Vec3::Y]])
    }

    /// Twice the area of each triangle, in f64.
    fn area(mesh: &TriangleMesh) -> f64 {
        (0..mesh.indices.len())
            .map(|t| {
                let [a, b, c] = mesh.triangle(t).map(|p| p.as_dvec3());
                (b - a).cross(c - a).length()
            })
            .sum()
    }

    #[test]
    fn each_level_quadruples_the_triangles_and_keeps_the_surface() {
        // An octahedron: eight faces around the origin.
        let corners = vec![
            Vec3::X,
            Vec3::NEG_X,
            Vec3::Y,
            Vec3::NEG_Y,
            Vec3::Z,
            Vec3::NEG_Z,
        ];
        let faces = (0..8u32)
            .map(|f| [f & 1, 2 + (f >> 1 & 1), 4 + (f >> 2 & 1)])
            .collect();
        let mut mesh = TriangleMesh::new(corners, faces);
        mesh.materials = (0..8).collect();
        let once = subdivide(&mesh);
        assert_eq!(once.indices.len(), 4 * mesh.indices.len());
        assert!((area(&once) - area(&mesh)).abs() < 1e-5 * area(&mesh));
        once.check().unwrap();
        // Children keep their parent's material.
        assert!(
            once.materials
                .chunks(4)
                .enumerate()
                .all(|(t, m)| m == [t as u32; 4])
        );
    }

    #[test]
    fn shared_edges_share_their_midpoint() {
        // Two triangles sharing the edge (1, 2): 4 corners and 5 distinct
        // edges give 9 vertices.
        let mesh = TriangleMesh::new(
            vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::ONE],
            vec![[0, 1, 2], [2, 1, 3]],
        );
        let once = subdivide(&mesh);
        assert_eq!(once.positions.len(), 9);
        assert_eq!(once.positions[4], Vec3::new(0.5, 0.0, 0.0));
        // The shared edge's midpoint appears in children of both.
        let shared = once
            .positions
            .iter()
            .position(|&p| p == Vec3::new(0.5, 0.5, 0.0))
            .unwrap() as u32;
        let users = once.indices.iter().filter(|t| t.contains(&shared)).count();
        assert_eq!(users, 6);
    }

    #[test]
    fn normals_and_texcoords_are_averaged() {
        let mut mesh = unit_triangle();
        mesh.normals = Some(vec![Vec3::Z, Vec3::Z, Vec3::X]);
        mesh.texcoords = Some(vec![Vec2::ZERO, Vec2::X, Vec2::Y]);
        let once = subdivide(&mesh);
        let normals = once.normals.unwrap();
        let texcoords = once.texcoords.unwrap();
        assert_eq!((normals[3], texcoords[3]), (Vec3::Z, Vec2::new(0.5, 0.0)));
        assert!((normals[4] - Vec3::new(1.0, 0.0, 1.0).normalize()).length() < 1e-6);
    }

    #[test]
    fn the_cache_round_trips_and_is_keyed_by_the_source() {
        let dir = tempfile::tempdir().unwrap();
        let mut mesh = unit_triangle();
        mesh.texcoords = Some(vec![Vec2::ZERO, Vec2::X, Vec2::Y]);
        let fresh = subdivided_in(None, &mesh, 2);
        assert_eq!(fresh.indices.len(), 16);
        assert_eq!(subdivided_in(Some(dir.path()), &mesh, 2), fresh);
        let files = || std::fs::read_dir(dir.path()).unwrap().count();
        assert_eq!(files(), 1);
        // A second load reads the cache.
        assert_eq!(subdivided_in(Some(dir.path()), &mesh, 2), fresh);
        assert_eq!(files(), 1);
        // Another level count or another source is another entry.
        assert_eq!(subdivided_in(Some(dir.path()), &mesh, 1).indices.len(), 4);
        mesh.positions[0].x = 0.25;
        subdivided_in(Some(dir.path()), &mesh, 2);
        assert_eq!(files(), 3);
        // A damaged cache file is ignored and rewritten.
        for entry in std::fs::read_dir(dir.path()).unwrap() {
            let path = entry.unwrap().path();
            let bytes = std::fs::read(&path).unwrap();
            std::fs::write(&path, &bytes[..bytes.len() - 3]).unwrap();
        }
        mesh.positions[0].x = 0.0;
        assert_eq!(subdivided_in(Some(dir.path()), &mesh, 2), fresh);
    }

    #[test]
    fn sizes_beyond_the_indices_are_named() {
        let source = Path::new("big.ply");
        let error = check_size(1, 3, MAX_LEVELS + 1, source).unwrap_err();
        assert!(error.to_string().contains("at most 6 levels"), "{error}");
        // 2^28 triangles, two levels: 2^32, one more than u32 indexes.
        let error = check_size(1 << 28, 1 << 27, 2, source).unwrap_err();
        assert!(
            error.to_string().contains("4294967296 triangles"),
            "{error}"
        );
        assert!(check_size(1 << 20, 1 << 19, 2, source).is_ok());
        assert!(check_size(871_414, 437_645, 2, source).is_ok());
    }

    /// A manifest's `subdivide` quadruples its mesh per level, and too
    /// many levels are an error naming the manifest and the line.
    #[test]
    fn manifests_subdivide_their_meshes() {
        let dir = tempfile::tempdir().unwrap();
        let cube = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cube.obj");
        let manifest = |levels: u32| {
            let path = dir.path().join(format!("cube-{levels}.toml"));
            let text = format!(
                "[[mesh]]\npath = {:?}\nsubdivide = {levels}\n",
                cube.display().to_string()
            );
            std::fs::write(&path, text).unwrap();
            path
        };
        let plain = crate::scene::load_mesh_file(&cube).unwrap().mesh;
        let scene = crate::scene::formats::manifest::load(&manifest(2)).unwrap();
        assert_eq!(scene.mesh.indices.len(), 16 * plain.indices.len());
        assert_eq!(scene.mesh.bounds(), plain.bounds());
        let error = crate::scene::formats::manifest::load(&manifest(7))
            .unwrap_err()
            .to_string();
        assert!(
            error.contains("cube-7.toml:1:") && error.contains("at most 6 levels"),
            "{error}"
        );
    }
}
