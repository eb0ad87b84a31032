//! The keyword options of a native function (`**options`), taken one by one with their
//! defaults: the Python wrappers name every option, and a function of many options keeps a short
//! Rust signature. An option the function does not know is an error naming it.

use crate::errors::ConfigError;
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use ronap_core::run::{Autoreset, BatchOf, BatchOptions, Lane, SeedOrder};
use ronap_core::sim::Worlds;
use ronap_core::ValidConfig;

/// The options left to take.
pub struct Options<'py> {
    function: &'static str,
    dict: Option<Bound<'py, PyDict>>,
}

impl<'py> Options<'py> {
    /// The options `dict` given to `function`.
    pub fn new(function: &'static str, dict: Option<&Bound<'py, PyDict>>) -> Self {
        Self {
            function,
            dict: dict.cloned(),
        }
    }

    /// Option `key`, or `default` when it was not given.
    pub fn take<T: FromPyObject<'py>>(&self, key: &str, default: T) -> PyResult<T> {
        let Some(dict) = &self.dict else {
            return Ok(default);
        };
        match dict.get_item(key)? {
            None => Ok(default),
            Some(value) => {
                dict.del_item(key)?;
                value
                    .extract()
                    .map_err(|e| PyTypeError::new_err(format!("{}(): {key}: {e}", self.function)))
            }
        }
    }

    /// Where and on how many threads episodes run, the options every run takes: `maze_seed`,
    /// `map_path` and `threads` (0: all cores), in that order.
    pub fn scene_and_threads(&self) -> PyResult<(Option<u64>, Option<String>, usize)> {
        Ok((
            self.take("maze_seed", None)?,
            self.take("map_path", None)?,
            self.take("threads", 0)?,
        ))
    }

    /// The batch of `num_envs` environments (at least 1) under `config` a vector class runs on,
    /// from the options every such class takes: `maze_seed`, `map_path`, `threads` (0: all cores)
    /// and `autoreset` ("next_step" unless given; "same_step", "disabled"). Takes the last
    /// options, so the caller takes its own first; seeds are strided.
    pub fn batch<E: Lane>(self, num_envs: usize, config: &ValidConfig) -> PyResult<BatchOf<E>> {
        let (maze_seed, map_path, threads) = self.scene_and_threads()?;
        let mode: String = self.take("autoreset", "next_step".to_string())?;
        self.finish()?;
        let autoreset = match mode.as_str() {
            "next_step" => Autoreset::NextStep,
            "same_step" => Autoreset::SameStep,
            "disabled" => Autoreset::Disabled,
            other => {
                return Err(ConfigError::new_err(format!(
                "autoreset_mode {other:?}: expected \"next_step\", \"same_step\" or \"disabled\""
            )))
            }
        };
        if num_envs == 0 {
            return Err(ConfigError::new_err("num_envs = 0: must be at least 1"));
        }
        let (_, scenes, _) = crate::conv::scenes(config, maze_seed, map_path.as_deref())?;
        let options = BatchOptions {
            envs: num_envs,
            threads,
            autoreset,
            seed_order: SeedOrder::Strided,
        };
        BatchOf::new(Worlds::new(config.clone(), scenes), options)
            .map_err(|e| crate::errors::RonapError::new_err(e.to_string()))
    }

    /// Fails naming any option not taken.
    pub fn finish(self) -> PyResult<()> {
        match self.dict.as_ref().and_then(|d| d.keys().iter().next()) {
            Some(key) => Err(PyTypeError::new_err(format!(
                "{}() got an unexpected keyword argument {key}",
                self.function
            ))),
            None => Ok(()),
        }
    }
}
