//! The exception tree: everything ronap raises is a `ronap.RonapError`, mapped here from the
//! core's errors. The classes live in the public module `ronap` (their `__module__`), so their
//! instances pickle and unpickle by name.

use pyo3::prelude::*;

pyo3::create_exception!(
    ronap,
    RonapError,
    pyo3::exceptions::PyException,
    "Base of every error ronap raises."
);
pyo3::create_exception!(
    ronap,
    ConfigError,
    RonapError,
    "A configuration value is out of range or unknown, or a scenario file cannot be read; the message \
     names the field and value (and the file and line for a value a scenario file sets). Also a \
     `ValueError`."
);
pyo3::create_exception!(
    ronap,
    SceneError,
    RonapError,
    "A scene or episode cannot be built: unreadable map, no room for start and goal."
);
pyo3::create_exception!(
    ronap,
    PolicyError,
    RonapError,
    "A policy failed: it raised, or returned an invalid action; the message names seed and step."
);
pyo3::create_exception!(
    ronap,
    ActionError,
    RonapError,
    "An action passed to step() is not one the environment takes. Also a `ValueError`."
);
pyo3::create_exception!(
    ronap,
    OutputError,
    RonapError,
    "An output file could not be written."
);

/// Adds the exception classes to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("RonapError", py.get_type::<RonapError>())?;
    m.add("ConfigError", py.get_type::<ConfigError>())?;
    m.add("SceneError", py.get_type::<SceneError>())?;
    m.add("PolicyError", py.get_type::<PolicyError>())?;
    m.add("ActionError", py.get_type::<ActionError>())?;
    m.add("OutputError", py.get_type::<OutputError>())?;
    // A bad value is also a `ValueError`, so `except ValueError` catches it as it catches
    // numpy's and Gymnasium's (a class of pyo3's takes one base; this gives it the second).
    let value_error = py.get_type::<pyo3::exceptions::PyValueError>();
    for class in [py.get_type::<ConfigError>(), py.get_type::<ActionError>()] {
        class.setattr("__bases__", (py.get_type::<RonapError>(), &value_error))?;
    }
    Ok(())
}

/// A scene or episode error as a `SceneError`.
pub fn scene(e: impl std::fmt::Display) -> PyErr {
    SceneError::new_err(e.to_string())
}

/// A run's error: an episode that cannot start is a `SceneError`, the rest `PolicyError`.
pub fn run(e: &ronap_core::run::RunError) -> PyErr {
    match e {
        ronap_core::run::RunError::Episode { .. } => scene(e),
        _ => PolicyError::new_err(e.to_string()),
    }
}

/// An output error as an `OutputError`.
pub fn output(e: impl std::fmt::Display) -> PyErr {
    OutputError::new_err(e.to_string())
}

/// An output directory that cannot be written as an `OutputError`, with the ways on when it was
/// refused for what it holds.
pub fn out_dir(e: ronap_core::io::OutputError) -> PyErr {
    use ronap_core::io::OutputError as E;
    let hint = match &e {
        E::StoppedShort { dir, .. } => format!(
            ": `ronap run --resume {}` finishes it, force=True replaces it, or choose another out",
            dir.display()
        ),
        E::Finished { .. } => ": force=True replaces it, or choose another out".to_string(),
        E::NotARun { .. } => {
            ": force=True writes there anyway (keeping those files), or choose another out"
                .to_string()
        }
        _ => String::new(),
    };
    OutputError::new_err(format!("{e}{hint}"))
}
