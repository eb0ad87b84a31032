//! Policies by name, as the command line gives them.

use anyhow::Result;
use ronap_core::policy::{
    coordinated_drives, Builtin, Coordinated, PerRobot, PolicyError, PolicyFactory,
    PolicyNameError, TeamPolicy, TeamPolicyFactory, COORDINATED_NAME,
};
use ronap_core::ValidConfig;

/// The policy `name` names: a built-in, `mlp:FILE[@RULE]` or `py:FILE:FUNCTION`.
pub fn policy_factory(name: &str, config: &ValidConfig) -> Result<Box<dyn PolicyFactory>> {
    named_policy("--policy", name, config)
}

/// [`policy_factory`] for the policy that `label` gives (a flag, `--driver`, or a file's field,
/// `robots[0].policy`; errors name it).
pub fn named_policy(
    label: &str,
    name: &str,
    config: &ValidConfig,
) -> Result<Box<dyn PolicyFactory>> {
    let flag = label;
    if name == COORDINATED_NAME {
        if flag.starts_with("robots[") {
            anyhow::bail!(
                "{flag} = \"coordinated\": the team planner drives the whole team, so it is \
                 chosen for all of it (--policy coordinated), not in one [[robots]] entry"
            );
        }
        anyhow::bail!(
            "{flag} coordinated: a team planner, for scenarios with [[robots]]; one robot alone \
             has no one to coordinate with (orca is what it would run)"
        );
    }
    if let Some(spec) = name.strip_prefix("py:") {
        return Ok(Box::new(
            crate::py_policy::PyPolicyFactory::new(spec).map_err(anyhow::Error::msg)?,
        ));
    }
    ronap_core::policy::factory(name, config.observation_size()).map_err(|e| match e {
        PolicyNameError::Unknown { .. } => {
            let known: Vec<&str> = Builtin::ALL.iter().map(|(_, n, _)| *n).collect();
            // The team planner is chosen on the command line only.
            let team = if flag == "--policy" {
                "; for a team, also coordinated"
            } else {
                ""
            };
            anyhow::anyhow!(
                "{flag} {name:?}: unknown policy (expected one of: {}, mlp:FILE[@RULE], \
                 py:FILE:FUNCTION{team})",
                known.join(", ")
            )
        }
        PolicyNameError::Rule { .. } => {
            let text = e.to_string();
            anyhow::anyhow!("{flag} {}", text.strip_prefix("policy ").unwrap_or(&text))
        }
        PolicyNameError::Network(e) => anyhow::Error::from(e).context(format!("{flag} {name:?}")),
    })
}

/// A team's policies: each robot's policy name (its `[[robots]]` entry's `policy`, else the
/// command line's), and one factory per entry that robots of the entry share.
pub struct TeamPolicies {
    /// Robot `k`'s policy name.
    pub names: Vec<String>,
    factories: Vec<Box<dyn PolicyFactory>>,
    /// Robot `k`'s factory, as an index into `factories`.
    of_robot: Vec<usize>,
    /// With `--batch`: the Python function the robots without a policy of their own share, one
    /// call a step for all of them, and its processes; `batched[k]` for those robots.
    batch: Option<(
        crate::py_policy::PyPolicyFactory,
        crate::py_policy::ProcessPool,
    )>,
    batched: Vec<bool>,
    /// Every robot driven by the `coordinated` team planner.
    coordinated: bool,
}

impl TeamPolicies {
    /// The policies of `config`'s `[[robots]]`, `default` where an entry names none.
    pub fn new(config: &ValidConfig, default: &str) -> Result<Self> {
        let mut team = Self {
            names: Vec::new(),
            factories: Vec::new(),
            of_robot: Vec::new(),
            batch: None,
            batched: Vec::new(),
            coordinated: false,
        };
        if coordinated_drives(config, default).map_err(anyhow::Error::msg)? {
            team.names = vec![COORDINATED_NAME.to_string(); config.team_size()];
            team.coordinated = true;
            return Ok(team);
        }
        for entry in &config.robots {
            let k = team.names.len();
            let name = entry.policy.clone().unwrap_or_else(|| default.to_string());
            let factory = policy_factory(&name, &config.team_robot(k))
                .map_err(|e| e.context(format!("[[robots]] entry with robot {k}")))?;
            team.factories.push(factory);
            for _ in 0..entry.count {
                team.names.push(name.clone());
                team.of_robot.push(team.factories.len() - 1);
                team.batched.push(entry.policy.is_none());
            }
        }
        Ok(team)
    }

    /// The robots driven by the default policy `default`, a `py:FILE:FUNCTION` one, decided
    /// together: one call of the function a step for every such robot of a team episode
    /// (`ronap run --batch` on a team scenario).
    pub fn batched(mut self, default: &str) -> Result<Self> {
        if self.coordinated {
            anyhow::bail!("--batch: batches are for py:FILE:FUNCTION policies; coordinated runs in Rust already");
        }
        let Some(spec) = default.strip_prefix("py:") else {
            anyhow::bail!("--batch: batches are for py:FILE:FUNCTION policies; {default} runs in Rust already");
        };
        if !self.batched.contains(&true) {
            anyhow::bail!(
                "--batch: every [[robots]] entry names a policy of its own; none runs {default}"
            );
        }
        let factory = crate::py_policy::PyPolicyFactory::new(spec).map_err(anyhow::Error::msg)?;
        self.batch = Some((factory, crate::py_policy::ProcessPool::default()));
        Ok(self)
    }

    /// A new team policy, each robot's policy fresh from its factory; an error names the
    /// policy that could not start.
    pub fn start(&self) -> Result<Box<dyn TeamPolicy>> {
        if self.coordinated {
            return Ok(Box::<Coordinated>::default());
        }
        let policies = self
            .of_robot
            .iter()
            .zip(&self.names)
            .map(|(&i, name)| {
                self.factories[i]
                    .make()
                    .map_err(|e| anyhow::anyhow!("cannot start policy {name}: {e}"))
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Box::new(PerRobot::new(policies)))
    }
}

/// Each robot driven by a policy of its own ([`PerRobot`]).
impl TeamPolicyFactory for TeamPolicies {
    fn make(&self) -> Result<Box<dyn TeamPolicy>, PolicyError> {
        if self.coordinated {
            return Ok(Box::<Coordinated>::default());
        }
        if let Some((py, pool)) = &self.batch {
            let others = self
                .of_robot
                .iter()
                .zip(&self.batched)
                .map(|(&i, &b)| (!b).then(|| self.factories[i].make()).transpose())
                .collect::<Result<Vec<_>, _>>()?;
            return Ok(Box::new(py.batched_team(
                pool,
                self.batched.clone(),
                others,
            )?));
        }
        let policies = self
            .of_robot
            .iter()
            .map(|&i| self.factories[i].make())
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Box::new(PerRobot::new(policies)))
    }

    fn names(&self) -> Vec<String> {
        self.names.clone()
    }
}
