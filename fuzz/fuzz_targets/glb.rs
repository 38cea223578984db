//! Fuzzes the GLB loader, Draco included (`scene::formats::glb::parse`): any bytes must
//! give a mesh or an error, never a panic, hang or OOM.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let _ = raycheck::scene::formats::glb::parse(Path::new("input.glb"), data);
});
