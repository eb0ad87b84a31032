//! Map files: images (PNG, PGM) and ROS `map_server` YAML descriptions of them.
//!
//! A ROS map YAML names an image and how to read it: `resolution` (metres per pixel), `origin`
//! (`[x, y, yaw]` of the lower-left pixel), `occupied_thresh`, `free_thresh` and `negate`. A pixel's
//! occupancy is `p = (255 - v) / 255` (or `v / 255` with `negate: 1`); `p > occupied_thresh` is an
//! obstacle, `p < free_thresh` free, and anything between (unknown) is treated as an obstacle.
//! ronap works in px, one image pixel to `map.resolution_px`; the metric resolution and origin are
//! kept so positions can be converted back.

use crate::config::MapConfig;
use crate::scene::{Scene, SceneError};
use std::path::{Path, PathBuf};

/// A map file that could not be read.
#[derive(Debug, thiserror::Error)]
pub enum MapError {
    /// The YAML file could not be read.
    #[error("cannot read map file {}: {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The error.
        source: std::io::Error,
    },
    /// A line of the YAML file is malformed or a value is out of range.
    #[error("map file {}{}: {message}", path.display(), at_line(*line))]
    Yaml {
        /// The file.
        path: PathBuf,
        /// 1-based line number (0 when a key is missing).
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// The image could not be used.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// The image a YAML file names could not be used.
    #[error("map file {}: {source}", yaml.display())]
    YamlImage {
        /// The YAML file.
        yaml: PathBuf,
        /// What is wrong with its image.
        source: SceneError,
    },
}

/// A ROS `map_server` map description.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RosMap {
    /// The image file, resolved against the YAML file's directory.
    pub image: PathBuf,
    /// Metres per pixel.
    pub resolution_m: f64,
    /// `[x, y, yaw]` of the lower-left pixel, metres and radians.
    pub origin: [f64; 3],
    /// Occupancy above which a pixel is an obstacle.
    pub occupied_thresh: f64,
    /// Occupancy below which a pixel is free.
    pub free_thresh: f64,
    /// Whether white means occupied.
    pub negate: bool,
}

/// `, line N`, or nothing for line 0 (a missing key).
fn at_line(line: usize) -> String {
    if line == 0 {
        String::new()
    } else {
        format!(", line {line}")
    }
}

impl RosMap {
    /// Reads a map YAML file (the flat `key: value` subset `map_server` writes).
    pub fn load(path: &Path) -> Result<Self, MapError> {
        let text =
            crate::bounded::read_to_string(path, crate::bounded::TEXT_LIMIT).map_err(|source| {
                MapError::Read {
                    path: path.to_path_buf(),
                    source,
                }
            })?;
        Self::parse(&text, path)
    }

    /// Parses map YAML `text`; `path` names the file in errors and resolves the image.
    pub fn parse(text: &str, path: &Path) -> Result<Self, MapError> {
        let err = |line: usize, message: String| MapError::Yaml {
            path: path.to_path_buf(),
            line,
            message,
        };
        let (mut image, mut resolution, mut origin) = (None, None, None);
        let (mut occupied, mut free, mut negate) = (0.65, 0.196, false);
        for (k, raw) in text.lines().enumerate() {
            let line = k + 1;
            let content = raw.split('#').next().unwrap_or("").trim();
            if content.is_empty() {
                continue;
            }
            let Some((key, value)) = content.split_once(':') else {
                return Err(err(
                    line,
                    format!("expected `key: value`, found {content:?}"),
                ));
            };
            let value = value.trim().trim_matches(|c| c == '"' || c == '\'');
            let number = |v: &str| -> Result<f64, MapError> {
                v.trim()
                    .parse::<f64>()
                    .ok()
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| err(line, format!("{} = {v:?} is not a number", key.trim())))
            };
            match key.trim() {
                "image" => image = Some(value.to_string()),
                "resolution" => {
                    let r = number(value)?;
                    if r <= 0.0 {
                        return Err(err(line, format!("resolution = {r}: must be positive")));
                    }
                    resolution = Some(r);
                }
                "origin" => {
                    let inner = value.trim_start_matches('[').trim_end_matches(']');
                    let parts: Vec<f64> = inner.split(',').map(number).collect::<Result<_, _>>()?;
                    let [x, y, yaw] = parts[..] else {
                        return Err(err(line, format!("origin = {value}: expected [x, y, yaw]")));
                    };
                    origin = Some([x, y, yaw]);
                }
                "occupied_thresh" => occupied = number(value)?,
                "free_thresh" => free = number(value)?,
                "negate" => {
                    negate = match value {
                        "0" | "false" => false,
                        "1" | "true" => true,
                        other => {
                            return Err(err(line, format!("negate = {other:?}: expected 0 or 1")))
                        }
                    }
                }
                // Other map_server keys (mode, ...) do not change how ronap reads the map.
                _ => {}
            }
        }
        let image = image.ok_or_else(|| err(0, "missing key `image`".into()))?;
        let resolution_m = resolution.ok_or_else(|| err(0, "missing key `resolution`".into()))?;
        if !(0.0..=1.0).contains(&free) || !(0.0..=1.0).contains(&occupied) || free > occupied {
            return Err(err(
                0,
                format!("free_thresh = {free}, occupied_thresh = {occupied}: need 0 <= free <= occupied <= 1"),
            ));
        }
        let dir = path.parent().unwrap_or(Path::new("."));
        Ok(Self {
            image: dir.join(image),
            resolution_m,
            origin: origin.unwrap_or([0.0, 0.0, 0.0]),
            occupied_thresh: occupied,
            free_thresh: free,
            negate,
        })
    }

    /// The scene of this map: obstacles where the occupancy is not below `free_thresh`.
    pub fn scene(&self, config: &MapConfig, reach_px: f64) -> Result<Scene, MapError> {
        self.scene_of(&crate::scene::read_image(&self.image)?, config, reach_px)
    }

    /// The scene of this map with `image` as its image (read from [`RosMap::image`]).
    pub fn scene_of(
        &self,
        image: &image::DynamicImage,
        config: &MapConfig,
        reach_px: f64,
    ) -> Result<Scene, MapError> {
        let image = image.to_luma8();
        let occupied: Vec<bool> = image
            .pixels()
            .map(|p| {
                let v = p.0[0] as f64;
                let occupancy = if self.negate {
                    v / 255.0
                } else {
                    (255.0 - v) / 255.0
                };
                occupancy >= self.free_thresh
            })
            .collect();
        crate::scene::check_runs(&occupied, image.width(), &self.image)?;
        Ok(Scene::from_occupancy(
            image.width(),
            image.height(),
            &occupied,
            config.resolution_px,
            reach_px,
        ))
    }
}

/// A map file given by the user.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum MapSource {
    /// An image, thresholded at `map.threshold`.
    Image(PathBuf),
    /// A ROS map YAML file.
    Ros(RosMap),
}

/// Reads a map file: `.yaml`/`.yml` as a ROS map, anything else as an image.
pub fn load(
    path: &Path,
    config: &MapConfig,
    reach_px: f64,
) -> Result<(Scene, MapSource), MapError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    if matches!(ext.as_deref(), Some("yaml") | Some("yml")) {
        let ros = RosMap::load(path)?;
        let scene = ros.scene(config, reach_px).map_err(|e| match e {
            MapError::Scene(source) => MapError::YamlImage {
                yaml: path.to_path_buf(),
                source,
            },
            other => other,
        })?;
        Ok((scene, MapSource::Ros(ros)))
    } else {
        let scene = Scene::load_image(path, config, reach_px)?;
        Ok((scene, MapSource::Image(path.to_path_buf())))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_map_server_yaml() {
        let text = "image: maze.pgm\nresolution: 0.05\norigin: [-10.0, -2.5, 0.0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196 # comment\nmode: trinary\n";
        let m = RosMap::parse(text, Path::new("/maps/m.yaml")).unwrap();
        assert_eq!(m.image, PathBuf::from("/maps/maze.pgm"));
        assert_eq!(m.resolution_m, 0.05);
        assert_eq!(m.origin, [-10.0, -2.5, 0.0]);
        assert!(!m.negate);
    }

    #[test]
    fn yaml_errors_name_line_and_value() {
        let e = RosMap::parse("image: a.png\nresolution: fast\n", Path::new("m.yaml")).unwrap_err();
        assert_eq!(
            e.to_string(),
            "map file m.yaml, line 2: resolution = \"fast\" is not a number"
        );
        let e = RosMap::parse("resolution: 0.1\n", Path::new("m.yaml")).unwrap_err();
        assert!(e.to_string().contains("missing key `image`"), "{e}");
        let e = RosMap::parse(
            "image: a.png\nresolution: 0.1\nnegate: maybe\n",
            Path::new("m.yaml"),
        )
        .unwrap_err();
        assert!(e.to_string().contains("line 3"), "{e}");
    }
}
