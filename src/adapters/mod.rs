//! Tracers that are not Rust crates, run as programs: the adapters in the
//! repository's `adapters/` folder (Mitsuba 3 in its `scalar_rgb` and
//! `llvm_ad_rgb` variants, trimesh's ray/triangle intersector, a C++
//! template), each run as `PROGRAM MESH.ply RAYS HITS` with the files of
//! `docs/exchange.md`, and what each needs set up the first time it is used,
//! in raycheck's cache: a Python virtual environment with pinned packages
//! ([`python_env`]) or a compiled program ([`compiled`]).
//!
//! Nothing here depends on the rest of raycheck: the cache folder is an
//! argument (raycheck's is `scene::assets::cache_dir()`).

pub mod compiled;
pub mod python_env;

pub use compiled::{CXX, compile_cpp};
pub use python_env::{PYTHON, PythonEnv};

use sha2::{Digest, Sha256};
use std::ffi::OsString;
use std::fmt;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Why an adapter could not be set up: what is missing or failed, and why.
#[derive(Debug, thiserror::Error)]
pub enum SetupError {
    /// A program raycheck runs (`python3`, `g++`) cannot be started.
    #[error("{program} cannot be run ({why}); {help}")]
    Missing {
        program: String,
        why: String,
        help: &'static str,
    },
    /// The interpreter's `venv` cannot put pip into a new environment.
    #[error(
        "{python} -m venv cannot install pip into a new environment (no ensurepip): {detail}; \
         install Python's venv module with pip (Debian: python3-venv)"
    )]
    NoPip { python: String, detail: String },
    /// pip could not reach the package index.
    #[error("pip could not reach the package index to install {what} (no network?): {detail}")]
    NoNetwork { what: String, detail: String },
    /// A command ran and failed; its output says why.
    #[error("{command} failed ({status}):\n{output}")]
    Failed {
        command: String,
        status: String,
        output: String,
    },
    /// A file or folder of the cache or the repository.
    #[error("{}: {error}", path.display())]
    Io {
        path: PathBuf,
        error: std::io::Error,
    },
}

impl SetupError {
    fn io(path: &Path) -> impl FnOnce(std::io::Error) -> Self + '_ {
        move |error| Self::Io {
            path: path.to_path_buf(),
            error,
        }
    }
}

/// The first 16 hex digits of the SHA-256 of `parts`, each followed by a
/// zero byte: the key of a cached environment or program.
fn key(parts: &[&[u8]]) -> String {
    let mut hash = Sha256::new();
    for part in parts {
        hash.update(part);
        hash.update([0]);
    }
    hash.finalize()[..8]
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// Runs `command` and returns its standard output, or the error that says
/// which program could not be started (`help` says what to install) or how
/// it failed.
fn run(mut command: Command, help: &'static str) -> Result<String, SetupError> {
    let program = command.get_program().to_string_lossy().into_owned();
    let output = command.output().map_err(|e| SetupError::Missing {
        program: program.clone(),
        why: e.to_string(),
        help,
    })?;
    if !output.status.success() {
        return Err(SetupError::Failed {
            command: shell_words(&command),
            status: output.status.to_string(),
            output: last_lines(&output.stderr, 30),
        });
    }
    Ok(String::from_utf8_lossy(&output.stdout).into_owned())
}

/// The last `n` lines of a program's output.
fn last_lines(bytes: &[u8], n: usize) -> String {
    let text = String::from_utf8_lossy(bytes);
    let lines: Vec<&str> = text.lines().collect();
    lines[lines.len().saturating_sub(n)..].join("\n")
}

/// A command as one line a POSIX shell reads back as the same words.
fn shell_words(command: &Command) -> String {
    std::iter::once(command.get_program())
        .chain(command.get_args())
        .map(|word| quote(&word.to_string_lossy()))
        .collect::<Vec<_>>()
        .join(" ")
}

fn quote(word: &str) -> String {
    let plain = !word.is_empty()
        && word
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "_-./=:,+@%".contains(c));
    if plain {
        word.to_string()
    } else {
        format!("'{}'", word.replace('\'', r"'\''"))
    }
}

/// The tracers in the repository's `adapters/` folder.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Adapter {
    /// Mitsuba 3's `scalar_rgb` variant: one ray per Python call.
    MitsubaScalar,
    /// Mitsuba 3's `llvm_ad_rgb` variant: every ray in one call, as arrays.
    MitsubaLlvm,
    /// trimesh's pure-numpy `ray_triangle.RayMeshIntersector`.
    Trimesh,
    /// `adapters/cpp/raycheck_tracer.cpp`: the template for a tracer of
    /// one's own, with a brute-force intersector in its place.
    CppTemplate,
}

impl Adapter {
    /// The repository's `adapters/` folder.
    pub fn folder() -> PathBuf {
        PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/adapters"))
    }

    /// Sets up what the adapter needs under `cache` (its Python environment
    /// or its compiled program; nothing when already there) and returns the
    /// command that runs it.
    pub fn prepare(self, cache: &Path) -> Result<ProgramCommand, SetupError> {
        let folder = Self::folder();
        let python = |env: &str, script: &str, args: &[&str]| {
            let requirements = folder.join(env).join("requirements.txt");
            let text =
                std::fs::read_to_string(&requirements).map_err(SetupError::io(&requirements))?;
            let env = PythonEnv::ensure(cache, PYTHON.as_ref(), env, &text)?;
            Ok(ProgramCommand {
                program: env.python(),
                args: std::iter::once(folder.join(script).into_os_string())
                    .chain(args.iter().map(OsString::from))
                    .collect(),
            })
        };
        match self {
            Adapter::MitsubaScalar => python(
                "mitsuba",
                "mitsuba/raycheck_mitsuba.py",
                &["--variant", "scalar_rgb"],
            ),
            Adapter::MitsubaLlvm => python(
                "mitsuba",
                "mitsuba/raycheck_mitsuba.py",
                &["--variant", "llvm_ad_rgb"],
            ),
            Adapter::Trimesh => python("trimesh", "trimesh/raycheck_trimesh.py", &[]),
            Adapter::CppTemplate => {
                let source = folder.join("cpp/raycheck_tracer.cpp");
                let text = std::fs::read_to_string(&source).map_err(SetupError::io(&source))?;
                Ok(ProgramCommand {
                    program: compile_cpp(cache, CXX.as_ref(), "raycheck_tracer", &text)?,
                    args: Vec::new(),
                })
            }
        }
    }
}

/// How to run a program backend (a prepared adapter, or a program a
/// tracers file names): `program args… MESH RAYS HITS`.
#[derive(Clone, Debug, PartialEq)]
pub struct ProgramCommand {
    pub program: PathBuf,
    pub args: Vec<OsString>,
}

impl ProgramCommand {
    /// The command that traces `rays` through `mesh` into `hits`.
    pub fn with_files(&self, mesh: &Path, rays: &Path, hits: &Path) -> Command {
        let mut command = Command::new(&self.program);
        command.args(&self.args).args([mesh, rays, hits]);
        command
    }
}

impl fmt::Display for ProgramCommand {
    /// The command as one shell line, without the three file arguments.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut command = Command::new(&self.program);
        command.args(&self.args);
        f.write_str(&shell_words(&command))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shell_lines_quote_only_what_needs_it() {
        let command = ProgramCommand {
            program: "/cache/python/bin/python".into(),
            args: vec!["a b.py".into(), "it's".into(), "--variant".into()],
        };
        assert_eq!(
            command.to_string(),
            r"/cache/python/bin/python 'a b.py' 'it'\''s' --variant"
        );
    }

    #[test]
    fn keys_separate_their_parts() {
        assert_ne!(key(&[b"ab", b"c"]), key(&[b"a", b"bc"]));
        assert_eq!(key(&[b"x"]).len(), 16);
    }
}
