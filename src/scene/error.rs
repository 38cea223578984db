//! The one error type of scene loading: every message names the file, and the
//! line where the format has lines.

use std::path::{Path, PathBuf};

#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// Something wrong at a known line of a text file.
    #[error("{}:{line}: {message}", path.display())]
    AtLine {
        path: PathBuf,
        line: usize,
        message: String,
    },
    /// Something wrong in a file without lines (binary data) or with the
    /// file as a whole.
    #[error("{}: {message}", path.display())]
    InFile { path: PathBuf, message: String },
    /// The file could not be read.
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    /// A packaged asset could not be fetched or unpacked.
    #[error("asset {asset}: {message}")]
    Asset { asset: String, message: String },
    /// A scene name that is neither a built-in scene nor a file.
    #[error("unknown scene {name:?}: not a file, and the built-in scenes are {}", known.join(", "))]
    UnknownScene { name: String, known: Vec<String> },
}

impl SceneError {
    pub fn at(path: &Path, line: usize, message: impl Into<String>) -> Self {
        Self::AtLine {
            path: path.to_path_buf(),
            line,
            message: message.into(),
        }
    }

    pub fn in_file(path: &Path, message: impl Into<String>) -> Self {
        Self::InFile {
            path: path.to_path_buf(),
            message: message.into(),
        }
    }

    pub fn io(path: &Path, source: std::io::Error) -> Self {
        Self::Io {
            path: path.to_path_buf(),
            source,
        }
    }

    pub fn asset(asset: &str, message: impl Into<String>) -> Self {
        Self::Asset {
            asset: asset.to_string(),
            message: message.into(),
        }
    }
}

/// Reads a whole file, naming it on failure.
pub fn read_file(path: &Path) -> Result<Vec<u8>, SceneError> {
    std::fs::read(path).map_err(|e| SceneError::io(path, e))
}
