//! The cached copy of Embree 4.4: fetched once, checked on every build.
//!
//! `<cache>/embree-4.4.0/` holds the two shared libraries of the pinned
//! `embreex` wheel (Embree 4.4.0 and its TBB) under their own versioned
//! names, and `libembree4.so`, a link to the Embree one. The wheel is
//! fetched with Python's own package client and checked against a pinned
//! SHA-256; the libraries' own SHA-256 are pinned too, so the unpacked
//! files can be checked whenever the build script runs: a damaged library
//! would otherwise fail only when a test binary loads it, before `main`.
//! A missing folder is fetched; a damaged file or link is fetched again,
//! with one line naming it and the hash expected and found.
//!
//! A first fetch appears by one rename of the whole folder; a repair
//! renames each fresh file over its namesake, so a process that has the
//! old library loaded keeps it and no reader finds a file missing.

use std::fs;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{SystemTime, UNIX_EPOCH};

use sha2::{Digest, Sha256};

/// The package (by name and version) whose wheel carries Embree 4.4.0.
const WHEEL_REQUIREMENT: &str = "embreex==4.4.0.post1";
/// SHA-256 of the one wheel of that release built for Linux x86_64.
const WHEEL_SHA256: &str = "2cd0f7d5c6342e6247e31f700761689cae7829454d8c6de0c41e62124a023e1f";
/// The libraries under `embreex.libs/` in that wheel, Embree first, with
/// their SHA-256.
pub const LIBRARIES: [(&str, &str); 2] = [
    (
        "libembree4-4aef3270.so.4",
        "aa4eb9d81e30237d032418832efd9caee19bead50f49939fb08347a053898c7a",
    ),
    (
        "libtbb-dcf63f8c.so.12",
        "08d7ce01dcce5c49f874ee91ba8dad75ee3aa1838d5ce8a92f5b2ec98b9df2ed",
    ),
];
/// Name of the folder inside the cache that holds the unpacked libraries.
const CACHE_SUBDIR: &str = "embree-4.4.0";
/// The unversioned name the linker looks for with `-lembree4`.
pub const LINK_NAME: &str = "libembree4.so";

/// The checked Embree folder.
pub struct CheckedEmbree {
    pub dir: PathBuf,
    /// The libraries and the link, for the build to watch.
    pub files: Vec<PathBuf>,
    /// What was damaged and fetched again, in one line.
    pub repaired: Option<String>,
}

/// The Embree folder under `cache`, fetched if absent and again if damaged.
pub fn checked_embree_folder(cache: &Path) -> Result<CheckedEmbree, String> {
    let dir = cache.join(CACHE_SUBDIR);
    let repaired = if dir.exists() {
        match damage(&dir) {
            None => None,
            Some(damage) => {
                fetch_into_cache(cache, &dir).map_err(|e| {
                    format!("{damage}; fetching {WHEEL_REQUIREMENT} again failed: {e}")
                })?;
                Some(format!("{damage}: fetched {WHEEL_REQUIREMENT} again"))
            }
        }
    } else {
        fetch_into_cache(cache, &dir)?;
        None
    };
    if let Some(still) = damage(&dir) {
        return Err(format!("{still}, right after fetching {WHEEL_REQUIREMENT}"));
    }
    let files = std::iter::once(LINK_NAME)
        .chain(LIBRARIES.map(|(name, _)| name))
        .map(|name| dir.join(name))
        .collect();
    Ok(CheckedEmbree {
        dir,
        files,
        repaired,
    })
}

/// The first thing wrong with the folder, in words naming the file: a
/// library missing or with another SHA-256, or the link not pointing at
/// the Embree library.
fn damage(dir: &Path) -> Option<String> {
    for (name, expected) in LIBRARIES {
        let path = dir.join(name);
        match fs::read(&path) {
            Err(e) => return Some(format!("{} cannot be read ({e})", path.display())),
            Ok(bytes) => {
                let found = sha256_hex(&bytes);
                if found != expected {
                    return Some(format!(
                        "{} has SHA-256 {found}, expected {expected}",
                        path.display()
                    ));
                }
            }
        }
    }
    let link = dir.join(LINK_NAME);
    let embree = LIBRARIES[0].0;
    match fs::read_link(&link) {
        Ok(target) if target == Path::new(embree) => None,
        _ => Some(format!("{} is not a link to {embree}", link.display())),
    }
}

/// The SHA-256 of `bytes` in lowercase hex.
pub fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// Downloads, verifies and unpacks the wheel into a private temporary folder
/// inside `cache`, then moves the libraries and the link into `target`.
fn fetch_into_cache(cache: &Path, target: &Path) -> Result<(), String> {
    fs::create_dir_all(cache)
        .map_err(|e| format!("cannot create cache folder {}: {e}", cache.display()))?;
    let nonce = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos());
    let scratch = cache.join(format!(".fetch-{}-{nonce}", std::process::id()));
    let result = fetch_via_scratch(&scratch, target);
    // The scratch folder is ours alone; a failure to remove it only leaves litter.
    let _ = fs::remove_dir_all(&scratch);
    result
}

fn fetch_via_scratch(scratch: &Path, target: &Path) -> Result<(), String> {
    let wheel_dir = scratch.join("wheel");
    let staged = scratch.join(CACHE_SUBDIR);
    fs::create_dir_all(&wheel_dir)
        .map_err(|e| format!("cannot create {}: {e}", wheel_dir.display()))?;
    fs::create_dir_all(&staged).map_err(|e| format!("cannot create {}: {e}", staged.display()))?;

    let wheel = download_wheel(&wheel_dir)?;
    let bytes = fs::read(&wheel).map_err(|e| format!("cannot read {}: {e}", wheel.display()))?;
    let digest = sha256_hex(&bytes);
    if digest != WHEEL_SHA256 {
        return Err(format!(
            "{} has SHA-256 {digest}, expected {WHEEL_SHA256}",
            wheel.display()
        ));
    }
    unpack_libraries(&bytes, &staged)?;
    std::os::unix::fs::symlink(LIBRARIES[0].0, staged.join(LINK_NAME))
        .map_err(|e| format!("cannot create the {LINK_NAME} symlink: {e}"))?;

    if !target.exists() {
        match fs::rename(&staged, target) {
            Ok(()) => return Ok(()),
            // Another build may have just moved its own copy into place;
            // then the files below replace its files, which are the same.
            Err(_) if target.is_dir() => {}
            Err(e) => return Err(format!("cannot move Embree into {}: {e}", target.display())),
        }
    }
    for (name, _) in LIBRARIES {
        replace(&staged.join(name), &target.join(name))?;
    }
    replace(&staged.join(LINK_NAME), &target.join(LINK_NAME))
}

/// Renames `fresh` over `old`: one atomic step, whatever `old` was.
fn replace(fresh: &Path, old: &Path) -> Result<(), String> {
    fs::rename(fresh, old).map_err(|e| format!("cannot replace {}: {e}", old.display()))
}

/// Runs `python3 -m pip download` for the pinned wheel; returns its path.
fn download_wheel(into: &Path) -> Result<PathBuf, String> {
    let output = Command::new("python3")
        .args(["-m", "pip", "download", "--no-deps", "--only-binary=:all:"])
        .args(["--python-version", "3.11", "--disable-pip-version-check"])
        .arg(WHEEL_REQUIREMENT)
        .arg("-d")
        .arg(into)
        .output()
        .map_err(|e| format!("cannot run python3 -m pip: {e}"))?;
    if !output.status.success() {
        return Err(format!(
            "python3 -m pip download {WHEEL_REQUIREMENT} failed ({}):\n{}",
            output.status,
            String::from_utf8_lossy(&output.stderr)
        ));
    }
    let entries = fs::read_dir(into).map_err(|e| format!("cannot list {}: {e}", into.display()))?;
    entries
        .filter_map(Result::ok)
        .map(|entry| entry.path())
        .find(|path| path.extension().is_some_and(|ext| ext == "whl"))
        .ok_or_else(|| {
            format!(
                "pip reported success but left no wheel in {}",
                into.display()
            )
        })
}

/// Unpacks the [`LIBRARIES`] under their own (versioned) names, which the
/// Embree library's dynamic section refers to, each checked against its
/// pinned SHA-256.
fn unpack_libraries(wheel: &[u8], into: &Path) -> Result<(), String> {
    let mut archive = zip::ZipArchive::new(std::io::Cursor::new(wheel))
        .map_err(|e| format!("the wheel is not a readable zip archive: {e}"))?;
    for (name, expected) in LIBRARIES {
        let mut entry = archive
            .by_name(&format!("embreex.libs/{name}"))
            .map_err(|e| format!("the wheel lacks embreex.libs/{name}: {e}"))?;
        let mut contents = Vec::new();
        entry
            .read_to_end(&mut contents)
            .map_err(|e| format!("cannot unpack {name}: {e}"))?;
        let found = sha256_hex(&contents);
        if found != expected {
            return Err(format!(
                "the wheel's {name} has SHA-256 {found}, expected {expected}"
            ));
        }
        let path = into.join(name);
        fs::write(&path, contents).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    }
    Ok(())
}
