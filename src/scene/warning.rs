//! Warnings of mesh loading: input that is wrong but can be loaded without
//! the wrong part, saying what was left out.

use std::fmt;
use std::path::PathBuf;

/// Something a loader left out, at a line of a file.
#[derive(Clone, Debug, PartialEq)]
pub struct LoadWarning {
    pub path: PathBuf,
    pub line: usize,
    pub message: String,
}

impl fmt::Display for LoadWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}:{}: warning: {}",
            self.path.display(),
            self.line,
            self.message
        )
    }
}
