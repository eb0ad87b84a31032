//! A map image (PNG, PGM or any format the decoder knows), as `--map FILE` reads it, then short
//! episodes in its scene.
#![no_main]

use libfuzzer_sys::fuzz_target;
use ronap_core::{Scene, Scenes, SimConfig};
use std::path::Path;
use std::sync::Arc;

fuzz_target!(|data: &[u8]| {
    let path = Path::new("fuzz.png");
    let Ok(image) = ronap_core::scene::decode_image_bytes(data, path) else {
        return;
    };
    let config = ronap_fuzz::shortened(SimConfig::default())
        .validate()
        .expect("the default configuration is valid");
    if let Ok(scene) = Scene::from_user_image(&image, &config.map, config.reach_px(), path) {
        ronap_fuzz::drive(config, Scenes::Fixed(Arc::new(scene)));
    }
});
