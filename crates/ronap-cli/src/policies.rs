//! Policies by name, as the command line gives them.

use anyhow::{bail, Context, Result};
use ronap_core::policy::mlp::{DecisionRule, MlpFactory};
use ronap_core::policy::{Builtin, PolicyFactory};
use ronap_core::ValidConfig;
use std::path::Path;

/// The policy `name` names: a built-in, `mlp:FILE` or `py:FILE:FUNCTION`.
pub fn policy_factory(name: &str, config: &ValidConfig) -> Result<Box<dyn PolicyFactory>> {
    if let Some(spec) = name.strip_prefix("mlp:") {
        let size = config.laser.beams as usize + 1;
        let (path, rule) = match spec.rsplit_once('@') {
            Some((path, rule)) => {
                let rule = DecisionRule::parse(rule).with_context(|| {
                    format!("--policy {name:?}: {rule:?} is not a decision rule (argmax or sample:TEMPERATURE)")
                })?;
                (path, Some(rule))
            }
            None => (spec, None),
        };
        let factory = MlpFactory::load(Path::new(path), size)?;
        return Ok(Box::new(match rule {
            Some(r) => factory.with_rule(r),
            None => factory,
        }));
    }
    if let Some(spec) = name.strip_prefix("py:") {
        return Ok(Box::new(
            crate::py_policy::PyPolicyFactory::new(spec).map_err(anyhow::Error::msg)?,
        ));
    }
    match Builtin::from_name(name) {
        Some(b) => Ok(Box::new(b)),
        None => {
            let known: Vec<&str> = Builtin::ALL.iter().map(|(_, n, _)| *n).collect();
            bail!(
                "--policy {name:?}: unknown policy (expected one of: {}, mlp:FILE, py:FILE:FUNCTION)",
                known.join(", ")
            )
        }
    }
}
