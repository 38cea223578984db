//! Finds the Embree 4.4 shared library to link against.
//!
//! - `EMBREE_DIR` set: that folder must hold `libembree4.so`.
//! - Otherwise a per-user cache folder (`$RAYCHECK_CACHE_DIR`, else
//!   `$XDG_CACHE_HOME/raycheck`, else `$HOME/.cache/raycheck`) holds
//!   `embree-4.4.0/`. When it is missing, the pinned `embreex` wheel (which
//!   ships Embree 4.4.0 and its TBB) is fetched once with Python's own package
//!   client, checked against a pinned SHA-256, and its two shared libraries
//!   are unpacked. The folder appears by one rename, so concurrent builds
//!   never see half of it.
//!
//! Dependents read the folder from `DEP_EMBREE4_ROOT` to set their rpath.

use std::env;
use std::fs;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, exit};
use std::time::{SystemTime, UNIX_EPOCH};

use sha2::{Digest, Sha256};

/// The package (by name and version) whose wheel carries Embree 4.4.0.
const WHEEL_REQUIREMENT: &str = "embreex==4.4.0.post1";
/// SHA-256 of the one wheel of that release built for Linux x86_64.
const WHEEL_SHA256: &str = "2cd0f7d5c6342e6247e31f700761689cae7829454d8c6de0c41e62124a023e1f";
/// Name of the folder inside the cache that holds the unpacked libraries.
const CACHE_SUBDIR: &str = "embree-4.4.0";
/// The unversioned name the linker looks for with `-lembree4`.
const LINK_NAME: &str = "libembree4.so";

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    for var in ["EMBREE_DIR", "RAYCHECK_CACHE_DIR", "XDG_CACHE_HOME", "HOME"] {
        println!("cargo:rerun-if-env-changed={var}");
    }
    match locate_embree() {
        Ok(dir) => emit_link_directives(&dir),
        Err(message) => {
            eprintln!("error: raycheck-reference cannot find Embree 4.4: {message}");
            eprintln!(
                "help: either install python3 with pip (Embree is then fetched once into the \
                 cache), or set EMBREE_DIR to a folder holding libembree4.so of Embree 4.4"
            );
            exit(1);
        }
    }
}

/// Tells cargo how to link Embree and where dependents find it.
fn emit_link_directives(dir: &Path) {
    let dir = dir.display();
    println!("cargo:rerun-if-changed={dir}/{LINK_NAME}");
    println!("cargo:rustc-link-search=native={dir}");
    println!("cargo:rustc-link-lib=dylib=embree4");
    println!("cargo:root={dir}");
    println!("cargo:rustc-link-arg=-Wl,-rpath,{dir}");
}

fn locate_embree() -> Result<PathBuf, String> {
    if let Some(dir) = env::var_os("EMBREE_DIR") {
        let dir = PathBuf::from(dir);
        return if dir.join(LINK_NAME).exists() {
            Ok(dir)
        } else {
            Err(format!(
                "EMBREE_DIR={} holds no {LINK_NAME} (add a symlink to the versioned file if only \
                 that is there)",
                dir.display()
            ))
        };
    }
    let cache = cache_root()?;
    let dir = cache.join(CACHE_SUBDIR);
    if !dir.join(LINK_NAME).exists() {
        fetch_into_cache(&cache, &dir)?;
    }
    Ok(dir)
}

fn cache_root() -> Result<PathBuf, String> {
    if let Some(dir) = env::var_os("RAYCHECK_CACHE_DIR") {
        return Ok(PathBuf::from(dir));
    }
    if let Some(dir) = env::var_os("XDG_CACHE_HOME") {
        return Ok(PathBuf::from(dir).join("raycheck"));
    }
    match env::var_os("HOME") {
        Some(home) => Ok(PathBuf::from(home).join(".cache").join("raycheck")),
        None => Err("no cache folder: set RAYCHECK_CACHE_DIR, XDG_CACHE_HOME or HOME".into()),
    }
}

/// Downloads, verifies and unpacks the wheel into a private temporary folder
/// inside `cache`, then renames the finished library folder to `target`.
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
    let digest: String = Sha256::digest(&bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    if digest != WHEEL_SHA256 {
        return Err(format!(
            "{} has SHA-256 {digest}, expected {WHEEL_SHA256}",
            wheel.display()
        ));
    }
    let embree_file = unpack_libraries(&bytes, &staged)?;
    std::os::unix::fs::symlink(&embree_file, staged.join(LINK_NAME))
        .map_err(|e| format!("cannot create the {LINK_NAME} symlink: {e}"))?;

    if let Err(e) = fs::rename(&staged, target) {
        // Another build may have finished first; its folder is just as good.
        if !target.join(LINK_NAME).exists() {
            return Err(format!("cannot move Embree into {}: {e}", target.display()));
        }
    }
    Ok(())
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

/// Unpacks Embree and TBB under their own (versioned) names, which the
/// library's dynamic section refers to; returns Embree's file name.
fn unpack_libraries(wheel: &[u8], into: &Path) -> Result<String, String> {
    let mut archive = zip::ZipArchive::new(std::io::Cursor::new(wheel))
        .map_err(|e| format!("the wheel is not a readable zip archive: {e}"))?;
    let mut embree_file = None;
    let mut tbb_found = false;
    for index in 0..archive.len() {
        let mut entry = archive
            .by_index(index)
            .map_err(|e| format!("cannot read wheel entry {index}: {e}"))?;
        let name = entry
            .name()
            .map_err(|e| format!("wheel entry {index} has no readable name: {e}"))?;
        let Some(file_name) = name.strip_prefix("embreex.libs/").map(str::to_owned) else {
            continue;
        };
        let is_embree = file_name.starts_with("libembree4-") && file_name.ends_with(".so.4");
        let is_tbb = file_name.starts_with("libtbb-") && file_name.ends_with(".so.12");
        if !is_embree && !is_tbb {
            continue;
        }
        let mut contents = Vec::new();
        entry
            .read_to_end(&mut contents)
            .map_err(|e| format!("cannot unpack {file_name}: {e}"))?;
        let path = into.join(&file_name);
        fs::write(&path, contents).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        if is_embree {
            embree_file = Some(file_name);
        } else {
            tbb_found = true;
        }
    }
    match (embree_file, tbb_found) {
        (Some(name), true) => Ok(name),
        _ => Err("the wheel lacks embreex.libs/libembree4-*.so.4 or libtbb-*.so.12".into()),
    }
}
