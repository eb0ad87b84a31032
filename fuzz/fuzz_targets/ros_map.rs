//! A ROS `map_server` YAML file and its image, as `--map FILE.yaml` reads them: the YAML text up
//! to the first NUL byte, the image after it. Then short episodes in the map's scene.
#![no_main]

use libfuzzer_sys::fuzz_target;
use ronap_core::scene::RosMap;
use ronap_core::{Scenes, SimConfig};
use std::path::Path;
use std::sync::Arc;

fuzz_target!(|data: &[u8]| {
    let (yaml, image) = match data.iter().position(|&b| b == 0) {
        Some(at) => (&data[..at], &data[at + 1..]),
        None => (data, &[][..]),
    };
    let Ok(yaml) = std::str::from_utf8(yaml) else {
        return;
    };
    let Ok(map) = RosMap::parse(yaml, Path::new("/fuzz/map.yaml")) else {
        return;
    };
    let Ok(image) = ronap_core::scene::decode_image_bytes(image, &map.image) else {
        return;
    };
    let config = ronap_fuzz::shortened(SimConfig::default())
        .validate()
        .expect("the default configuration is valid");
    if let Ok(scene) = map.scene_of(&image, &config.map, config.reach_px()) {
        ronap_fuzz::drive(config, Scenes::Fixed(Arc::new(scene)));
    }
});
