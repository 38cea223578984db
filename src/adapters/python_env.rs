//! A Python virtual environment for one adapter, made in the cache the first
//! time it is asked for and reused after.
//!
//! `<cache>/python/<name>-<key>/` is made by `python3 -m venv`, then
//! `pip install --require-hashes --no-deps --only-binary=:all: -r` of the
//! adapter's requirements: exact `==` versions, each with the SHA-256 of its
//! wheels, every dependency listed, nothing built from source. The key hashes
//! the requirements and the interpreter (its path, version and machine), so
//! new pins or another Python make a new environment. The environment is
//! built in a temporary folder beside it and appears by one rename, so no
//! process ever sees half of one; a lock file keeps two processes from
//! building the same one at once. It is used only through its `bin/python`
//! (the scripts pip writes into `bin/` name the temporary folder).

use super::{SetupError, key, last_lines, run, shell_words};
use std::ffi::OsStr;
use std::fs::File;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The interpreter that makes environments: the one on `PATH`.
pub const PYTHON: &str = "python3";

/// The requirements an environment was made from, inside it: pip installs
/// from this file, and a folder holding it with these contents is ready.
const REQUIREMENTS: &str = "raycheck-requirements.txt";

/// What pip prints when it cannot connect, as urllib3 and the socket layer
/// word it.
const NETWORK_ERRORS: [&str; 8] = [
    "NewConnectionError",
    "Failed to establish a new connection",
    "Temporary failure in name resolution",
    "Name or service not known",
    "Network is unreachable",
    "ProxyError",
    "ConnectTimeoutError",
    "ReadTimeoutError",
];

const PYTHON_HELP: &str = "install Python 3 with its venv module (wheels are pinned for \
                           CPython 3.11 to 3.13 on Linux x86_64)";

/// A ready environment.
#[derive(Clone, Debug, PartialEq)]
pub struct PythonEnv {
    dir: PathBuf,
}

impl PythonEnv {
    /// The environment `name` with `requirements` (the text of a pip
    /// requirements file) for the interpreter `python`, under `cache`:
    /// made first if it is not there or not whole.
    pub fn ensure(
        cache: &Path,
        python: &OsStr,
        name: &str,
        requirements: &str,
    ) -> Result<Self, SetupError> {
        let identity = interpreter(python)?;
        let root = cache.join("python");
        let env = Self {
            dir: root.join(format!(
                "{name}-{}",
                key(&[requirements.as_bytes(), identity.as_bytes()])
            )),
        };
        if env.is_ready(requirements) {
            return Ok(env);
        }
        std::fs::create_dir_all(&root).map_err(SetupError::io(&root))?;
        let lock_path = root.join(format!("{name}.lock"));
        let lock = File::create(&lock_path).map_err(SetupError::io(&lock_path))?;
        lock.lock().map_err(SetupError::io(&lock_path))?;
        if env.is_ready(requirements) {
            return Ok(env);
        }
        let temp = tempfile::Builder::new()
            .prefix(".tmp-")
            .tempdir_in(&root)
            .map_err(SetupError::io(&root))?;
        let staged = temp.path().join("env");
        build(python, &staged, requirements, name)?;
        if env.dir.exists() {
            // Not whole (no requirements, or no interpreter): set it aside
            // with the temporary folder, which removes it.
            let aside = temp.path().join("damaged");
            std::fs::rename(&env.dir, &aside).map_err(SetupError::io(&env.dir))?;
        }
        std::fs::rename(&staged, &env.dir).map_err(SetupError::io(&env.dir))?;
        Ok(env)
    }

    /// The environment's folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Its interpreter, which sees the installed packages.
    pub fn python(&self) -> PathBuf {
        self.dir.join("bin").join("python")
    }

    fn is_ready(&self, requirements: &str) -> bool {
        self.python().exists()
            && std::fs::read_to_string(self.dir.join(REQUIREMENTS)).is_ok_and(|r| r == requirements)
    }
}

/// The interpreter's path, version and machine, as it reports them.
fn interpreter(python: &OsStr) -> Result<String, SetupError> {
    let mut command = Command::new(python);
    command.args([
        "-c",
        "import platform, sys; print(sys.executable, platform.python_version(), platform.machine())",
    ]);
    run(command, PYTHON_HELP)
}

/// Makes the environment in `dir` and installs `requirements` into it.
fn build(python: &OsStr, dir: &Path, requirements: &str, name: &str) -> Result<(), SetupError> {
    let mut venv = Command::new(python);
    venv.args(["-m", "venv"]).arg(dir);
    run(venv, PYTHON_HELP).map_err(|e| match e {
        SetupError::Failed { output, .. } if output.contains("ensurepip") => SetupError::NoPip {
            python: python.to_string_lossy().into_owned(),
            detail: output.lines().last().unwrap_or_default().trim().to_string(),
        },
        other => other,
    })?;
    let file = dir.join(REQUIREMENTS);
    std::fs::write(&file, requirements).map_err(SetupError::io(&file))?;
    let mut pip = Command::new(dir.join("bin").join("python"));
    pip.args(["-m", "pip", "install", "--require-hashes", "--no-deps"])
        .args([
            "--only-binary=:all:",
            "--disable-pip-version-check",
            "--no-input",
        ])
        .arg("-r")
        .arg(&file);
    let output = pip.output().map_err(SetupError::io(dir))?;
    if output.status.success() {
        return Ok(());
    }
    let stderr = String::from_utf8_lossy(&output.stderr);
    match stderr
        .lines()
        .find(|line| NETWORK_ERRORS.iter().any(|e| line.contains(e)))
    {
        Some(line) => Err(SetupError::NoNetwork {
            what: format!("the {name} environment"),
            detail: connection_reason(line),
        }),
        None => Err(SetupError::Failed {
            command: shell_words(&pip),
            status: output.status.to_string(),
            output: last_lines(&output.stderr, 30),
        }),
    }
}

/// The reason in one of pip's connection warnings (`... Failed to establish
/// a new connection: [Errno -3] Temporary failure in name resolution')': ...`),
/// else the whole line.
fn connection_reason(line: &str) -> String {
    const MARK: &str = "Failed to establish a new connection: ";
    match line.split_once(MARK) {
        Some((_, rest)) => rest.split('\'').next().unwrap_or(rest).to_string(),
        None => line.trim().to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_reason_is_cut_out_of_pips_warning() {
        let line = "WARNING: Retrying (Retry(total=4)) after connection broken by \
                    'NewConnectionError('<HTTPSConnection object at 0x7f>: Failed to establish a \
                    new connection: [Errno -3] Temporary failure in name resolution')': /simple/x/";
        assert_eq!(
            connection_reason(line),
            "[Errno -3] Temporary failure in name resolution"
        );
        assert_eq!(connection_reason("  ProxyError: 407  "), "ProxyError: 407");
    }
}
