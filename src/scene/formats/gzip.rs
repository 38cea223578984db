//! Transparent gzip: files starting with the gzip magic bytes are inflated,
//! whatever their name.

use crate::scene::error::SceneError;
use flate2::read::GzDecoder;
use std::borrow::Cow;
use std::io::Read;
use std::path::Path;

/// Inflated data larger than this is refused (a corrupt or hostile file
/// must not exhaust memory).
const MAX_INFLATED_BYTES: u64 = 1 << 30;

/// `bytes`, inflated if they are gzip data.
pub fn maybe_inflate<'a>(path: &Path, bytes: &'a [u8]) -> Result<Cow<'a, [u8]>, SceneError> {
    if !bytes.starts_with(&[0x1f, 0x8b]) {
        return Ok(Cow::Borrowed(bytes));
    }
    let mut out = Vec::new();
    GzDecoder::new(bytes)
        .take(MAX_INFLATED_BYTES + 1)
        .read_to_end(&mut out)
        .map_err(|e| SceneError::in_file(path, format!("corrupt gzip data: {e}")))?;
    if out.len() as u64 > MAX_INFLATED_BYTES {
        return Err(SceneError::in_file(
            path,
            format!("gzip data inflates to more than {MAX_INFLATED_BYTES} bytes"),
        ));
    }
    Ok(Cow::Owned(out))
}

#[cfg(test)]
mod tests {
    use super::*;
    use flate2::{Compression, write::GzEncoder};
    use std::io::Write;

    #[test]
    fn gzip_is_detected_by_content_not_name() {
        let mut enc = GzEncoder::new(Vec::new(), Compression::fast());
        enc.write_all(b"hello").unwrap();
        let packed = enc.finish().unwrap();
        let path = Path::new("plain.ply");
        assert_eq!(*maybe_inflate(path, &packed).unwrap(), *b"hello");
        assert_eq!(*maybe_inflate(path, b"ply\n").unwrap(), *b"ply\n");
    }

    #[test]
    fn truncated_gzip_is_an_error_naming_the_file() {
        let mut enc = GzEncoder::new(Vec::new(), Compression::fast());
        enc.write_all(&[7u8; 10_000]).unwrap();
        let mut packed = enc.finish().unwrap();
        packed.truncate(packed.len() / 2);
        let err = maybe_inflate(Path::new("cut.ply.gz"), &packed).unwrap_err();
        assert!(
            err.to_string().starts_with("cut.ply.gz: corrupt gzip"),
            "{err}"
        );
    }
}
