//! Fuzzes the hits file reader (`exchange::HitsFile::parse`, what `read`
//! runs on a file's bytes; the files a buggy tracer writes): any bytes
//! must give answers or an error, never a panic, hang or OOM.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let _ = raycheck::exchange::HitsFile::parse(Path::new("input.hits"), data);
});
