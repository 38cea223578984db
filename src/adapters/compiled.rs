//! A C++ adapter compiled once into the cache: `<cache>/programs/<name>-<key>`,
//! the key hashing the source, the flags and the compiler's `--version`, so
//! an edited source or another compiler makes a new program. The program is
//! linked in a temporary folder beside it and appears by one rename.

use super::{SetupError, key, run};
use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The compiler used unless told otherwise: the one on `PATH`.
pub const CXX: &str = "g++";

/// The flags every program is compiled with.
pub const FLAGS: [&str; 3] = ["-std=c++17", "-O2", "-pthread"];

const CXX_HELP: &str = "install a C++17 compiler (Debian: g++)";

/// The program compiled from the C++ `source` with `compiler`, under
/// `cache`: compiled first if it is not there.
pub fn compile_cpp(
    cache: &Path,
    compiler: &OsStr,
    name: &str,
    source: &str,
) -> Result<PathBuf, SetupError> {
    let mut version = Command::new(compiler);
    version.arg("--version");
    let version = run(version, CXX_HELP)?;
    let root = cache.join("programs");
    let program = root.join(format!(
        "{name}-{}",
        key(&[
            source.as_bytes(),
            FLAGS.join(" ").as_bytes(),
            version.as_bytes()
        ])
    ));
    if program.is_file() {
        return Ok(program);
    }
    std::fs::create_dir_all(&root).map_err(SetupError::io(&root))?;
    let temp = tempfile::Builder::new()
        .prefix(".tmp-")
        .tempdir_in(&root)
        .map_err(SetupError::io(&root))?;
    let file = temp.path().join(format!("{name}.cpp"));
    std::fs::write(&file, source).map_err(SetupError::io(&file))?;
    let linked = temp.path().join(name);
    let mut compile = Command::new(compiler);
    compile.args(FLAGS).arg(&file).arg("-o").arg(&linked);
    run(compile, CXX_HELP)?;
    std::fs::rename(&linked, &program).map_err(SetupError::io(&program))?;
    Ok(program)
}
