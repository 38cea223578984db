//! Finds the Embree 4.4 shared library to link against.
//!
//! - `EMBREE_DIR` set: that folder must hold `libembree4.so`.
//! - Otherwise a per-user cache folder (`$RAYCHECK_CACHE_DIR`, else
//!   `$XDG_CACHE_HOME/raycheck`, else `$HOME/.cache/raycheck`) holds
//!   `embree-4.4.0/`, fetched from the pinned `embreex` wheel when missing
//!   and checked file by file whenever this script runs (see
//!   `build_script/embree_cache.rs`). The script runs again when one of
//!   those files changes, so a damaged library is fetched again at the next
//!   build instead of failing the test binaries as they start.
//!
//! Dependents read the folder from `DEP_EMBREE4_ROOT` to set their rpath.

#[path = "build_script/embree_cache.rs"]
mod embree_cache;

use std::env;
use std::path::{Path, PathBuf};
use std::process::exit;

use embree_cache::{LINK_NAME, checked_embree_folder};

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=build_script/embree_cache.rs");
    for var in ["EMBREE_DIR", "RAYCHECK_CACHE_DIR", "XDG_CACHE_HOME", "HOME"] {
        println!("cargo:rerun-if-env-changed={var}");
    }
    match locate_embree() {
        Ok((dir, watched)) => emit_link_directives(&dir, &watched),
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

/// Tells cargo how to link Embree, which files to watch and where
/// dependents find it.
fn emit_link_directives(dir: &Path, watched: &[PathBuf]) {
    for file in watched {
        println!("cargo:rerun-if-changed={}", file.display());
    }
    let dir = dir.display();
    println!("cargo:rustc-link-search=native={dir}");
    println!("cargo:rustc-link-lib=dylib=embree4");
    println!("cargo:root={dir}");
    println!("cargo:rustc-link-arg=-Wl,-rpath,{dir}");
}

/// The Embree folder and the files in it whose change should run this
/// script again.
fn locate_embree() -> Result<(PathBuf, Vec<PathBuf>), String> {
    if let Some(dir) = env::var_os("EMBREE_DIR") {
        let dir = PathBuf::from(dir);
        let link = dir.join(LINK_NAME);
        return if link.exists() {
            Ok((dir, vec![link]))
        } else {
            Err(format!(
                "EMBREE_DIR={} holds no {LINK_NAME} (add a symlink to the versioned file if only \
                 that is there)",
                dir.display()
            ))
        };
    }
    let embree = checked_embree_folder(&cache_root()?)?;
    if let Some(repair) = &embree.repaired {
        println!("cargo:warning={repair}");
    }
    Ok((embree.dir, embree.files))
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
