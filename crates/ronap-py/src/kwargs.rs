//! The keyword options of a native function (`**options`), taken one by one with their
//! defaults: the Python wrappers name every option, and a function of many options keeps a short
//! Rust signature. An option the function does not know is an error naming it.

use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use ronap_core::run::Autoreset;

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

    /// `autoreset` ("next_step" unless given; "same_step", "disabled") as the batch's mode.
    pub fn autoreset(&self) -> PyResult<Autoreset> {
        let mode: String = self.take("autoreset", "next_step".to_string())?;
        match mode.as_str() {
            "next_step" => Ok(Autoreset::NextStep),
            "same_step" => Ok(Autoreset::SameStep),
            "disabled" => Ok(Autoreset::Disabled),
            other => Err(crate::errors::ConfigError::new_err(format!(
                "autoreset_mode {other:?}: expected \"next_step\", \"same_step\" or \"disabled\""
            ))),
        }
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
