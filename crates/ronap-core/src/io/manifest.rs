//! A run's manifest: `summary.json`, one versioned schema whoever wrote the run (`ronap run` or
//! Python's `ronap.evaluate`), read back by `ronap replay` to rebuild the run's configuration
//! and scenes.

use crate::config::{SimConfig, ValidConfig};
use crate::eval::Summary;
use crate::scene::map::{MapError, MapSource};
use crate::sim::{SceneSpec, Scenes};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The schema version this ronap writes; a manifest of another version is refused by name.
pub const SCHEMA_VERSION: u32 = 1;

/// What a run was and what it gave: the contents of `summary.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunManifest {
    /// `SCHEMA_VERSION` of the writer.
    pub schema_version: u32,
    /// The ronap version that wrote the run.
    pub ronap_version: String,
    /// The simulation model the run's episodes were made under ([`crate::MODEL_VERSION`]);
    /// a run recorded before the manifest carried it was model 1. Another model makes other
    /// episodes of the same seeds, so `ronap replay` refuses it.
    #[serde(default = "first_model")]
    pub model_version: u32,
    /// The policy, as named to the front end (`apf`, `mlp:FILE`, a Python function's name...).
    pub policy: String,
    /// The first seed.
    pub seed_start: u64,
    /// Episodes asked for.
    pub seeds_requested: u64,
    /// Worker threads (0: all cores).
    pub threads: usize,
    /// Where episodes took place.
    pub scenes: SceneSpec,
    /// What the map file was read as, for runs on a map.
    pub map: Option<MapSource>,
    /// Whether the run was interrupted before every seed ran.
    pub interrupted: bool,
    /// The error that stopped the run, if one did.
    pub error: Option<String>,
    /// The figures (of every robot, for a team run).
    pub summary: Summary,
    /// The team figures, for a run of several robots.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub team: Option<crate::eval::TeamSummary>,
    /// The whole configuration.
    pub config: SimConfig,
}

/// The model version of a manifest that does not record one: written before the field was, under
/// model 1.
fn first_model() -> u32 {
    1
}

/// A manifest that cannot be read.
#[derive(Debug, thiserror::Error)]
pub enum ManifestError {
    /// The file cannot be read.
    #[error("cannot read the run's summary {}: {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The file is not a manifest of this schema.
    #[error("{} is not a ronap run summary: {message}", path.display())]
    Format {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// The recorded configuration is invalid.
    #[error("{}: invalid `config`: {source}", path.display())]
    Config {
        /// The file.
        path: PathBuf,
        /// Why.
        source: crate::config::ConfigError,
    },
    /// The run's map cannot be read.
    #[error("the run's map (from {}): {source}", path.display())]
    Map {
        /// The manifest.
        path: PathBuf,
        /// Why.
        source: MapError,
    },
}

/// Reads a JSON file of schema `version` into `T`, refusing another version by name.
fn read_versioned<T: serde::de::DeserializeOwned>(
    path: &Path,
    version: u32,
) -> Result<T, ManifestError> {
    let text =
        crate::bounded::read_to_string(path, crate::bounded::TEXT_LIMIT).map_err(|source| {
            ManifestError::Read {
                path: path.to_path_buf(),
                source,
            }
        })?;
    parse_versioned(&text, path, version)
}

/// Parses the JSON `text` of schema `version` into `T` ([`read_versioned`]; `path` names it).
fn parse_versioned<T: serde::de::DeserializeOwned>(
    text: &str,
    path: &Path,
    version: u32,
) -> Result<T, ManifestError> {
    let format = |message: String| ManifestError::Format {
        path: path.to_path_buf(),
        message,
    };
    let value: serde_json::Value = serde_json::from_str(text).map_err(|e| format(e.to_string()))?;
    match value.get("schema_version").and_then(|v| v.as_u64()) {
        Some(v) if v == u64::from(version) => {}
        Some(v) => {
            return Err(format(format!(
                "schema_version {v}; this ronap reads version {version}"
            )))
        }
        None => return Err(format("no `schema_version`".into())),
    }
    serde_json::from_value(value).map_err(|e| format(e.to_string()))
}

impl RunManifest {
    /// Reads `path`.
    pub fn read(path: &Path) -> Result<Self, ManifestError> {
        read_versioned(path, SCHEMA_VERSION)
    }

    /// Parses the text of a manifest; `path` names it in errors.
    pub fn parse(text: &str, path: &Path) -> Result<Self, ManifestError> {
        parse_versioned(text, path, SCHEMA_VERSION)
    }

    /// Writes the manifest to `path`, atomically.
    pub fn write(&self, path: &Path) -> Result<(), crate::io::atomic::OutputError> {
        crate::io::atomic::write_atomic(path, |out| {
            serde_json::to_writer_pretty(&mut *out, self)?;
            std::io::Write::write_all(out, b"\n")
        })
    }

    /// The run's configuration and scenes, as the run had them (`path` names the manifest in
    /// errors).
    pub fn setting(&self, path: &Path) -> Result<(ValidConfig, Scenes), ManifestError> {
        setting(&self.config, &self.scenes, path)
    }
}

fn setting(
    config: &SimConfig,
    scenes: &SceneSpec,
    path: &Path,
) -> Result<(ValidConfig, Scenes), ManifestError> {
    let config = config
        .clone()
        .validate()
        .map_err(|source| ManifestError::Config {
            path: path.to_path_buf(),
            source,
        })?;
    let (scenes, _) = scenes.load(&config).map_err(|source| ManifestError::Map {
        path: path.to_path_buf(),
        source,
    })?;
    Ok((config, scenes))
}

/// The name of a run's plan inside its directory.
pub const PLAN_FILE: &str = "run.json";

/// The schema version of the plans this ronap writes; `--resume` refuses another.
pub const PLAN_SCHEMA_VERSION: u32 = 1;

/// What a run was asked to do, written to `run.json` before its first episode, so that a run
/// stopped short (killed, interrupted, out of disk) can be finished by a later process exactly
/// as it would have gone on.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunPlan {
    /// `PLAN_SCHEMA_VERSION` of the writer.
    pub schema_version: u32,
    /// The ronap version that wrote the run; another version may run episodes differently.
    pub ronap_version: String,
    /// The simulation model of the run's episodes ([`RunManifest::model_version`]).
    #[serde(default = "first_model")]
    pub model_version: u32,
    /// The policy, as named to the front end.
    pub policy: String,
    /// The first seed.
    pub seed_start: u64,
    /// Episodes asked for.
    pub seeds_requested: u64,
    /// The seeds, when they are not `seeds_requested` seeds from `seed_start`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seeds: Option<Vec<u64>>,
    /// Worker threads (0: all cores).
    pub threads: usize,
    /// Where episodes take place.
    pub scenes: SceneSpec,
    /// What the map file was read as, for runs on a map.
    pub map: Option<MapSource>,
    /// Which episodes get a trajectory picture (`3`, `failures`, `all`), if any.
    pub pictures: Option<String>,
    /// Whether step logs are written.
    pub steps: bool,
    /// Whether the front end writes animations.
    pub gifs: bool,
    /// The front end's own options (opaque to the core), so it can finish the run as begun.
    pub front_end: serde_json::Value,
    /// The whole configuration.
    pub config: SimConfig,
}

impl RunPlan {
    /// Reads `path`, refusing a plan of another schema, ronap or model version by name.
    pub fn read(path: &Path) -> Result<Self, ManifestError> {
        let plan: Self = read_versioned(path, PLAN_SCHEMA_VERSION)?;
        let ours = env!("CARGO_PKG_VERSION");
        if plan.ronap_version != ours {
            return Err(ManifestError::Format {
                path: path.to_path_buf(),
                message: format!(
                    "written by ronap {}; this is ronap {ours}, whose episodes may differ: \
                     finish the run with ronap {}",
                    plan.ronap_version, plan.ronap_version
                ),
            });
        }
        if plan.model_version != crate::MODEL_VERSION {
            return Err(ManifestError::Format {
                path: path.to_path_buf(),
                message: format!(
                    "begun under model version {}; this ronap runs model version {}, whose \
                     episodes differ: finish the run with the ronap that began it",
                    plan.model_version,
                    crate::MODEL_VERSION
                ),
            });
        }
        Ok(plan)
    }

    /// Writes the plan to `path`, atomically.
    pub fn write(&self, path: &Path) -> Result<(), crate::io::atomic::OutputError> {
        crate::io::atomic::write_atomic(path, |out| {
            serde_json::to_writer_pretty(&mut *out, self)?;
            std::io::Write::write_all(out, b"\n")
        })
    }

    /// The run's seeds.
    pub fn seeds(&self) -> crate::eval::Seeds {
        match &self.seeds {
            Some(list) => crate::eval::Seeds::List(list.clone()),
            None => crate::eval::Seeds::Range {
                start: self.seed_start,
                count: self.seeds_requested,
            },
        }
    }

    /// The run's configuration and scenes (`path` names the plan in errors).
    pub fn setting(&self, path: &Path) -> Result<(ValidConfig, Scenes), ManifestError> {
        setting(&self.config, &self.scenes, path)
    }
}
