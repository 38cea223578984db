//! Wavefront OBJ meshes with MTL materials, parsed by `tobj`.
//!
//! `tobj` reports errors without line numbers, so the file is first scanned
//! line by line for everything `tobj` would trip on (unparsable or
//! non-finite numbers, zero or out-of-range indices, missing material
//! libraries, unknown `usemtl` names, missing textures); only a file that
//! passes goes to `tobj`.
//!
//! A face naming a texcoord or normal index the file does not have (a
//! common exporter slip) is not an error: that attribute is left out of the
//! whole mesh, with a [`LoadWarning`] naming the first such line. A bad
//! position index stays an error.
//!
//! MTL statements used: `Kd`, `Ks`, `Ns`, `d` (or `Tr` = 1 - opacity),
//! `map_Kd` (resolved relative to the MTL file), and `illum 3`
//! ("reflection on") which makes the material a mirror whose reflectance is
//! its `Ks`.

use super::text::{finite_f32, numbered_lines};
use crate::geometry::TriangleMesh;
use crate::scene::LoadedMesh;
use crate::scene::error::{SceneError, read_file};
use crate::scene::material::Material;
use crate::scene::warning::LoadWarning;
use glam::{Vec2, Vec3};
use std::borrow::Cow;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Loads an `.obj` file and the MTL libraries it names.
pub fn load(path: &Path) -> Result<LoadedMesh, SceneError> {
    parse_bytes(path, &read_file(path)?)
}

/// Parses OBJ bytes; `path` names the file in errors and anchors the
/// relative paths of its `mtllib` statements.
pub fn parse_bytes(path: &Path, bytes: &[u8]) -> Result<LoadedMesh, SceneError> {
    let Scan { libraries, missing } = scan_obj(path, bytes)?;
    let dropped = missing.each_ref().map(Option::is_some);
    let bytes: Cow<[u8]> = if dropped.contains(&true) {
        Cow::Owned(without_attributes(bytes, dropped))
    } else {
        Cow::Borrowed(bytes)
    };
    let warnings = ATTRIBUTES
        .iter()
        .zip(missing)
        .filter_map(|(attribute, missing)| Some(missing?.warning(path, attribute)))
        .collect();
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let (models, materials) = tobj::load_obj_buf(&mut &bytes[..], &options, |lib| {
        let source = libraries
            .sources
            .get(lib)
            .ok_or(tobj::LoadError::OpenFileFailed)?;
        tobj::load_mtl_buf(&mut source.as_slice())
    })
    .map_err(|e| SceneError::in_file(path, format!("OBJ parse error: {e}")))?;
    let mut materials: Vec<Material> = materials
        .map_err(|e| SceneError::in_file(path, format!("MTL parse error: {e}")))?
        .iter()
        .map(|m| convert_material(m, &libraries.textures))
        .collect();
    let default_id = materials.len() as u32;
    let mut mesh = TriangleMesh::default();
    for model in &models {
        let part = convert_model(&model.mesh, default_id);
        mesh.append(&part, 0);
    }
    if mesh.indices.is_empty() {
        return Err(SceneError::in_file(path, "no faces: the mesh is empty"));
    }
    if mesh.materials.contains(&default_id) {
        materials.push(Material::default());
    }
    mesh.check().map_err(|e| SceneError::in_file(path, e))?;
    Ok(LoadedMesh {
        mesh,
        materials,
        warnings,
    })
}

/// Parses MTL bytes on their own into materials, with the checks the OBJ
/// loader applies to its libraries; `path` names the file in errors and
/// anchors texture paths.
pub fn parse_mtl_bytes(path: &Path, bytes: &[u8]) -> Result<Vec<Material>, SceneError> {
    let mut libraries = Libraries::default();
    scan_mtl(path, bytes, &mut libraries)?;
    let (materials, _) = tobj::load_mtl_buf(&mut &bytes[..])
        .map_err(|e| SceneError::in_file(path, format!("MTL parse error: {e}")))?;
    Ok(materials
        .iter()
        .map(|m| convert_material(m, &libraries.textures))
        .collect())
}

fn convert_model(m: &tobj::Mesh, default_material: u32) -> TriangleMesh {
    let vec3s = |v: &[f32]| v.chunks_exact(3).map(Vec3::from_slice).collect::<Vec<_>>();
    let positions = vec3s(&m.positions);
    let n = positions.len();
    let indices: Vec<[u32; 3]> = m
        .indices
        .chunks_exact(3)
        .map(|t| [t[0], t[1], t[2]])
        .collect();
    TriangleMesh {
        materials: vec![m.material_id.map_or(default_material, |id| id as u32); indices.len()],
        normals: (m.normals.len() == 3 * n && n > 0).then(|| vec3s(&m.normals)),
        texcoords: (m.texcoords.len() == 2 * n && n > 0)
            .then(|| m.texcoords.chunks_exact(2).map(Vec2::from_slice).collect()),
        positions,
        indices,
    }
}

fn convert_material(m: &tobj::Material, textures: &HashMap<String, PathBuf>) -> Material {
    let default = Material::default();
    let ks = m.specular.map_or(default.ks, Vec3::from);
    let opacity = m.dissolve.or_else(|| {
        m.unknown_param
            .get("Tr")
            .and_then(|t| t.trim().parse::<f32>().ok())
            .map(|tr| 1.0 - tr)
    });
    Material {
        name: m.name.clone(),
        kd: m.diffuse.map_or(default.kd, Vec3::from),
        ks,
        shininess: m.shininess.unwrap_or(default.shininess),
        mirror: if m.illumination_model == Some(3) {
            ks
        } else {
            Vec3::ZERO
        },
        opacity: opacity.unwrap_or(1.0),
        diffuse_texture: textures.get(&m.name).cloned(),
        ..default
    }
}

/// What the scan learned from the material libraries.
#[derive(Default)]
struct Libraries {
    /// Material names defined so far.
    names: Vec<String>,
    /// Resolved diffuse texture of each material that has one.
    textures: HashMap<String, PathBuf>,
    /// The bytes of each library, by the name `mtllib` gave it.
    sources: HashMap<PathBuf, Vec<u8>>,
}

/// Attribute counts, for index checks.
#[derive(Default, Clone, Copy)]
struct Counts {
    positions: i64,
    texcoords: i64,
    normals: i64,
}

/// The optional parts of a face corner `v/t/n`, in that order, as what the
/// mesh is without when one is dropped.
const ATTRIBUTES: [&str; 2] = ["texture coordinates", "vertex normals"];

/// What the scan learned: the material libraries, and for each of
/// [`ATTRIBUTES`] the faces that name an index the file does not have.
struct Scan {
    libraries: Libraries,
    missing: [Option<Missing>; 2],
}

/// Faces naming an attribute index the file does not have.
struct Missing {
    first_line: usize,
    first_problem: String,
    faces: usize,
}

impl Missing {
    fn warning(self, path: &Path, attribute: &str) -> LoadWarning {
        let others = match self.faces - 1 {
            0 => String::new(),
            1 => " (1 more face names an index the file lacks)".into(),
            n => format!(" ({n} more faces name indices the file lacks)"),
        };
        LoadWarning {
            path: path.to_path_buf(),
            line: self.first_line,
            message: format!(
                "{}; the mesh is loaded without {attribute}{others}",
                self.first_problem
            ),
        }
    }
}

fn scan_obj(path: &Path, bytes: &[u8]) -> Result<Scan, SceneError> {
    let mut totals = Counts::default();
    for (_, line) in numbered_lines(bytes) {
        match line.ok().and_then(|l| l.split_ascii_whitespace().next()) {
            Some("v") => totals.positions += 1,
            Some("vt") => totals.texcoords += 1,
            Some("vn") => totals.normals += 1,
            _ => {}
        }
    }
    let mut so_far = Counts::default();
    let mut libraries = Libraries::default();
    let mut missing: [Option<Missing>; 2] = [None, None];
    let dir = path.parent().unwrap_or(Path::new("."));
    for (number, line) in numbered_lines(bytes) {
        let err = |msg: String| SceneError::at(path, number, msg);
        let line = line.map_err(err)?;
        let line = line.split('#').next().unwrap_or_default();
        let mut words = line.split_ascii_whitespace();
        let Some(keyword) = words.next() else {
            continue;
        };
        let args: Vec<&str> = words.collect();
        match keyword {
            "v" => {
                numbers(&args, 3, "vertex coordinate").map_err(err)?;
                so_far.positions += 1;
            }
            "vt" => {
                numbers(&args, 1, "texture coordinate").map_err(err)?;
                so_far.texcoords += 1;
            }
            "vn" => {
                numbers(&args, 3, "normal component").map_err(err)?;
                so_far.normals += 1;
            }
            "f" => {
                if args.len() < 3 {
                    return Err(err(format!(
                        "a face needs at least 3 vertices, this one has {}",
                        args.len()
                    )));
                }
                let mut problems = [None, None];
                for corner in &args {
                    let found = check_corner(corner, totals, so_far).map_err(err)?;
                    for (problem, new) in problems.iter_mut().zip(found) {
                        *problem = problem.take().or(new);
                    }
                }
                for (missing, problem) in missing.iter_mut().zip(problems) {
                    let Some(problem) = problem else { continue };
                    missing
                        .get_or_insert(Missing {
                            first_line: number,
                            first_problem: problem,
                            faces: 0,
                        })
                        .faces += 1;
                }
            }
            "mtllib" => {
                let name = line.trim_start()["mtllib".len()..].trim();
                let mtl = dir.join(name);
                if !mtl.is_file() {
                    return Err(err(format!(
                        "material library {name:?} not found (looked for {})",
                        mtl.display()
                    )));
                }
                let source = read_file(&mtl)?;
                scan_mtl(&mtl, &source, &mut libraries)?;
                libraries.sources.insert(PathBuf::from(name), source);
            }
            "usemtl" => {
                let name = line.trim_start()["usemtl".len()..].trim();
                if !libraries.names.iter().any(|n| n == name) {
                    return Err(err(format!(
                        "usemtl {name:?}: no such material in the loaded libraries"
                    )));
                }
            }
            _ => {}
        }
    }
    Ok(Scan { libraries, missing })
}

/// Checks that `args` starts with at least `min` finite numbers and holds only numbers.
fn numbers(args: &[&str], min: usize, what: &str) -> Result<(), String> {
    if args.len() < min {
        return Err(format!("expected {min} numbers, found {}", args.len()));
    }
    args.iter().try_for_each(|a| finite_f32(a, what).map(drop))
}

/// Checks one face corner `v`, `v/t`, `v//n` or `v/t/n` against the
/// counts. A position index the file does not have is an error; a texcoord
/// or normal index it does not have is returned (in [`ATTRIBUTES`] order).
fn check_corner(
    corner: &str,
    totals: Counts,
    so_far: Counts,
) -> Result<[Option<String>; 2], String> {
    let parts: Vec<&str> = corner.split('/').collect();
    if parts.len() > 3 || parts[0].is_empty() {
        return Err(format!("malformed face vertex {corner:?}"));
    }
    let kinds = [
        ("face", "vertices", totals.positions, so_far.positions),
        ("texcoord", "texcoords", totals.texcoords, so_far.texcoords),
        ("normal", "normals", totals.normals, so_far.normals),
    ];
    let mut missing = [None, None];
    for (slot, (part, (kind, plural, total, before))) in parts.iter().zip(kinds).enumerate() {
        if part.is_empty() {
            continue;
        }
        let index: i64 = part
            .parse()
            .map_err(|_| format!("{kind} index {part:?} is not an integer"))?;
        let problem = if index == 0 {
            format!("{kind} index 0 (OBJ indices start at 1)")
        } else if index > total {
            format!("{kind} index {index} out of range (mesh has {total} {plural})")
        } else if index < 0 && index.unsigned_abs() > before as u64 {
            format!(
                "relative {kind} index {index} reaches before the first of the {before} {plural} defined so far"
            )
        } else {
            continue;
        };
        match slot {
            0 => return Err(problem),
            _ => missing[slot - 1] = Some(problem),
        }
    }
    Ok(missing)
}

/// `bytes` with the indices of the attributes marked in `dropped` (in
/// [`ATTRIBUTES`] order) taken out of every face; other lines and the line
/// numbering stay as they are.
fn without_attributes(bytes: &[u8], dropped: [bool; 2]) -> Vec<u8> {
    let mut out = Vec::with_capacity(bytes.len());
    for (i, line) in bytes.split(|&b| b == b'\n').enumerate() {
        if i > 0 {
            out.push(b'\n');
        }
        let text = std::str::from_utf8(line).unwrap_or_default();
        let mut words = text
            .split('#')
            .next()
            .unwrap_or_default()
            .split_ascii_whitespace();
        if words.next() != Some("f") {
            out.extend_from_slice(line);
            continue;
        }
        out.push(b'f');
        for corner in words {
            let mut parts = corner.split('/');
            let position = parts.next().unwrap_or_default();
            let [texcoord, normal] =
                dropped.map(|drop| parts.next().filter(|_| !drop).unwrap_or_default());
            let corner = match (texcoord, normal) {
                ("", "") => format!(" {position}"),
                (t, "") => format!(" {position}/{t}"),
                (t, n) => format!(" {position}/{t}/{n}"),
            };
            out.extend_from_slice(corner.as_bytes());
        }
    }
    out
}

fn scan_mtl(path: &Path, bytes: &[u8], libraries: &mut Libraries) -> Result<(), SceneError> {
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut current: Option<String> = None;
    for (number, line) in numbered_lines(bytes) {
        let err = |msg: String| SceneError::at(path, number, msg);
        let line = line.map_err(err)?;
        let line = line.split('#').next().unwrap_or_default().trim();
        let (keyword, rest) = line.split_once(char::is_whitespace).unwrap_or((line, ""));
        let rest = rest.trim();
        let args: Vec<&str> = rest.split_ascii_whitespace().collect();
        match keyword {
            "newmtl" => {
                libraries.names.push(rest.to_string());
                current = Some(rest.to_string());
            }
            "Ka" | "Kd" | "Ks" | "Ke" | "Tf" => numbers(&args, 3, keyword).map_err(err)?,
            "Ns" | "Ni" | "d" | "Tr" => numbers(&args, 1, keyword).map_err(err)?,
            "illum" => {
                rest.parse::<u8>().map_err(|_| {
                    err(format!(
                        "illum {rest:?} is not an illumination model number"
                    ))
                })?;
            }
            "map_Kd" => {
                let name = current
                    .clone()
                    .ok_or_else(|| err("map_Kd before any newmtl".into()))?;
                let file = if rest.starts_with('-') {
                    args.last().copied().unwrap_or_default()
                } else {
                    rest
                };
                let texture = dir.join(file);
                if !texture.is_file() {
                    return Err(err(format!(
                        "texture {file:?} not found (looked for {})",
                        texture.display()
                    )));
                }
                libraries.textures.insert(name, texture);
            }
            _ => {}
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mtl_statements_become_materials_with_resolved_textures() {
        let dir = tempfile::tempdir().unwrap();
        let textures = dir.path().join("textures");
        std::fs::create_dir(&textures).unwrap();
        std::fs::write(textures.join("wood.png"), b"").unwrap();
        std::fs::write(
            dir.path().join("m.mtl"),
            "newmtl wood\nKd 0.5 0.4 0.3\nTr 0.25\nmap_Kd -s 1 1 1 textures/wood.png\n\nnewmtl chrome\nKs 0.8 0.8 0.8\nNs 200\nillum 3\n",
        )
        .unwrap();
        std::fs::write(
            dir.path().join("m.obj"),
            "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl wood\nf 1/1 2/2 3/3 4/4\nusemtl chrome\nf -4/1 -2/3 -1/4\n",
        )
        .unwrap();
        let loaded = load(&dir.path().join("m.obj")).unwrap();
        let [wood, chrome] = &loaded.materials[..] else {
            panic!("expected two materials, got {:?}", loaded.materials);
        };
        assert_eq!(wood.kd, Vec3::new(0.5, 0.4, 0.3));
        assert_eq!(wood.opacity, 0.75);
        assert_eq!(
            wood.diffuse_texture.as_deref(),
            Some(textures.join("wood.png").as_path())
        );
        assert_eq!(wood.mirror, Vec3::ZERO);
        assert_eq!(chrome.mirror, Vec3::splat(0.8));
        assert_eq!(chrome.shininess, 200.0);
        let mesh = &loaded.mesh;
        assert_eq!(mesh.triangle_count(), 3);
        assert_eq!(mesh.materials, [0, 0, 1]);
        assert!(mesh.texcoords.is_some() && mesh.normals.is_none());
        let corners = mesh.triangle(2);
        assert_eq!(
            corners,
            [
                Vec3::ZERO,
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0)
            ]
        );
    }

    #[test]
    fn a_dangling_texcoord_drops_texcoords_and_keeps_normals() {
        let path = Path::new("dir/m.obj");
        let obj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nvn 0 0 -1\n\
                   f 1/1/1 2/1/1 3/1/1\nf 1/2/2 3/1/2 4/0/2 # two dangling\nf 4/-3/1 1//1 2//1\n";
        let loaded = parse_bytes(path, obj.as_bytes()).unwrap();
        assert_eq!(
            loaded.warnings,
            [LoadWarning {
                path: path.to_path_buf(),
                line: 9,
                message: "texcoord index 2 out of range (mesh has 1 texcoords); the mesh is \
                          loaded without texture coordinates (1 more face names an index the \
                          file lacks)"
                    .into(),
            }]
        );
        let mesh = &loaded.mesh;
        assert_eq!(mesh.triangle_count(), 3);
        assert!(mesh.texcoords.is_none());
        let normals = mesh.normals.as_ref().expect("normals are kept");
        let corner_normals: Vec<Vec3> = mesh.indices[1]
            .iter()
            .map(|&i| normals[i as usize])
            .collect();
        assert_eq!(corner_normals, [Vec3::NEG_Z; 3]);
        assert_eq!(mesh.triangle(2)[0], Vec3::new(0.0, 1.0, 0.0));
    }

    #[test]
    fn a_dangling_position_index_stays_an_error() {
        let obj = "v 0 0 0\nv 1 0 0\nvt 0 0\nf 1/1 2/7 3/1\n";
        let err = parse_bytes(Path::new("m.obj"), obj.as_bytes()).unwrap_err();
        assert_eq!(
            err.to_string(),
            "m.obj:4: face index 3 out of range (mesh has 2 vertices)"
        );
    }

    #[test]
    fn the_most_negative_index_is_an_error_not_an_overflow() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.obj");
        std::fs::write(
            &path,
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -9223372036854775808\n",
        )
        .unwrap();
        let message = load(&path).unwrap_err().to_string();
        assert!(message.contains("m.obj:4"), "{message}");
        assert!(message.contains("reaches before the first"), "{message}");
    }
}
