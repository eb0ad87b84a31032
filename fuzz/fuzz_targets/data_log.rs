//! A data log (`ronap train bc --data FILE`), in ronap's format or the original RoNAP's.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let _ = ronap_core::io::parse_data_log(text, Path::new("/fuzz/data.csv"), 50.0);
});
