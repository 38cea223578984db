//! Fuzzes the bundle manifest reader (`exchange::bundle::Manifest::parse`):
//! any text must give a manifest naming files in the bundle's folder only,
//! or an error, never a panic, hang or OOM.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|text: &str| {
    let _ = raycheck::exchange::bundle::Manifest::parse(Path::new("bundle.json"), text);
});
