//! Fuzzes the PLY loader, gzip included (`scene::formats::ply::parse_bytes`): any bytes must
//! give a mesh or an error, never a panic, hang or OOM.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let _ = raycheck::scene::formats::ply::parse_bytes(Path::new("input.ply"), data);
});
