//! PLY meshes: ASCII, binary little- and big-endian, optionally gzipped.
//!
//! The `vertex` element must have `x y z`; `nx ny nz` and `u v` (or `s t`)
//! become normals and texcoords when all present. The `face` element's
//! `vertex_indices` (or `vertex_index`) list gives polygons, fan-triangulated.
//! Other elements and properties are read and ignored. ASCII bodies are read
//! one element per line, so errors name the line; binary errors name the
//! element and row.

use super::gzip::maybe_inflate;
use super::text::numbered_lines;
use crate::geometry::TriangleMesh;
use crate::scene::LoadedMesh;
use crate::scene::error::{SceneError, read_file};
use crate::scene::material::Material;
use glam::{Vec2, Vec3};
use std::path::Path;

/// Loads a `.ply` or `.ply.gz` file.
pub fn load(path: &Path) -> Result<LoadedMesh, SceneError> {
    parse_bytes(path, &read_file(path)?)
}

/// Parses PLY bytes, gzipped or not; `path` names the file in errors and
/// its one material.
pub fn parse_bytes(path: &Path, bytes: &[u8]) -> Result<LoadedMesh, SceneError> {
    let mesh = parse(path, &maybe_inflate(path, bytes)?)?;
    let name = path
        .file_name()
        .map_or("ply".into(), |n| n.to_string_lossy().into_owned());
    Ok(LoadedMesh {
        mesh,
        materials: vec![Material::named(&name)],
        warnings: Vec::new(),
    })
}

/// Parses PLY data; `path` only names the file in errors.
pub fn parse(path: &Path, bytes: &[u8]) -> Result<TriangleMesh, SceneError> {
    let header = Header::parse(path, bytes)?;
    let body = &bytes[header.body_offset..];
    header.check_sizes(path, body.len())?;
    let mut reader = match header.format {
        Format::Ascii => RowReader::Ascii {
            lines: Box::new(numbered_lines(body).map(move |(n, l)| (n + header.lines, l))),
            last_line: header.lines,
        },
        Format::Binary { little_endian } => RowReader::Binary {
            body,
            pos: 0,
            little_endian,
        },
    };
    let vertex_count = header
        .elements
        .iter()
        .find(|e| e.name == "vertex")
        .map_or(0, |e| e.count as usize);
    let mut builder = MeshBuilder::default();
    let mut row = Row::default();
    for element in &header.elements {
        let role = Role::of(element);
        let wanted_list = match &role {
            Role::Faces { list } => Some(*list),
            _ => None,
        };
        for index in 0..element.count {
            let at = reader
                .read_row(element, wanted_list, &mut row)
                .map_err(|msg| reader.error(path, element, index, msg))?;
            let result = match &role {
                Role::Vertices(columns) => builder.vertex(columns, &row.scalars),
                Role::Faces { .. } => builder.face(&row.list, vertex_count),
                Role::Ignored => Ok(()),
            };
            result.map_err(|msg| reader.error_at(path, element, index, at, msg))?;
        }
    }
    reader.check_end(path)?;
    if builder.indices.is_empty() {
        return Err(SceneError::in_file(path, "no faces: the mesh is empty"));
    }
    Ok(builder.finish())
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Format {
    Ascii,
    Binary { little_endian: bool },
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &str) -> Option<Self> {
        Some(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    fn is_float(self) -> bool {
        matches!(self, Scalar::F32 | Scalar::F64)
    }

    fn range(self) -> (i64, i64) {
        match self {
            Scalar::I8 => (i8::MIN.into(), i8::MAX.into()),
            Scalar::U8 => (0, u8::MAX.into()),
            Scalar::I16 => (i16::MIN.into(), i16::MAX.into()),
            Scalar::U16 => (0, u16::MAX.into()),
            Scalar::I32 => (i32::MIN.into(), i32::MAX.into()),
            Scalar::U32 => (0, u32::MAX.into()),
            Scalar::F32 | Scalar::F64 => (i64::MIN, i64::MAX),
        }
    }

    /// Parses an ASCII token of this type.
    fn parse_token(self, token: &str) -> Result<f64, String> {
        if self.is_float() {
            return token
                .parse::<f64>()
                .map_err(|_| format!("{token:?} is not a number"));
        }
        let value = token
            .parse::<i64>()
            .map_err(|_| format!("{token:?} is not an integer"))?;
        let (lo, hi) = self.range();
        if value < lo || value > hi {
            return Err(format!("{value} does not fit the property's type {self:?}"));
        }
        Ok(value as f64)
    }

    /// Decodes one binary value from the front of `bytes` (long enough).
    fn decode(self, bytes: &[u8], little_endian: bool) -> f64 {
        macro_rules! get {
            ($t:ty) => {{
                let raw = bytes[..size_of::<$t>()].try_into().unwrap();
                if little_endian {
                    <$t>::from_le_bytes(raw) as f64
                } else {
                    <$t>::from_be_bytes(raw) as f64
                }
            }};
        }
        match self {
            Scalar::I8 => get!(i8),
            Scalar::U8 => get!(u8),
            Scalar::I16 => get!(i16),
            Scalar::U16 => get!(u16),
            Scalar::I32 => get!(i32),
            Scalar::U32 => get!(u32),
            Scalar::F32 => get!(f32),
            Scalar::F64 => get!(f64),
        }
    }
}

#[derive(Debug)]
enum Property {
    Scalar {
        name: String,
        ty: Scalar,
    },
    List {
        name: String,
        count: Scalar,
        item: Scalar,
    },
}

impl Property {
    fn name(&self) -> &str {
        match self {
            Property::Scalar { name, .. } | Property::List { name, .. } => name,
        }
    }
}

#[derive(Debug)]
struct Element {
    name: String,
    count: u64,
    properties: Vec<Property>,
    /// Header line that declared it.
    line: usize,
}

impl Element {
    /// The fewest bytes one row can take in `format`.
    fn min_row_bytes(&self, format: Format) -> u64 {
        let per_property = |p: &Property| match (format, p) {
            // A digit and a separator.
            (Format::Ascii, _) => 2,
            (_, Property::Scalar { ty, .. }) => ty.size() as u64,
            (_, Property::List { count, .. }) => count.size() as u64,
        };
        self.properties.iter().map(per_property).sum::<u64>().max(1)
    }

    fn scalar_index(&self, name: &str) -> Option<usize> {
        self.properties
            .iter()
            .position(|p| matches!(p, Property::Scalar { name: n, .. } if n == name))
    }
}

struct Header {
    format: Format,
    elements: Vec<Element>,
    /// Number of header lines, `end_header` included.
    lines: usize,
    body_offset: usize,
}

impl Header {
    fn parse(path: &Path, bytes: &[u8]) -> Result<Self, SceneError> {
        let mut format = None;
        let mut elements: Vec<Element> = Vec::new();
        let mut offset = 0;
        for (number, line) in numbered_lines(bytes) {
            offset += bytes[offset..]
                .iter()
                .position(|&b| b == b'\n')
                .map_or(bytes.len() - offset, |p| p + 1);
            let line = line.map_err(|msg| SceneError::at(path, number, msg))?;
            let err = |msg: String| SceneError::at(path, number, msg);
            let words: Vec<&str> = line.split_ascii_whitespace().collect();
            if number == 1 {
                if words != ["ply"] {
                    return Err(err("not a PLY file (the first line must be `ply`)".into()));
                }
                continue;
            }
            match words.as_slice() {
                ["format", kind, _version] => {
                    format = Some(match *kind {
                        "ascii" => Format::Ascii,
                        "binary_little_endian" => Format::Binary {
                            little_endian: true,
                        },
                        "binary_big_endian" => Format::Binary {
                            little_endian: false,
                        },
                        other => return Err(err(format!("unknown PLY format {other:?}"))),
                    })
                }
                ["comment", ..] | ["obj_info", ..] | [] => {}
                ["element", name, count] => {
                    let count = count
                        .parse::<u64>()
                        .map_err(|_| err(format!("element count {count:?} is not a count")))?;
                    elements.push(Element {
                        name: name.to_string(),
                        count,
                        properties: Vec::new(),
                        line: number,
                    });
                }
                ["property", rest @ ..] => {
                    let element = elements
                        .last_mut()
                        .ok_or_else(|| err("property before any element".into()))?;
                    element.properties.push(parse_property(rest).map_err(err)?);
                }
                ["end_header"] => {
                    let format =
                        format.ok_or_else(|| err("no `format` line in the header".into()))?;
                    return Ok(Header {
                        format,
                        elements,
                        lines: number,
                        body_offset: offset,
                    });
                }
                _ => return Err(err(format!("unrecognized header line {line:?}"))),
            }
        }
        Err(SceneError::in_file(
            path,
            "the header never ends (no `end_header` line)",
        ))
    }

    /// Refuses counts the body cannot possibly hold, before anything is allocated.
    fn check_sizes(&self, path: &Path, body_len: usize) -> Result<(), SceneError> {
        let mut needed: u64 = 0;
        for element in &self.elements {
            let rows = element
                .count
                .checked_mul(element.min_row_bytes(self.format));
            needed = match rows.and_then(|r| r.checked_add(needed)) {
                Some(n) if n <= body_len as u64 => n,
                _ => {
                    return Err(SceneError::at(
                        path,
                        element.line,
                        format!(
                            "element {} declares {} rows, more than the {body_len} bytes after the header can hold",
                            element.name, element.count
                        ),
                    ));
                }
            };
        }
        Ok(())
    }
}

fn parse_property(words: &[&str]) -> Result<Property, String> {
    let ty =
        |name: &str| Scalar::parse(name).ok_or_else(|| format!("unknown property type {name:?}"));
    match words {
        ["list", count, item, name] => Ok(Property::List {
            name: name.to_string(),
            count: ty(count)?,
            item: ty(item)?,
        }),
        [t, name] => Ok(Property::Scalar {
            name: name.to_string(),
            ty: ty(t)?,
        }),
        _ => Err(format!(
            "malformed property line `property {}`",
            words.join(" ")
        )),
    }
}

/// What the loader does with an element's rows.
enum Role {
    Vertices(VertexColumns),
    /// Faces; `list` is the index of the vertex-index list property.
    Faces {
        list: usize,
    },
    Ignored,
}

impl Role {
    fn of(element: &Element) -> Role {
        match element.name.as_str() {
            "vertex" => Role::Vertices(VertexColumns::of(element)),
            "face" => element
                .properties
                .iter()
                .position(|p| {
                    matches!(p, Property::List { name, .. } if name == "vertex_indices" || name == "vertex_index")
                })
                .map_or(Role::Ignored, |list| Role::Faces { list }),
            _ => Role::Ignored,
        }
    }
}

/// Where the vertex attributes sit in a vertex row.
struct VertexColumns {
    position: Option<[usize; 3]>,
    normal: Option<[usize; 3]>,
    texcoord: Option<[usize; 2]>,
}

impl VertexColumns {
    fn of(element: &Element) -> Self {
        let find = |names: &[&str]| {
            names
                .iter()
                .map(|n| element.scalar_index(n))
                .collect::<Option<Vec<_>>>()
        };
        let three = |names: &[&str]| find(names).map(|v| [v[0], v[1], v[2]]);
        let two = |names: &[&str]| find(names).map(|v| [v[0], v[1]]);
        Self {
            position: three(&["x", "y", "z"]),
            normal: three(&["nx", "ny", "nz"]),
            texcoord: two(&["u", "v"]).or_else(|| two(&["s", "t"])),
        }
    }
}

/// One row's values: every scalar property in order (lists as NaN) and the
/// items of the one list that matters.
#[derive(Default)]
struct Row {
    scalars: Vec<f64>,
    list: Vec<f64>,
}

enum RowReader<'a> {
    Ascii {
        lines: Box<dyn Iterator<Item = (usize, Result<&'a str, String>)> + 'a>,
        last_line: usize,
    },
    Binary {
        body: &'a [u8],
        pos: usize,
        little_endian: bool,
    },
}

impl RowReader<'_> {
    /// Reads the next row of `element`; returns its line (ASCII) or 0.
    fn read_row(
        &mut self,
        element: &Element,
        wanted_list: Option<usize>,
        row: &mut Row,
    ) -> Result<usize, String> {
        row.scalars.clear();
        row.list.clear();
        match self {
            RowReader::Ascii { lines, last_line } => {
                let (number, line) = loop {
                    match lines.next() {
                        None => return Err("unexpected end of file".into()),
                        Some((n, Ok(l))) if l.trim().is_empty() => *last_line = n,
                        Some((n, l)) => break (n, l),
                    }
                };
                *last_line = number;
                let mut tokens = line?.split_ascii_whitespace();
                let mut next = |what: &str| {
                    tokens.next().ok_or_else(|| {
                        format!(
                            "too few values for a {} (missing {what}; properties: {})",
                            element.name,
                            property_names(element)
                        )
                    })
                };
                for (i, property) in element.properties.iter().enumerate() {
                    match property {
                        Property::Scalar { name, ty } => {
                            row.scalars.push(ty.parse_token(next(name)?)?)
                        }
                        Property::List { name, count, item } => {
                            row.scalars.push(f64::NAN);
                            let n = count.parse_token(next(name)?)? as u64;
                            for _ in 0..n {
                                let value = item.parse_token(next(name)?)?;
                                if Some(i) == wanted_list {
                                    row.list.push(value);
                                }
                            }
                        }
                    }
                }
                if tokens.next().is_some() {
                    return Err(format!(
                        "too many values for a {} (properties: {}); are the header counts right?",
                        element.name,
                        property_names(element)
                    ));
                }
                Ok(number)
            }
            RowReader::Binary {
                body,
                pos,
                little_endian,
            } => {
                let mut take = |ty: Scalar| {
                    let bytes = body
                        .get(*pos..*pos + ty.size())
                        .ok_or_else(|| format!("file truncated at byte {} of the body", *pos))?;
                    *pos += ty.size();
                    Ok::<f64, String>(ty.decode(bytes, *little_endian))
                };
                for (i, property) in element.properties.iter().enumerate() {
                    match property {
                        Property::Scalar { ty, .. } => row.scalars.push(take(*ty)?),
                        Property::List { count, item, .. } => {
                            row.scalars.push(f64::NAN);
                            let n = take(*count)?;
                            if n < 0.0 {
                                return Err(format!("negative list length {n}"));
                            }
                            for _ in 0..n as u64 {
                                let value = take(*item)?;
                                if Some(i) == wanted_list {
                                    row.list.push(value);
                                }
                            }
                        }
                    }
                }
                Ok(0)
            }
        }
    }

    /// An error in row `index` of `element`, at the current line.
    fn error(&self, path: &Path, element: &Element, index: u64, message: String) -> SceneError {
        let line = match self {
            RowReader::Ascii { last_line, .. } => *last_line,
            RowReader::Binary { .. } => 0,
        };
        self.error_at(path, element, index, line, message)
    }

    fn error_at(
        &self,
        path: &Path,
        element: &Element,
        index: u64,
        line: usize,
        message: String,
    ) -> SceneError {
        let message = format!("{} {index} of {}: {message}", element.name, element.count);
        match self {
            RowReader::Ascii { .. } => SceneError::at(path, line, message),
            RowReader::Binary { .. } => SceneError::in_file(path, message),
        }
    }

    /// Anything but blank lines after the last element means wrong counts.
    fn check_end(&mut self, path: &Path) -> Result<(), SceneError> {
        match self {
            RowReader::Ascii { lines, .. } => {
                for (number, line) in lines {
                    if line.map_or(true, |l| !l.trim().is_empty()) {
                        return Err(SceneError::at(
                            path,
                            number,
                            "data after the last element (the header counts are too small?)",
                        ));
                    }
                }
                Ok(())
            }
            RowReader::Binary { body, pos, .. } if *pos < body.len() => Err(SceneError::in_file(
                path,
                format!(
                    "{} bytes after the last element (the header counts are too small?)",
                    body.len() - *pos
                ),
            )),
            RowReader::Binary { .. } => Ok(()),
        }
    }
}

fn property_names(element: &Element) -> String {
    element
        .properties
        .iter()
        .map(Property::name)
        .collect::<Vec<_>>()
        .join(" ")
}

#[derive(Default)]
struct MeshBuilder {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    texcoords: Vec<Vec2>,
    indices: Vec<[u32; 3]>,
}

impl MeshBuilder {
    fn vertex(&mut self, columns: &VertexColumns, values: &[f64]) -> Result<(), String> {
        let [x, y, z] = columns
            .position
            .ok_or("the vertex element has no x, y and z properties")?;
        let coord = |i: usize, what: &str| {
            let value = values[i] as f32;
            if value.is_finite() {
                Ok(value)
            } else {
                Err(format!("{what} = {} is not a finite number", values[i]))
            }
        };
        self.positions
            .push(Vec3::new(coord(x, "x")?, coord(y, "y")?, coord(z, "z")?));
        if let Some([x, y, z]) = columns.normal {
            self.normals
                .push(Vec3::new(coord(x, "nx")?, coord(y, "ny")?, coord(z, "nz")?));
        }
        if let Some([u, v]) = columns.texcoord {
            self.texcoords
                .push(Vec2::new(coord(u, "u")?, coord(v, "v")?));
        }
        Ok(())
    }

    fn face(&mut self, list: &[f64], vertex_count: usize) -> Result<(), String> {
        if list.len() < 3 {
            return Err(format!(
                "a face needs at least 3 vertices, this one has {}",
                list.len()
            ));
        }
        let mut ids = list.iter().map(|&value| {
            if value < 0.0 {
                Err(format!("negative face index {value}"))
            } else if value.fract() != 0.0 {
                Err(format!("face index {value} is not an integer"))
            } else if value >= vertex_count as f64 {
                Err(format!(
                    "face index {value} out of range (mesh has {vertex_count} vertices)"
                ))
            } else {
                Ok(value as u32)
            }
        });
        let first = ids.next().unwrap()?;
        let mut previous = ids.next().unwrap()?;
        for id in ids {
            let id = id?;
            self.indices.push([first, previous, id]);
            previous = id;
        }
        Ok(())
    }

    fn finish(self) -> TriangleMesh {
        let n = self.positions.len();
        let full = |len: usize| len == n && n > 0;
        TriangleMesh {
            materials: vec![0; self.indices.len()],
            normals: full(self.normals.len()).then_some(self.normals),
            texcoords: full(self.texcoords.len()).then_some(self.texcoords),
            positions: self.positions,
            indices: self.indices,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEADER: &str = "ply\nformat ascii 1.0\ncomment two triangles\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";

    fn parse_str(text: &str) -> Result<TriangleMesh, SceneError> {
        parse(Path::new("t.ply"), text.as_bytes())
    }

    fn error_of(text: &str) -> String {
        parse_str(text).unwrap_err().to_string()
    }

    #[test]
    fn ascii_quad_is_fan_triangulated() {
        let mesh = parse_str(&format!("{HEADER}0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n")).unwrap();
        assert_eq!(mesh.positions.len(), 4);
        assert_eq!(mesh.indices, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(mesh.materials, vec![0, 0]);
        assert!(mesh.normals.is_none());
        mesh.check().unwrap();
    }

    #[test]
    fn binary_matches_ascii() {
        let header = HEADER.replace("ascii", "binary_little_endian");
        let mut bytes = header.into_bytes();
        for p in [[0f32, 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]] {
            p.iter().for_each(|c| bytes.extend(c.to_le_bytes()));
        }
        bytes.push(3);
        [3i32, 1, 2]
            .iter()
            .for_each(|i| bytes.extend(i.to_le_bytes()));
        let mesh = parse(Path::new("b.ply"), &bytes).unwrap();
        assert_eq!(mesh.indices, vec![[3, 1, 2]]);
        assert_eq!(mesh.positions[2], Vec3::new(1.0, 1.0, 0.0));
        bytes.pop();
        let err = parse(Path::new("b.ply"), &bytes).unwrap_err().to_string();
        assert!(
            err.starts_with("b.ply: face 0 of 1: file truncated"),
            "{err}"
        );
    }

    #[test]
    fn normals_and_texcoords_are_read_when_complete() {
        let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty float u\nproperty float v\nelement face 1\nproperty list uchar uint vertex_index\nend_header\n0 0 0 0 0 1 0 0\n1 0 0 0 0 1 1 0\n0 1 0 0 0 1 0 1\n3 0 1 2\n";
        let mesh = parse_str(text).unwrap();
        assert_eq!(mesh.normals.unwrap()[1], Vec3::Z);
        assert_eq!(mesh.texcoords.unwrap()[2], Vec2::new(0.0, 1.0));
    }

    #[test]
    fn bad_bodies_name_the_line() {
        let vertices = "0 0 0\n1 0 0\n1 1 0\n0 1 0\n";
        let cases = [
            (
                format!("{HEADER}{vertices}3 0 1 9\n"),
                "t.ply:15: face 0 of 1: face index 9 out of range (mesh has 4 vertices)",
            ),
            (
                format!("{HEADER}{vertices}3 0 -1 2\n"),
                "t.ply:15: face 0 of 1: negative face index -1",
            ),
            (
                format!("{HEADER}0 0 0\n1 nan 0\n1 1 0\n0 1 0\n3 0 1 2\n"),
                "t.ply:12: vertex 1 of 4: y = NaN is not a finite number",
            ),
            (
                format!("{HEADER}0.5 0.5 0.5\n1.5 0.5 0.5\n1.5 1.5 0.5\n"),
                "t.ply:14: vertex 3 of 4: unexpected end of file",
            ),
            (
                format!("{HEADER}{vertices}3 0 1 2\n3 0 1 2\n"),
                "t.ply:16: data after the last element",
            ),
            (
                format!("{HEADER}{vertices}2 0 1\n"),
                "t.ply:15: face 0 of 1: a face needs at least 3 vertices",
            ),
            (
                format!("{HEADER}0 0 0 0\n{vertices}"),
                "t.ply:11: vertex 0 of 4: too many values",
            ),
            (
                HEADER.replace("vertex 4", "vertex 999999999999"),
                "t.ply:4: element vertex declares 999999999999 rows",
            ),
            (
                HEADER.replace("end_header\n", ""),
                "t.ply: the header never ends",
            ),
            ("plx\n".to_string(), "t.ply:1: not a PLY file"),
        ];
        for (text, expected) in cases {
            let err = error_of(&text);
            assert!(
                err.starts_with(expected),
                "expected {expected:?}, got {err:?}"
            );
        }
    }

    #[test]
    fn unsigned_list_items_reject_negative_values() {
        let text = HEADER.replace("uchar int", "uchar uint");
        let err = error_of(&format!("{text}0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 -1 2\n"));
        assert!(
            err.starts_with("t.ply:15: face 0 of 1: -1 does not fit"),
            "{err}"
        );
    }
}
