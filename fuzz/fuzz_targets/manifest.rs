//! Fuzzes the manifest parser (`scene::formats::manifest::parse_str`): any text must
//! give a parsed manifest or an error, never a panic, hang or OOM.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|text: &str| {
    let _ = raycheck::scene::formats::manifest::parse_str(Path::new("input.toml"), text);
});
