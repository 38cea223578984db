//! Fuzzes the OBJ loader (`scene::formats::obj::parse_bytes`): any bytes must
//! give a mesh or an error, never a panic, hang or OOM.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let _ = raycheck::scene::formats::obj::parse_bytes(Path::new("input.obj"), data);
});
