//! Policies by name, as the command line gives them.

use anyhow::Result;
use ronap_core::policy::{Builtin, PolicyFactory, PolicyNameError};
use ronap_core::ValidConfig;

/// The policy `name` names: a built-in, `mlp:FILE[@RULE]` or `py:FILE:FUNCTION`.
pub fn policy_factory(name: &str, config: &ValidConfig) -> Result<Box<dyn PolicyFactory>> {
    if let Some(spec) = name.strip_prefix("py:") {
        return Ok(Box::new(
            crate::py_policy::PyPolicyFactory::new(spec).map_err(anyhow::Error::msg)?,
        ));
    }
    ronap_core::policy::factory(name, config.observation_size()).map_err(|e| match e {
        PolicyNameError::Unknown { .. } => {
            let known: Vec<&str> = Builtin::ALL.iter().map(|(_, n, _)| *n).collect();
            anyhow::anyhow!(
                "--policy {name:?}: unknown policy (expected one of: {}, mlp:FILE[@RULE], \
                 py:FILE:FUNCTION)",
                known.join(", ")
            )
        }
        PolicyNameError::Rule { .. } => anyhow::anyhow!("--{e}"),
        PolicyNameError::Network(e) => anyhow::Error::from(e).context(format!("--policy {name:?}")),
    })
}
