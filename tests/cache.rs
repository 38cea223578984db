//! The asset cache heals: a cached mesh damaged so that it no longer
//! parses is fetched again on its next use, with one line saying which file
//! and the hash expected and found, and the command succeeds.

use sha2::{Digest, Sha256};
use std::process::{Command, Output};

fn explain_monkey(cache: &std::path::Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_raycheck"))
        .args(["render", "monkey", "--explain"])
        .env("RAYCHECK_CACHE_DIR", cache)
        .output()
        .unwrap()
}

fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

#[test]
fn a_cached_mesh_damaged_past_parsing_is_fetched_again_with_one_line() {
    let cache = tempfile::tempdir().unwrap();
    let first = explain_monkey(cache.path());
    assert!(first.status.success());
    assert_eq!(String::from_utf8_lossy(&first.stderr), "");
    let file = cache.path().join("npm/gsimone-suzanne-0.0.12/index.js");
    let original = std::fs::read(&file).unwrap();
    let truncated = &original[..original.len() / 2];
    std::fs::write(&file, truncated).unwrap();

    let second = explain_monkey(cache.path());
    assert!(
        second.status.success(),
        "{}",
        String::from_utf8_lossy(&second.stderr)
    );
    assert_eq!(
        String::from_utf8_lossy(&second.stderr),
        format!(
            "note: cached file {} has SHA-256 {}, expected {}: fetched @gsimone/suzanne@0.0.12 again\n",
            file.display(),
            sha256_hex(truncated),
            sha256_hex(&original)
        )
    );
    assert_eq!(second.stdout, first.stdout);
    assert_eq!(std::fs::read(&file).unwrap(), original);
}
