//! The rays and hits files: little-endian, a 32-byte header, then one
//! fixed-size record per ray (the layout is documented, with a Python
//! reader and writer, in `docs/exchange.md`).
//!
//! ```text
//! header   magic     8 bytes  "RCRAYS\0\0" or "RCHITS\0\0"
//!          version   u32      1
//!          set       u32      1 primary, 2 shadow, 3 reflection, 4 diffuse,
//!                             5 stability case (closest hit), 6 stability case (any hit)
//!          count     u64      rays (or answers)
//!          flags     u32      hits: bit 0 set when u, v are given; rays: 0
//!          reserved  u32      0
//! ray      origin x y z, tnear, direction x y z, tfar: 8 × f32 (32 bytes)
//! hit      t f32, u f32, v f32, primID u32 (16 bytes); a miss has
//!          primID 0xFFFFFFFF (t, u, v then ignored)         (closest-hit sets)
//!          or one u8 per ray, 1 occluded, 0 not              (any-hit sets: 2, 6)
//! ```

use crate::check::{Answer, RaySet};
use crate::geometry::{Hit, Ray};
use glam::Vec3;
use std::path::{Path, PathBuf};

pub const RAYS_MAGIC: [u8; 8] = *b"RCRAYS\0\0";
pub const HITS_MAGIC: [u8; 8] = *b"RCHITS\0\0";
pub const VERSION: u32 = 1;
pub const HEADER_BYTES: usize = 32;
pub const RAY_BYTES: usize = 32;
pub const HIT_BYTES: usize = 16;
/// The primID of a miss (Embree's `RTC_INVALID_GEOMETRY_ID`).
pub const MISS: u32 = u32::MAX;
/// Hits header flag: the file gives `u`, `v`.
pub const FLAG_UV: u32 = 1;

/// A file that is not what it should be, with its path and what is wrong.
#[derive(Debug, thiserror::Error)]
#[error("{}: {what}", path.display())]
pub struct FileError {
    pub path: PathBuf,
    pub what: String,
}

fn error(path: &Path, what: impl Into<String>) -> FileError {
    FileError {
        path: path.to_path_buf(),
        what: what.into(),
    }
}

/// A rays file: which set the rays are and the rays.
#[derive(Clone, Debug, PartialEq)]
pub struct RaysFile {
    pub set: RaySet,
    pub rays: Vec<Ray>,
}

/// A hits file: one answer per ray of a rays file.
#[derive(Clone, Debug, PartialEq)]
pub struct HitsFile {
    pub set: RaySet,
    /// Whether the `u`, `v` of the hits are given.
    pub gives_uv: bool,
    pub answers: Vec<Answer>,
}

const SETS: [(u32, RaySet); 6] = [
    (1, RaySet::Primary),
    (2, RaySet::Shadow),
    (3, RaySet::Reflection),
    (4, RaySet::Diffuse),
    (5, RaySet::StabilityCase),
    (6, RaySet::StabilityCaseAnyHit),
];

fn set_code(set: RaySet) -> u32 {
    SETS.iter().find(|(_, s)| *s == set).map_or(0, |(c, _)| *c)
}

fn header(magic: [u8; 8], set: RaySet, count: usize, flags: u32) -> Vec<u8> {
    let mut bytes = magic.to_vec();
    bytes.extend(VERSION.to_le_bytes());
    bytes.extend(set_code(set).to_le_bytes());
    bytes.extend((count as u64).to_le_bytes());
    bytes.extend(flags.to_le_bytes());
    bytes.extend(0u32.to_le_bytes());
    bytes
}

fn u32_at(bytes: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]])
}

fn f32_at(bytes: &[u8], at: usize) -> f32 {
    f32::from_bits(u32_at(bytes, at))
}

/// A parsed header: the set, the count and the flags.
struct Header {
    set: RaySet,
    count: usize,
    flags: u32,
}

/// Checks the header of `bytes` and that the body holds exactly `count`
/// records of `record_bytes` (given the set).
fn parse_header(
    path: &Path,
    bytes: &[u8],
    magic: [u8; 8],
    kind: &str,
    record_bytes: impl Fn(RaySet) -> usize,
) -> Result<Header, FileError> {
    if bytes.len() < HEADER_BYTES {
        return Err(error(
            path,
            format!(
                "truncated: {} bytes, shorter than the {HEADER_BYTES}-byte header",
                bytes.len()
            ),
        ));
    }
    if bytes[..8] != magic {
        return Err(error(
            path,
            format!(
                "not a raycheck {kind} file: it starts with {:?}, expected {:?}",
                String::from_utf8_lossy(&bytes[..8]),
                String::from_utf8_lossy(&magic)
            ),
        ));
    }
    let version = u32_at(bytes, 8);
    if version != VERSION {
        return Err(error(
            path,
            format!("version {version} is not supported (this raycheck reads version {VERSION})"),
        ));
    }
    let code = u32_at(bytes, 12);
    let set = SETS
        .iter()
        .find(|(c, _)| *c == code)
        .map(|(_, s)| *s)
        .ok_or_else(|| {
            error(
                path,
                format!("unknown ray set code {code} (expected 1 to 6)"),
            )
        })?;
    let count = u64::from_le_bytes(bytes[16..24].try_into().unwrap_or_default());
    let flags = u32_at(bytes, 24);
    let body = (bytes.len() - HEADER_BYTES) as u64;
    let per = record_bytes(set) as u64;
    let expected = count.checked_mul(per);
    if expected != Some(body) {
        let need = expected.map_or("more than 2^64".to_string(), |n| n.to_string());
        return Err(error(
            path,
            format!(
                "the header says {count} records of {per} bytes ({need} bytes), the body has {body} bytes{}",
                if expected.is_some_and(|n| n > body) {
                    ": truncated"
                } else {
                    ""
                }
            ),
        ));
    }
    Ok(Header {
        set,
        count: count as usize,
        flags,
    })
}

impl RaysFile {
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut bytes = header(RAYS_MAGIC, self.set, self.rays.len(), 0);
        for ray in &self.rays {
            let [ox, oy, oz, dx, dy, dz, tnear, tfar] = ray.inputs();
            for value in [ox, oy, oz, tnear, dx, dy, dz, tfar] {
                bytes.extend(value.to_le_bytes());
            }
        }
        bytes
    }

    /// Parses a rays file; `path` names it in errors. Rays may hold NaN or
    /// infinities (the stability catalogue asks such rays on purpose).
    pub fn parse(path: &Path, bytes: &[u8]) -> Result<Self, FileError> {
        let header = parse_header(path, bytes, RAYS_MAGIC, "rays", |_| RAY_BYTES)?;
        let rays = (0..header.count)
            .map(|i| {
                let at = HEADER_BYTES + i * RAY_BYTES;
                let v = |k: usize| f32_at(bytes, at + 4 * k);
                Ray::segment(
                    Vec3::new(v(0), v(1), v(2)),
                    Vec3::new(v(4), v(5), v(6)),
                    v(3),
                    v(7),
                )
            })
            .collect();
        Ok(Self {
            set: header.set,
            rays,
        })
    }

    pub fn read(path: &Path) -> Result<Self, FileError> {
        Self::parse(path, &read(path)?)
    }

    pub fn write(&self, path: &Path) -> Result<(), FileError> {
        write(path, &self.to_bytes())
    }
}

/// Bytes per answer of a hits file of `set`.
fn answer_bytes(set: RaySet) -> usize {
    if set.is_any_hit() { 1 } else { HIT_BYTES }
}

impl HitsFile {
    /// Checks that these hits answer every ray of `rays`, of the same set,
    /// with primIDs of a mesh of `triangles` triangles.
    pub fn check_answers(&self, rays: &RaysFile, triangles: usize) -> anyhow::Result<()> {
        anyhow::ensure!(
            self.set == rays.set && self.answers.len() == rays.rays.len(),
            "the hits answer {} rays of the {} set; the rays file holds {} rays of the {} set",
            self.answers.len(),
            self.set.name(),
            rays.rays.len(),
            rays.set.name()
        );
        for (index, answer) in self.answers.iter().enumerate() {
            if let Answer::Closest(Some(hit)) = answer {
                anyhow::ensure!(
                    (hit.prim as usize) < triangles,
                    "answer {index}: primID {} is beyond the mesh's {triangles} triangles",
                    hit.prim
                );
            }
        }
        Ok(())
    }

    pub fn to_bytes(&self) -> Vec<u8> {
        let flags = if self.gives_uv { FLAG_UV } else { 0 };
        let mut bytes = header(HITS_MAGIC, self.set, self.answers.len(), flags);
        for answer in &self.answers {
            match answer {
                Answer::Occluded(occluded) => bytes.push(*occluded as u8),
                Answer::Closest(Some(hit)) => {
                    for value in [hit.t, hit.u, hit.v] {
                        bytes.extend(value.to_le_bytes());
                    }
                    bytes.extend(hit.prim.to_le_bytes());
                }
                Answer::Closest(None) => {
                    bytes.extend([0u8; 12]);
                    bytes.extend(MISS.to_le_bytes());
                }
            }
        }
        bytes
    }

    /// Parses a hits file; `path` names it in errors. A NaN `t` (or `u`,
    /// `v` where given) and an occluded flag other than 0 or 1 are errors
    /// naming the record.
    pub fn parse(path: &Path, bytes: &[u8]) -> Result<Self, FileError> {
        let header = parse_header(path, bytes, HITS_MAGIC, "hits", answer_bytes)?;
        let gives_uv = header.flags & FLAG_UV != 0;
        let answers = (0..header.count)
            .map(|i| {
                let at = HEADER_BYTES + i * answer_bytes(header.set);
                if header.set.is_any_hit() {
                    return match bytes[at] {
                        0 => Ok(Answer::Occluded(false)),
                        1 => Ok(Answer::Occluded(true)),
                        other => Err(error(
                            path,
                            format!("answer {i}: occluded flag {other}, expected 0 or 1"),
                        )),
                    };
                }
                let prim = u32_at(bytes, at + 12);
                if prim == MISS {
                    return Ok(Answer::Closest(None));
                }
                let (t, u, v) = (
                    f32_at(bytes, at),
                    f32_at(bytes, at + 4),
                    f32_at(bytes, at + 8),
                );
                let nan = if t.is_nan() {
                    Some("t")
                } else if gives_uv && (u.is_nan() || v.is_nan()) {
                    Some("u or v")
                } else {
                    None
                };
                if let Some(what) = nan {
                    return Err(error(path, format!("answer {i}: {what} is NaN")));
                }
                let (u, v) = if gives_uv { (u, v) } else { (0.0, 0.0) };
                Ok(Answer::Closest(Some(Hit {
                    t,
                    u,
                    v,
                    prim,
                    ng: Vec3::ZERO,
                })))
            })
            .collect::<Result<_, _>>()?;
        Ok(Self {
            set: header.set,
            gives_uv,
            answers,
        })
    }

    pub fn read(path: &Path) -> Result<Self, FileError> {
        Self::parse(path, &read(path)?)
    }

    pub fn write(&self, path: &Path) -> Result<(), FileError> {
        write(path, &self.to_bytes())
    }
}

fn read(path: &Path) -> Result<Vec<u8>, FileError> {
    std::fs::read(path).map_err(|e| error(path, format!("cannot read: {e}")))
}

fn write(path: &Path, bytes: &[u8]) -> Result<(), FileError> {
    std::fs::write(path, bytes).map_err(|e| error(path, format!("cannot write: {e}")))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rays() -> RaysFile {
        RaysFile {
            set: RaySet::Primary,
            rays: vec![
                Ray::segment(Vec3::new(1.0, -2.0, 3.5), Vec3::NEG_Z, 0.25, 9.0),
                Ray::segment(Vec3::ZERO, Vec3::X, f32::NAN, f32::INFINITY),
            ],
        }
    }

    fn hits() -> HitsFile {
        HitsFile {
            set: RaySet::Primary,
            gives_uv: true,
            answers: vec![
                Answer::Closest(Some(Hit {
                    t: 1.5,
                    u: 0.25,
                    v: 0.5,
                    prim: 7,
                    ng: Vec3::ZERO,
                })),
                Answer::Closest(None),
            ],
        }
    }

    fn what(result: Result<impl std::fmt::Debug, FileError>) -> String {
        result.unwrap_err().to_string()
    }

    #[test]
    fn rays_round_trip_bit_for_bit() {
        let file = rays();
        let bytes = file.to_bytes();
        assert_eq!(bytes.len(), HEADER_BYTES + 2 * RAY_BYTES);
        assert_eq!(&bytes[..8], b"RCRAYS\0\0");
        let back = RaysFile::parse(Path::new("r"), &bytes).unwrap();
        let bits =
            |f: &RaysFile| -> Vec<[u32; 8]> { f.rays.iter().map(crate::check::ray_bits).collect() };
        assert_eq!(bits(&back), bits(&file));
        // The documented order: origin, tnear, direction, tfar.
        assert_eq!(f32_at(&bytes, HEADER_BYTES + 12), 0.25);
        assert_eq!(f32_at(&bytes, HEADER_BYTES + 28), 9.0);
    }

    #[test]
    fn hits_round_trip_and_occlusion_flags() {
        let file = hits();
        assert_eq!(
            HitsFile::parse(Path::new("h"), &file.to_bytes()).unwrap(),
            file
        );
        let shadow = HitsFile {
            set: RaySet::Shadow,
            gives_uv: false,
            answers: vec![Answer::Occluded(true), Answer::Occluded(false)],
        };
        let bytes = shadow.to_bytes();
        assert_eq!(bytes.len(), HEADER_BYTES + 2);
        assert_eq!(HitsFile::parse(Path::new("h"), &bytes).unwrap(), shadow);
    }

    #[test]
    fn u_and_v_are_read_only_where_the_flag_gives_them() {
        // A tracer that gives no u, v may leave anything there: NaN, huge
        // values. With flag bit 0 clear they are neither checked nor used.
        let mut bytes = hits().to_bytes();
        bytes[24..28].copy_from_slice(&0u32.to_le_bytes());
        let u_at = HEADER_BYTES + 4;
        bytes[u_at..u_at + 4].copy_from_slice(&f32::NAN.to_le_bytes());
        bytes[u_at + 4..u_at + 8].copy_from_slice(&1e30f32.to_le_bytes());
        let file = HitsFile::parse(Path::new("h"), &bytes).unwrap();
        assert!(!file.gives_uv);
        let Answer::Closest(Some(hit)) = file.answers[0] else {
            panic!("{file:?}")
        };
        assert_eq!((hit.t, hit.prim), (1.5, 7));
        assert_eq!((hit.u.to_bits(), hit.v.to_bits()), (0, 0));
        // The same bytes with the flag set are a NaN u: an error.
        bytes[24..28].copy_from_slice(&FLAG_UV.to_le_bytes());
        let message = what(HitsFile::parse(Path::new("h"), &bytes));
        assert!(message.contains("answer 0: u or v is NaN"), "{message}");
    }

    #[test]
    fn bad_files_are_named_errors() {
        let path = Path::new("bad.rays");
        let good = rays().to_bytes();
        let mut wrong_magic = good.clone();
        wrong_magic[0] = b'X';
        assert!(what(RaysFile::parse(path, &wrong_magic)).contains("not a raycheck rays file"));
        assert!(what(HitsFile::parse(path, &good)).contains("not a raycheck hits file"));
        let truncated = &good[..good.len() - 5];
        let message = what(RaysFile::parse(path, truncated));
        assert!(message.starts_with("bad.rays: "), "{message}");
        assert!(message.contains("truncated"), "{message}");
        assert!(
            what(RaysFile::parse(path, &good[..10])).contains("shorter than the 32-byte header")
        );
        let mut longer = good.clone();
        longer.extend([0; 3]);
        assert!(what(RaysFile::parse(path, &longer)).contains("the body has 67 bytes"));
        let mut version = good.clone();
        version[8] = 2;
        assert!(what(RaysFile::parse(path, &version)).contains("version 2 is not supported"));
        let mut set = good.clone();
        set[12] = 9;
        assert!(what(RaysFile::parse(path, &set)).contains("unknown ray set code 9"));
        let mut huge = good.clone();
        huge[16..24].copy_from_slice(&u64::MAX.to_le_bytes());
        assert!(what(RaysFile::parse(path, &huge)).contains("more than 2^64"));

        let mut nan = hits().to_bytes();
        nan[HEADER_BYTES..HEADER_BYTES + 4].copy_from_slice(&f32::NAN.to_le_bytes());
        assert!(what(HitsFile::parse(path, &nan)).contains("answer 0: t is NaN"));
        let mut flag = HitsFile {
            set: RaySet::Shadow,
            gives_uv: false,
            answers: vec![Answer::Occluded(true)],
        }
        .to_bytes();
        flag[HEADER_BYTES] = 7;
        assert!(what(HitsFile::parse(path, &flag)).contains("occluded flag 7"));
    }
}
