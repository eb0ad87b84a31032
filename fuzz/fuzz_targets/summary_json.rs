//! A run's `summary.json` (`ronap replay --summary FILE`): parsed, its configuration and scenes
//! rebuilt, and, when small enough, short episodes run in them.
#![no_main]

use libfuzzer_sys::fuzz_target;
use ronap_core::io::RunManifest;
use ronap_core::sim::SceneSpec;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let path = Path::new("/fuzz/summary.json");
    let Ok(manifest) = RunManifest::parse(text, path) else {
        return;
    };
    // A map scene would read the file it names; the map targets cover maps.
    if matches!(manifest.scenes, SceneSpec::Map { .. }) || !ronap_fuzz::small(&manifest.config) {
        return;
    }
    if let Ok((config, scenes)) = manifest.setting(path) {
        let config = ronap_fuzz::shortened(config.as_sim_config().clone())
            .validate()
            .expect("shortening a valid configuration keeps it valid");
        ronap_fuzz::drive(config, scenes);
    }
});
