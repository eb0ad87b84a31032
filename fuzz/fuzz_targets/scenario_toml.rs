//! A scenario file (`--scenario`): parsed, checked, and, when small enough, its scene built and
//! short episodes run in it (a team episode for `[[robots]]`).
#![no_main]

use libfuzzer_sys::fuzz_target;
use ronap_core::config::ConfigFile;
use ronap_core::sim::SceneSpec;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let file = ConfigFile::from_text(Path::new("/fuzz/scenario.toml"), text.to_string());
    let Ok(sim) = file.parse() else {
        return;
    };
    if !ronap_fuzz::small(&sim) {
        return;
    }
    let Ok(config) = ronap_fuzz::shortened(sim).validate() else {
        return;
    };
    let spec = SceneSpec::resolve(&config.scene, None, None);
    if let Ok((scenes, _)) = spec.load(&config) {
        ronap_fuzz::drive(config, scenes);
    }
});
