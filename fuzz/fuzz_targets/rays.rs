//! Fuzzes the rays file reader (`exchange::RaysFile::parse`, what `read`
//! runs on a file's bytes): any bytes must give rays or an error, never a
//! panic, hang or OOM.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let _ = raycheck::exchange::RaysFile::parse(Path::new("input.rays"), data);
});
