//! Inputs with no end or out of all proportion: a device given as a file, a map image that claims
//! a huge size or is all noise, a YAML map missing a key. Each is one line naming the file and
//! the bound, exit 2, quickly and in bounded memory (found while writing the fuzz targets).

use crate::util::{assert_rejected, assert_rejected_leaving_nothing};
use std::path::Path;

#[cfg(unix)]
#[test]
fn an_endless_device_as_a_file_is_refused_not_read_forever() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o");
    let out_s = out.to_str().unwrap();
    assert_rejected_leaving_nothing(
        &[
            "run",
            "--policy",
            "apf",
            "--scenario",
            "/dev/zero",
            "--out",
            out_s,
        ],
        &["/dev/zero", "larger than 64 MiB"],
        &out,
    );
    assert_rejected_leaving_nothing(
        &[
            "replay",
            "/dev/zero",
            "--summary",
            "/dev/zero",
            "--out",
            &format!("{out_s}.gif"),
        ],
        &["/dev/zero", "a line longer than 1 MiB"],
        &dir.path().join("o.gif"),
    );
    let model = dir.path().join("m.safetensors");
    assert_rejected_leaving_nothing(
        &[
            "train",
            "bc",
            "--data",
            "/dev/zero",
            "--out",
            model.to_str().unwrap(),
        ],
        &["/dev/zero", "a line longer than 1 MiB"],
        &model,
    );
}

/// `ronap run --map MAP` into a fresh directory: refused naming each of `names`, nothing
/// written; the error line.
fn map_refused(map: &Path, names: &[&str]) -> String {
    let out = map.with_file_name("o");
    let err = assert_rejected(
        &[
            "run",
            "--policy",
            "apf",
            "--map",
            map.to_str().unwrap(),
            "--seeds",
            "1",
            "--out",
            out.to_str().unwrap(),
        ],
        names,
    );
    assert!(!out.exists(), "left {}", out.display());
    err
}

#[test]
fn a_map_image_claiming_a_huge_size_is_refused_before_decoding() {
    let dir = tempfile::tempdir().unwrap();
    let map = dir.path().join("huge.pgm");
    // A header for 100,000 x 100,000 pixels and no pixels: 40 bytes.
    std::fs::write(&map, b"P5\n100000 100000\n255\n").unwrap();
    map_refused(
        &map,
        &["huge.pgm", "100000 x 100000", "over the 64 megapixels"],
    );
}

#[test]
fn a_map_image_of_noise_is_refused_naming_its_runs() {
    let dir = tempfile::tempdir().unwrap();
    let map = dir.path().join("noise.pgm");
    // A checkerboard of 2100 x 1000: 1,050,000 separate obstacle pixels.
    let (w, h) = (2100usize, 1000usize);
    let mut bytes = format!("P5\n{w} {h}\n255\n").into_bytes();
    bytes.extend((0..w * h).map(|i| if (i % w + i / w) % 2 == 0 { 0u8 } else { 255 }));
    std::fs::write(&map, bytes).unwrap();
    map_refused(
        &map,
        &[
            "noise.pgm",
            "1050000 runs of obstacle pixels",
            "over the 1048576",
        ],
    );
}

#[test]
fn a_yaml_map_missing_a_key_names_the_key_and_no_line_zero() {
    let dir = tempfile::tempdir().unwrap();
    let map = dir.path().join("map.yaml");
    std::fs::write(&map, "image: map.pgm\norigin: [0, 0, 0]\n").unwrap();
    let err = map_refused(&map, &["map.yaml", "missing key `resolution`"]);
    assert!(!err.contains("line 0"), "{err}");
}
