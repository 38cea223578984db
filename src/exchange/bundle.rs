//! A stability case as files, as the case judges it: a folder holding one
//! (mesh, rays) pair per batch the case judges, and a manifest.
//!
//! ```text
//! CASE/bundle.json                 the manifest: the case, its form, the pairs in order
//! CASE/mesh-000.ply ...            each distinct mesh once (binary PLY, every f32 exact)
//! CASE/pair-000.closest.rays ...   per pair, its rays asked for the closest hit (set 5)
//! CASE/pair-000.any-hit.rays ...   and the same rays asked for any hit (set 6)
//! ```
//!
//! A tracer answers each rays file `X.rays` of a pair against the pair's
//! mesh with a hits file `X.hits` in a folder of its own; `raycheck
//! judge CASE HITS` judges every pair as the case does in process.
//! `docs/exchange.md` documents the manifest.

use super::files::{FileError, RaysFile};
use super::ply;
use crate::check::RaySet;
use crate::geometry::TriangleMesh;
use crate::stability::Batch;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The manifest's file name in a bundle's folder.
pub const MANIFEST: &str = "bundle.json";
/// What the manifest's `format` field says.
pub const FORMAT: &str = "raycheck bundle";
pub const VERSION: u32 = 1;

/// `bundle.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    /// Always [`FORMAT`].
    pub format: String,
    /// Always [`VERSION`].
    pub version: u32,
    /// The stability case's name.
    pub case: String,
    /// `quick` or `full`.
    pub form: String,
    /// The batches the case judges, in order.
    pub pairs: Vec<Pair>,
}

/// One batch: file names in the bundle's folder.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Pair {
    /// The mesh (binary PLY), face `i` being primID `i`.
    pub mesh: String,
    /// Rays asked for their closest hit (set 5).
    pub closest: String,
    /// Rays asked whether anything occludes them (set 6).
    pub any_hit: String,
    /// Whether every ray had to hit: misses of rays that exactly hit the
    /// mesh count as leaks.
    pub must_hit: bool,
}

/// One pair read back.
pub struct LoadedPair {
    pub mesh: TriangleMesh,
    pub closest: RaysFile,
    pub any_hit: RaysFile,
    pub must_hit: bool,
}

/// A bundle's folder and its manifest.
pub struct Bundle {
    pub dir: PathBuf,
    pub manifest: Manifest,
}

/// Whether `path` is a bundle's folder (it holds a manifest).
pub fn is_bundle(path: &Path) -> bool {
    path.join(MANIFEST).is_file()
}

/// The hits file that answers rays file `rays` of a bundle, in the
/// folder `hits_dir`: the same name, ending `.hits`.
pub fn hits_path(hits_dir: &Path, rays: &str) -> PathBuf {
    hits_dir.join(Path::new(rays).with_extension("hits"))
}

/// Writes `batches` of stability case `case` (its `full` or quick form)
/// as a bundle in `dir` (created if need be; files of an earlier bundle
/// there are overwritten). Equal meshes are written once.
pub fn write(dir: &Path, case: &str, full: bool, batches: &[Batch]) -> anyhow::Result<Manifest> {
    std::fs::create_dir_all(dir).map_err(|e| FileError {
        path: dir.to_path_buf(),
        what: format!("cannot create the bundle's folder: {e}"),
    })?;
    let mut meshes: Vec<(&TriangleMesh, String)> = Vec::new();
    let mut pairs = Vec::new();
    for (index, batch) in batches.iter().enumerate() {
        let mesh = match meshes.iter().find(|(m, _)| same_mesh(m, &batch.mesh)) {
            Some((_, name)) => name.clone(),
            None => {
                let name = format!("mesh-{:03}.ply", meshes.len());
                let note = format!(
                    "mesh of stability case {case}, first judged in pair {index}; face i is primID i"
                );
                write_file(&dir.join(&name), &ply::to_bytes(&batch.mesh, &[note]))?;
                meshes.push((&batch.mesh, name.clone()));
                name
            }
        };
        let pair = Pair {
            mesh,
            closest: format!("pair-{index:03}.closest.rays"),
            any_hit: format!("pair-{index:03}.any-hit.rays"),
            must_hit: batch.must_hit,
        };
        for (name, set, rays) in [
            (&pair.closest, RaySet::StabilityCase, &batch.closest),
            (&pair.any_hit, RaySet::StabilityCaseAnyHit, &batch.any_hit),
        ] {
            RaysFile {
                set,
                rays: rays.clone(),
            }
            .write(&dir.join(name))?;
        }
        pairs.push(pair);
    }
    let manifest = Manifest {
        format: FORMAT.to_string(),
        version: VERSION,
        case: case.to_string(),
        form: if full { "full" } else { "quick" }.to_string(),
        pairs,
    };
    write_file(
        &dir.join(MANIFEST),
        serde_json::to_string_pretty(&manifest)?.as_bytes(),
    )?;
    Ok(manifest)
}

/// Whether two meshes have the same vertices, bit for bit, and faces.
fn same_mesh(a: &TriangleMesh, b: &TriangleMesh) -> bool {
    let bits = |m: &TriangleMesh| -> Vec<[u32; 3]> {
        m.positions
            .iter()
            .map(|p| p.to_array().map(f32::to_bits))
            .collect()
    };
    a.indices == b.indices && bits(a) == bits(b)
}

fn write_file(path: &Path, bytes: &[u8]) -> Result<(), FileError> {
    std::fs::write(path, bytes).map_err(|e| FileError {
        path: path.to_path_buf(),
        what: format!("cannot write: {e}"),
    })
}

impl Manifest {
    /// Parses a manifest; `path` names it in errors. Every file it names
    /// must be a plain name in the bundle's folder.
    pub fn parse(path: &Path, text: &str) -> Result<Self, FileError> {
        let error = |what: String| FileError {
            path: path.to_path_buf(),
            what,
        };
        let manifest: Manifest = serde_json::from_str(text).map_err(|e| {
            error(format!(
                "line {}, column {}: not a bundle manifest: {e}",
                e.line(),
                e.column()
            ))
        })?;
        if manifest.format != FORMAT || manifest.version != VERSION {
            return Err(error(format!(
                "format \"{}\" version {} is not supported (this raycheck reads \"{FORMAT}\" \
                 version {VERSION})",
                manifest.format, manifest.version
            )));
        }
        for (index, pair) in manifest.pairs.iter().enumerate() {
            for name in [&pair.mesh, &pair.closest, &pair.any_hit] {
                let plain = Path::new(name)
                    .file_name()
                    .is_some_and(|n| n == name.as_str());
                if !plain {
                    return Err(error(format!(
                        "pair {index}: \"{name}\" is not a file name in the bundle's folder"
                    )));
                }
            }
        }
        Ok(manifest)
    }
}

impl Bundle {
    /// Reads the manifest of the bundle in `dir`.
    pub fn open(dir: &Path) -> Result<Self, FileError> {
        let path = dir.join(MANIFEST);
        let text = std::fs::read_to_string(&path).map_err(|e| FileError {
            path: path.clone(),
            what: format!("cannot read the bundle's manifest: {e}"),
        })?;
        Ok(Self {
            dir: dir.to_path_buf(),
            manifest: Manifest::parse(&path, &text)?,
        })
    }

    /// Reads pair `index`: its mesh and its two rays files, which must be
    /// the sets the manifest names them for.
    pub fn load(&self, index: usize) -> anyhow::Result<LoadedPair> {
        let pair = &self.manifest.pairs[index];
        let mesh = crate::scene::formats::ply::load(&self.dir.join(&pair.mesh))?.mesh;
        let rays = |name: &str, set: RaySet| -> anyhow::Result<RaysFile> {
            let path = self.dir.join(name);
            let file = RaysFile::read(&path)?;
            anyhow::ensure!(
                file.set == set,
                "{}: holds {} rays, where the bundle's manifest expects {} rays",
                path.display(),
                file.set.name(),
                set.name()
            );
            Ok(file)
        };
        Ok(LoadedPair {
            mesh,
            closest: rays(&pair.closest, RaySet::StabilityCase)?,
            any_hit: rays(&pair.any_hit, RaySet::StabilityCaseAnyHit)?,
            must_hit: pair.must_hit,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn manifest(mesh: &str) -> String {
        format!(
            r#"{{"format": "raycheck bundle", "version": 1, "case": "c", "form": "quick",
               "pairs": [{{"mesh": "{mesh}", "closest": "a.rays", "any_hit": "b.rays",
                           "must_hit": false}}]}}"#
        )
    }

    #[test]
    fn manifests_name_files_in_the_folder_only() {
        let path = Path::new("bundle.json");
        assert!(Manifest::parse(path, &manifest("m.ply")).is_ok());
        for bad in ["../m.ply", "/etc/m.ply", "sub/m.ply", "..", ""] {
            let message = Manifest::parse(path, &manifest(bad))
                .unwrap_err()
                .to_string();
            assert!(message.contains("pair 0:"), "{bad}: {message}");
        }
    }

    #[test]
    fn bad_manifests_are_named_errors() {
        let path = Path::new("b/bundle.json");
        let what = |text: &str| Manifest::parse(path, text).unwrap_err().to_string();
        assert!(what("{").starts_with("b/bundle.json: line 1"));
        assert!(
            what(&manifest("m.ply").replace("version\": 1", "version\": 2"))
                .contains("version 2 is not supported")
        );
        assert!(what(&manifest("m.ply").replace("must_hit", "must")).contains("unknown field"));
    }
}
