//! JavaScript modules that export a model as a base64 data URI
//! (`exports.default = "data:...;base64,...."`), as some npm packages ship them.

use super::glb;
use super::text::line_at;
use crate::scene::LoadedMesh;
use crate::scene::error::{SceneError, read_file};
use base64::Engine;
use std::path::Path;

/// Loads the first base64 data URI in a `.js` file as a GLB model.
pub fn load(path: &Path) -> Result<LoadedMesh, SceneError> {
    let text = read_file(path)?;
    let start = find(&text, b"data:")
        .ok_or_else(|| SceneError::in_file(path, "no `data:` URI in this module"))?;
    let line = line_at(&text, start);
    let err = |msg: String| SceneError::at(path, line, msg);
    let rest = &text[start..];
    let payload_start = find(rest, b";base64,")
        .ok_or_else(|| err("the data URI is not base64".into()))?
        + b";base64,".len();
    let payload = &rest[payload_start..];
    let end = payload
        .iter()
        .position(|&b| !(b.is_ascii_alphanumeric() || b"+/=".contains(&b)))
        .unwrap_or(payload.len());
    let bytes = base64::engine::general_purpose::STANDARD
        .decode(&payload[..end])
        .map_err(|e| err(format!("invalid base64 in the data URI: {e}")))?;
    glb::parse(&path.with_extension("js (embedded GLB)"), &bytes)
}

fn find(haystack: &[u8], needle: &[u8]) -> Option<usize> {
    haystack.windows(needle.len()).position(|w| w == needle)
}
