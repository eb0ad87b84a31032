//! Crowds (docs/model.md "Crowds that react"): a `[[crowd]]` entry makes `count` reactive
//! pedestrians at once, placed by a pattern, and can put the robot's own start and goal on the
//! same pattern (CrowdNav's robot at (0, -R) heading for (0, R)).
//!
//! A crowd is a shorthand: validation turns each entry into the `[[moving]]` entry it stands for
//! (after the file's own `[[moving]]` entries, so their obstacles and draws come first), and the
//! robot's pattern into a [`RobotPattern`] that placement reads.

use crate::config::moving::validate_entry;
use crate::config::{check, AgentOrca, Arrival, ConfigError, Forces, MotionKind, MovingConfig};
use crate::config::{MovingShape, Pattern};
use serde::{Deserialize, Serialize};

/// One `[[crowd]]` entry: `count` pedestrians placed by `pattern`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CrowdConfig {
    /// How many pedestrians. Default 5.
    pub count: u32,
    /// `circle` (opposite points of a circle), `square` (opposite sides of a square) or `random`
    /// (start and goal drawn in free space, the default).
    pub pattern: Pattern,
    /// `orca` (default) or `social_force`.
    pub motion: MotionKind,
    /// Disc radius, px. Default 8.
    pub radius_px: f64,
    /// Preferred speed, px per step. Default 2.
    pub speed_px: f64,
    /// Largest speed, px per step. Default `speed_px`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_speed_px: Option<f64>,
    /// The pattern's centre `[x, y]`, px. Default: the scene's centre.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pattern_center: Option<[f64; 2]>,
    /// The circle's radius, or the square's half side, px (needed by `circle` and `square`).
    #[serde(skip_serializing_if = "super::is_zero")]
    pub pattern_radius_px: f64,
    /// Starts and goals move by up to this much in x and y, px (uniform). Default 0.
    #[serde(skip_serializing_if = "super::is_zero")]
    pub jitter_px: f64,
    /// At its goal `stay` (default), `new_goal` or `vanish`.
    pub on_arrival: Arrival,
    /// Whether they avoid the robots too. Default false (CrowdNav's invisible robot).
    pub sees_robots: bool,
    /// Least gap between a pedestrian's start or goal and the robots' starts and goals, px.
    /// Default 30.
    pub min_robot_distance_px: f64,
    /// `circle`, `square`: the robot starts at the pattern's bottom point `(cx, cy - R)` heading
    /// up (90 degrees) and heads for its top point `(cx, cy + R)`, as CrowdNav puts it. Default
    /// false (the robot's start and goal as `[episode]` says).
    #[serde(skip_serializing_if = "super::is_false")]
    pub robot_follows: bool,
    /// `orca`: how they avoid.
    #[serde(skip_serializing_if = "AgentOrca::is_default")]
    pub orca: AgentOrca,
    /// `social_force`: their forces.
    #[serde(skip_serializing_if = "Forces::is_default")]
    pub social_force: Forces,
}

impl Default for CrowdConfig {
    fn default() -> Self {
        let m = MovingConfig::default();
        Self {
            count: 5,
            pattern: Pattern::Random,
            motion: MotionKind::Orca,
            radius_px: m.radius_px,
            speed_px: m.speed_px,
            max_speed_px: None,
            pattern_center: None,
            pattern_radius_px: 0.0,
            jitter_px: 0.0,
            on_arrival: Arrival::Stay,
            sees_robots: false,
            min_robot_distance_px: m.min_robot_distance_px,
            robot_follows: false,
            orca: AgentOrca::default(),
            social_force: Forces::default(),
        }
    }
}

impl CrowdConfig {
    /// The `[[moving]]` entry this crowd stands for.
    pub fn to_moving(&self) -> MovingConfig {
        MovingConfig {
            count: self.count,
            shape: MovingShape::Disc,
            radius_px: self.radius_px,
            motion: self.motion,
            speed_px: self.speed_px,
            max_speed_px: self.max_speed_px,
            on_arrival: self.on_arrival,
            sees_robots: self.sees_robots,
            pattern: Some(self.pattern),
            pattern_center: self.pattern_center,
            pattern_radius_px: self.pattern_radius_px,
            jitter_px: self.jitter_px,
            min_robot_distance_px: self.min_robot_distance_px,
            orca: self.orca.clone(),
            social_force: self.social_force.clone(),
            ..MovingConfig::default()
        }
    }
}

/// Where a crowd's pattern puts the robot (`robot_follows`).
#[derive(Clone, Debug, PartialEq)]
pub struct RobotPattern {
    /// The `[[crowd]]` entry (from 0).
    pub entry: usize,
    /// The crowd's pattern.
    pub pattern: Pattern,
    /// Its centre; `None`: the scene's centre.
    pub center: Option<[f64; 2]>,
    /// Its radius (half side), px.
    pub radius_px: f64,
}

impl RobotPattern {
    /// The robot's start pose `[x, y, heading deg]` and goal `[x, y]` in a scene of `width` x
    /// `height` px; `None` for `random` (drawn as usual).
    pub fn start_goal(&self, width: f64, height: f64) -> Option<([f64; 3], [f64; 2])> {
        let [cx, cy] = self.center.unwrap_or([width / 2.0, height / 2.0]);
        let r = self.radius_px;
        match self.pattern {
            Pattern::Circle | Pattern::Square => Some(([cx, cy - r, 90.0], [cx, cy + r])),
            Pattern::Random => None,
        }
    }
}

/// Checks every `[[crowd]]` entry (`crowd[i]`) as the `[[moving]]` entry it stands for, and that
/// at most one puts the robot on its pattern, and only a lone robot (or a team of one) whose
/// start and goal `[episode]` (or its `[[robots]]` entry) leaves unset. Gives the robot's
/// pattern, if one does.
pub(super) fn validate_crowds(
    crowds: &[CrowdConfig],
    fixed_start_or_goal: bool,
    robots: &[super::TeamRobotConfig],
) -> Result<Option<RobotPattern>, ConfigError> {
    // A team of one is the lone robot: it may follow a pattern as the lone robot does.
    let team = match robots {
        [] => false,
        [one] => one.count != 1,
        _ => true,
    };
    let entry_places = robots
        .iter()
        .any(|r| r.start.is_some() || r.goal.is_some() || !r.goals.is_empty());
    let mut robot = None;
    for (i, c) in crowds.iter().enumerate() {
        let f = |name: &str| format!("crowd[{i}].{name}");
        check(
            c.motion.is_reactive(),
            &f("motion"),
            format!("{:?}", c.motion.name()),
            "a crowd's pedestrians move as \"orca\" or \"social_force\"",
        )?;
        validate_entry(&c.to_moving(), &f)?;
        if c.robot_follows {
            check(
                robot.is_none(),
                &f("robot_follows"),
                true,
                "only one [[crowd]] entry may place the robot",
            )?;
            check(
                !team,
                &f("robot_follows"),
                true,
                "a team's robots are placed by their [[robots]] entries (a team of one may follow it)",
            )?;
            check(
                !fixed_start_or_goal,
                &f("robot_follows"),
                true,
                "episode.start and episode.goal already place the robot: leave them unset",
            )?;
            check(
                !entry_places,
                &f("robot_follows"),
                true,
                "the [[robots]] entry's start or goals already place the robot: leave them unset",
            )?;
            robot = Some(RobotPattern {
                entry: i,
                pattern: c.pattern,
                center: c.pattern_center,
                radius_px: c.pattern_radius_px,
            });
        }
    }
    Ok(robot)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::SimConfig;

    fn crowd_file(entry: &str) -> String {
        format!("[[crowd]]\n{entry}\n")
    }

    #[test]
    fn a_crowd_is_the_moving_entry_it_stands_for() {
        let text = crowd_file(
            "count = 3\npattern = \"circle\"\npattern_radius_px = 80.0\nspeed_px = 5.0\nradius_px = 6.0\nmin_robot_distance_px = 12.0",
        );
        let c = SimConfig::from_toml_str(&text).unwrap().validate().unwrap();
        assert_eq!(c.moving.len(), 1);
        assert!(c.crowd.is_empty(), "the crowd is expanded once");
        let m = &c.moving[0];
        assert_eq!(
            (m.count, m.motion, m.pattern, m.speed_px, m.radius_px),
            (3, MotionKind::Orca, Some(Pattern::Circle), 5.0, 6.0)
        );
        // As written, it is still a crowd.
        assert_eq!(c.as_sim_config().crowd.len(), 1);
        assert!(c.as_sim_config().moving.is_empty());
        assert_eq!(c.robot_pattern(), None);
    }

    #[test]
    fn crowd_entries_follow_the_moving_ones() {
        let text = "[[crowd]]\nmotion = \"social_force\"\n[[moving]]\ncount = 2\n";
        let c = SimConfig::from_toml_str(text).unwrap().validate().unwrap();
        let kinds: Vec<_> = c.moving.iter().map(|m| m.motion).collect();
        assert_eq!(kinds, [MotionKind::RandomWalk, MotionKind::SocialForce]);
    }

    #[test]
    fn bad_entries_name_the_crowd_field() {
        let bad = |entry: &str| {
            SimConfig::from_toml_str(&crowd_file(entry))
                .unwrap()
                .validate()
                .unwrap_err()
                .to_string()
        };
        assert_eq!(
            bad("speed_px = -1.0"),
            "crowd[0].speed_px = -1.0: must be between 0 and 100000 px"
        );
        // A horizon is a time: in steps, not px (the robot's [orca] as the pedestrians').
        let robot = SimConfig::from_toml_str("[orca]\ntime_horizon_steps = -1.0\n")
            .unwrap()
            .validate()
            .unwrap_err()
            .to_string();
        assert_eq!(
            robot,
            "orca.time_horizon_steps = -1.0: must be a positive number of steps, at most 100000"
        );
        assert_eq!(
            bad("motion = \"orca\"\norca = { time_horizon_steps = -1 }"),
            "crowd[0].orca.time_horizon_steps = -1.0: must be a positive number of steps, at most \
             100000"
        );
        assert!(bad("motion = \"linear\"").starts_with("crowd[0].motion = \"linear\""));
        assert!(bad("pattern = \"circle\"").starts_with("crowd[0].pattern = \"circle\""));
        let two =
            "[[crowd]]\nrobot_follows = true\npattern = \"circle\"\npattern_radius_px = 5.0\n\
                   [[crowd]]\nrobot_follows = true\n";
        let e = SimConfig::from_toml_str(two)
            .unwrap()
            .validate()
            .unwrap_err();
        assert!(e.to_string().starts_with("crowd[1].robot_follows"), "{e}");
        let fixed = "[episode]\ngoal = [1.0, 2.0]\n[[crowd]]\nrobot_follows = true\n";
        let e = SimConfig::from_toml_str(fixed)
            .unwrap()
            .validate()
            .unwrap_err();
        assert!(e.to_string().contains("episode.start"), "{e}");
        // A team of one follows a pattern as the lone robot does; a team, or one whose entry
        // places it, does not.
        let follows =
            "[[crowd]]\nrobot_follows = true\npattern = \"circle\"\npattern_radius_px = 50.0\n";
        for (robots, ok) in [
            ("[[robots]]\ncount = 1\n", true),
            ("[[robots]]\ncount = 2\n", false),
            ("[[robots]]\n[[robots]]\n", false),
            ("[[robots]]\nstart = [10.0, 10.0, 0.0]\n", false),
        ] {
            let text = format!("{follows}{robots}");
            let c = SimConfig::from_toml_str(&text).unwrap().validate();
            assert_eq!(c.is_ok(), ok, "{robots}: {c:?}");
        }
    }

    #[test]
    fn collision_ends_is_terminate_in_effect_and_kept_as_written() {
        use crate::config::OnCollision;
        let c = SimConfig::from_toml_str("[episode]\ncollision_ends = true\n")
            .unwrap()
            .validate()
            .unwrap();
        assert_eq!(c.robot.on_collision, OnCollision::Terminate);
        assert_eq!(c.as_sim_config().robot.on_collision, OnCollision::Revert);
        assert!(c.as_sim_config().episode.collision_ends);
        // Validating what was written again gives the same configuration in effect.
        assert_eq!(c.as_sim_config().clone().validate().unwrap(), c);
    }

    #[test]
    fn the_robot_follows_circle_and_square_not_random() {
        let p = |pattern| RobotPattern {
            entry: 0,
            pattern,
            center: None,
            radius_px: 80.0,
        };
        assert_eq!(
            p(Pattern::Circle).start_goal(300.0, 300.0),
            Some(([150.0, 70.0, 90.0], [150.0, 230.0]))
        );
        assert_eq!(
            p(Pattern::Square).start_goal(300.0, 200.0),
            Some(([150.0, 20.0, 90.0], [150.0, 180.0]))
        );
        assert_eq!(p(Pattern::Random).start_goal(300.0, 300.0), None);
    }
}
