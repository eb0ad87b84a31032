//! A step log (`ronap replay FILE`): parsed, and a log that parses replayed into a small GIF in
//! the default scene, as `ronap replay` does with the run's summary.json.
#![no_main]

use libfuzzer_sys::fuzz_target;
use ronap_core::eval::Evaluator;
use ronap_core::render::{animate, GifOptions};
use ronap_core::{Scenes, SimConfig};
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(steps) = ronap_core::io::parse_steps(data, Path::new("/fuzz/steps.csv")) else {
        return;
    };
    let Some(seed) = steps.first().map(|s| s.seed) else {
        return;
    };
    let config = SimConfig::default().validate().expect("default is valid");
    let evaluator = Evaluator::new(config, Scenes::MazePerSeed);
    let Ok(episode) = evaluator.worlds().episode(seed) else {
        return;
    };
    let steps = &steps[..steps.len().min(40)];
    let actions: Vec<_> = steps.iter().map(|s| s.action).collect();
    let poses: Vec<_> = steps.iter().map(|s| s.pose).collect();
    let options = GifOptions {
        size_px: 64,
        ..GifOptions::default()
    };
    let _ = animate(episode, &actions, Some(&poses), &options);
});
