//! Policies by name, as users give them: a built-in (`apf`, `geodesic`, `geodesic-wait`,
//! `random`, `orca`, `social-force`, `dwa`) or `mlp:FILE[@RULE]`.

use crate::policy::mlp::{self, DecisionRule, MlpFactory};
use crate::policy::{
    apf, dwa, geodesic, orca, random, social_force, Policy, PolicyError, PolicyFactory,
};

/// The built-in policies.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Builtin {
    /// The paper's artificial potential field (Algorithm 3), local minima and all.
    Apf,
    /// Descent on the geodesic distance to the goal: a navigation function with no local minima.
    Geodesic,
    /// Shortest-path following that waits while the laser sees a moving obstacle close ahead.
    GeodesicWait,
    /// Uniformly random discrete actions: the floor.
    Random,
    /// Optimal Reciprocal Collision Avoidance along the geodesic path, among what moves.
    Orca,
    /// The social force model along the geodesic path, among what moves.
    SocialForce,
    /// The dynamic window approach along the geodesic path, among what moves.
    Dwa,
}

impl Builtin {
    /// Every built-in policy with its name and a one-line description.
    pub const ALL: [(Builtin, &'static str, &'static str); 7] = [
        (
            Builtin::Apf,
            "apf",
            "the paper's artificial potential field (Algorithm 3); trapped by local minima",
        ),
        (
            Builtin::Geodesic,
            "geodesic",
            "follows the shortest path (descent on geodesic distance: no local minima)",
        ),
        (
            Builtin::GeodesicWait,
            "geodesic-wait",
            "geodesic, but waits (turning on the spot) while the laser sees a moving obstacle close ahead",
        ),
        (
            Builtin::Random,
            "random",
            "uniformly random LEFT/AHEAD/RIGHT",
        ),
        (
            Builtin::Orca,
            "orca",
            "ORCA (optimal reciprocal collision avoidance) along the geodesic path: avoids the moving obstacles and robots it senses ([orca] settings)",
        ),
        (
            Builtin::SocialForce,
            "social-force",
            "the social force model (Helbing-Molnar) along the geodesic path: pushed away from what it senses and from walls ([social_force] settings)",
        ),
        (
            Builtin::Dwa,
            "dwa",
            "the dynamic window approach along the geodesic path: samples (v, w), rolls each out against the laser's points and what moves ([dwa] settings)",
        ),
    ];

    /// The policy named `name`.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL
            .iter()
            .find(|(_, n, _)| *n == name)
            .map(|(b, _, _)| *b)
    }

    /// The policy's name.
    pub fn name(self) -> &'static str {
        Self::ALL
            .iter()
            .find(|(b, _, _)| *b == self)
            .map_or("unknown", |(_, n, _)| n)
    }
}

impl PolicyFactory for Builtin {
    fn make(&self) -> Result<Box<dyn Policy>, PolicyError> {
        Ok(match self {
            Builtin::Apf => Box::new(apf::Apf::default()),
            Builtin::Geodesic => Box::new(geodesic::Geodesic::default()),
            Builtin::GeodesicWait => Box::new(geodesic::GeodesicWait::default()),
            Builtin::Random => Box::new(random::RandomPolicy::default()),
            Builtin::Orca => Box::new(orca::Orca::default()),
            Builtin::SocialForce => Box::new(social_force::SocialForce::default()),
            Builtin::Dwa => Box::new(dwa::Dwa::default()),
        })
    }

    fn name(&self) -> String {
        Builtin::name(*self).to_string()
    }
}

/// A policy name that names no policy, or a network file that cannot be used.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum PolicyNameError {
    /// Neither a built-in nor a known `kind:` prefix.
    #[error("policy {name:?}: unknown (expected one of: {}, mlp:FILE[@RULE])", Builtin::ALL.map(|b| b.1).join(", "))]
    Unknown {
        /// The name given.
        name: String,
    },
    /// The `@RULE` of `mlp:FILE@RULE` is not a decision rule.
    #[error("policy {name:?}: {rule:?} is not a decision rule (argmax or sample:TEMPERATURE)")]
    Rule {
        /// The name given.
        name: String,
        /// The rule.
        rule: String,
    },
    /// The weights file cannot be used.
    #[error(transparent)]
    Network(#[from] mlp::MlpError),
}

/// The policy `name` names: a built-in (`apf`, `geodesic`, `random`) or `mlp:FILE[@RULE]` (a
/// weights file, with an optional decision rule overriding the file's), for observations of
/// `observation_size` values.
pub fn factory(
    name: &str,
    observation_size: usize,
) -> Result<Box<dyn PolicyFactory>, PolicyNameError> {
    if let Some(spec) = name.strip_prefix("mlp:") {
        let (path, rule) = match spec.rsplit_once('@') {
            Some((path, rule)) => {
                let parsed = DecisionRule::parse(rule).ok_or_else(|| PolicyNameError::Rule {
                    name: name.into(),
                    rule: rule.into(),
                })?;
                (path, Some(parsed))
            }
            None => (spec, None),
        };
        let loaded = MlpFactory::load(std::path::Path::new(path), observation_size)?;
        return Ok(Box::new(match rule {
            Some(r) => loaded.with_rule(r),
            None => loaded,
        }));
    }
    Builtin::from_name(name)
        .map(|b| Box::new(b) as Box<dyn PolicyFactory>)
        .ok_or_else(|| PolicyNameError::Unknown { name: name.into() })
}
