//! The robot and its laser (docs/model.md "Robot", "Sensors"): the disc, its kinematics, speeds
//! and limits, what a collision does, its motion and goal-sensing noise, and the range finder,
//! with their defaults and checks.

use crate::config::{
    check, finite, fraction, is_zero, length, non_negative, ConfigError, MAX_LENGTH_PX,
};
use serde::{Deserialize, Serialize};

/// How the robot's body answers a command (docs/model.md "Kinematics").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum KinematicsKind {
    /// The paper's robot: LEFT and RIGHT turn on the spot, AHEAD moves; continuous `(v, w)`
    /// actions follow ideal unicycle arcs (the default).
    #[default]
    Discrete,
    /// The same body, meant for continuous `(v, w)` actions: any commanded speed within the
    /// limits is reached at once.
    Unicycle,
    /// A differential-drive base: `(v, w)` commands reached under acceleration limits
    /// (`accel_max_px`, `alpha_max_deg`) and, given `wheel_base_px`, wheel-speed limits.
    DiffDrive,
    /// An omnidirectional base: `(vx, vy, w)` in the robot's frame, under the same limits.
    Omni,
    /// A car-like robot: speed and steering angle, `wheel_base_px` between the axles; it
    /// cannot turn on the spot.
    Ackermann,
}

impl KinematicsKind {
    /// Every kind, in the order the documentation lists them.
    pub const ALL: [Self; 5] = [
        Self::Discrete,
        Self::Unicycle,
        Self::DiffDrive,
        Self::Omni,
        Self::Ackermann,
    ];

    /// The name configurations use.
    pub fn name(self) -> &'static str {
        match self {
            Self::Discrete => "discrete",
            Self::Unicycle => "unicycle",
            Self::DiffDrive => "diff_drive",
            Self::Omni => "omni",
            Self::Ackermann => "ackermann",
        }
    }

    fn is_default(&self) -> bool {
        *self == Self::Discrete
    }
}

/// What a step that would touch an obstacle does.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum OnCollision {
    /// The pose stays where it was and the episode goes on (the paper's behaviour).
    Revert,
    /// The pose stays where it was and the episode ends as a collision.
    Terminate,
}

/// The robot disc and its actions (docs/model.md "Robot").
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RobotConfig {
    /// Disc radius, px. Default 5.
    pub radius_px: f64,
    /// Distance of one AHEAD step, px (v_m). Default 5.
    pub move_speed_px: f64,
    /// Heading change of one LEFT or RIGHT step, degrees (v_r). Default 15.
    pub turn_speed_deg: f64,
    /// Continuous actions: largest |v|, px per step. Default 5.
    pub max_linear_speed_px: f64,
    /// Continuous actions: largest |w|, degrees per step. Default 15.
    pub max_angular_speed_deg: f64,
    /// `revert` (default, the paper) or `terminate`.
    pub on_collision: OnCollision,
    /// The footprint: `disc` (default) or `rectangle`.
    #[serde(skip_serializing_if = "Shape::is_default")]
    pub shape: Shape,
    /// `rectangle`: length along the heading, px.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub length_px: Option<f64>,
    /// `rectangle`: width across the heading, px.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub width_px: Option<f64>,
    /// `rectangle`: how far the rectangle's centre lies ahead of the robot's position (the
    /// point it turns about; a car's rear axle), px. Unset: 0.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub offset_px: Option<f64>,
    /// `polygon`: the corners of a convex polygon in the robot's frame, `[ahead px, left px]`,
    /// in order round it.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub vertices: Vec<[f64; 2]>,
    /// How the body answers a command. Default `discrete`.
    #[serde(skip_serializing_if = "KinematicsKind::is_default")]
    pub kinematics: KinematicsKind,
    /// `diff_drive`, `omni`, `ackermann`: largest change of the linear speed in one step, px
    /// per step per step. Unset: none.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub accel_max_px: Option<f64>,
    /// `diff_drive`, `omni`: largest change of the turn rate in one step, degrees per step per
    /// step. Unset: none.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub alpha_max_deg: Option<f64>,
    /// `diff_drive`: distance between the wheels, px (each wheel's speed `v +- w b / 2` kept
    /// within `max_linear_speed_px`); `ackermann`: distance between the axles, px (required).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub wheel_base_px: Option<f64>,
    /// `omni`: largest |vy| (sideways), px per step. Unset: `max_linear_speed_px`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_lateral_speed_px: Option<f64>,
    /// `ackermann`: largest steering angle, degrees. Unset: 30.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub steer_max_deg: Option<f64>,
    /// `ackermann`: largest change of the steering angle in one step, degrees. Unset: none.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub steer_rate_max_deg: Option<f64>,
    /// Standard deviation of Gaussian noise on the executed linear speed (and sideways speed),
    /// px per step. Default 0 (none).
    #[serde(skip_serializing_if = "is_zero")]
    pub motion_noise_px: f64,
    /// Standard deviation of Gaussian noise on the executed turn rate, degrees per step.
    /// Default 0 (none).
    #[serde(skip_serializing_if = "is_zero")]
    pub motion_noise_deg: f64,
    /// Standard deviation of Gaussian noise on the sensed goal bearing (the observation's goal
    /// direction), degrees. Default 0 (none).
    #[serde(skip_serializing_if = "is_zero")]
    pub goal_noise_deg: f64,
    /// Standard deviation of Gaussian noise on the sensed goal distance, px (what
    /// `Episode::sensed_goal` reports). Default 0 (none).
    #[serde(skip_serializing_if = "is_zero")]
    pub goal_noise_px: f64,
}

/// The robot's footprint (docs/model.md "Footprints").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Shape {
    /// A disc of `radius_px` (the paper's robot, the default).
    #[default]
    Disc,
    /// A rectangle `length_px` along the heading by `width_px` across, its centre `offset_px`
    /// ahead of the robot's position (the point it turns about).
    Rectangle,
    /// A convex polygon, its `vertices` in the robot's frame (`[ahead px, left px]`).
    Polygon,
}

impl Shape {
    fn is_default(&self) -> bool {
        *self == Self::Disc
    }
}

/// Largest number of discs a footprint is covered by in collision checks.
const MAX_COVER_DISCS: usize = 64;

/// Steering limit of an Ackermann robot when `steer_max_deg` is unset, degrees.
pub const DEFAULT_STEER_MAX_DEG: f64 = 30.0;

impl Default for RobotConfig {
    fn default() -> Self {
        Self {
            radius_px: 5.0,
            move_speed_px: 5.0,
            turn_speed_deg: 15.0,
            max_linear_speed_px: 5.0,
            max_angular_speed_deg: 15.0,
            on_collision: OnCollision::Revert,
            shape: Shape::Disc,
            length_px: None,
            width_px: None,
            offset_px: None,
            vertices: Vec::new(),
            kinematics: KinematicsKind::Discrete,
            accel_max_px: None,
            alpha_max_deg: None,
            wheel_base_px: None,
            max_lateral_speed_px: None,
            steer_max_deg: None,
            steer_rate_max_deg: None,
            motion_noise_px: 0.0,
            motion_noise_deg: 0.0,
            goal_noise_deg: 0.0,
            goal_noise_px: 0.0,
        }
    }
}

/// The laser range finder (docs/model.md "Sensors").
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LaserConfig {
    /// Number of beams m. Default 17.
    pub beams: u32,
    /// Angle covered by the beams, centred on the heading, degrees. Default 180.
    pub fov_deg: f64,
    /// Largest reading d_max, px. Default 50.
    pub range_px: f64,
    /// Standard deviation of Gaussian reading noise, px. Default 0 (no noise).
    pub noise_sigma_px: f64,
    /// Probability that a beam returns nothing in a scan (it reads `range_px`). Default 0.
    #[serde(skip_serializing_if = "is_zero")]
    pub dropout: f64,
    /// Standard deviation of Gaussian noise on each beam's angle, drawn afresh every scan,
    /// degrees. Default 0 (none).
    #[serde(skip_serializing_if = "is_zero")]
    pub angle_jitter_deg: f64,
}

impl Default for LaserConfig {
    fn default() -> Self {
        Self {
            beams: 17,
            fov_deg: 180.0,
            range_px: 50.0,
            noise_sigma_px: 0.0,
            dropout: 0.0,
            angle_jitter_deg: 0.0,
        }
    }
}

/// Largest number of laser beams.
pub const MAX_BEAMS: u32 = 4096;

impl RobotConfig {
    /// Checks every robot field, naming the first one out of range.
    pub(crate) fn validate(&self) -> Result<(), ConfigError> {
        let r = self;
        length("robot.radius_px", r.radius_px, false)?;
        length("robot.move_speed_px", r.move_speed_px, true)?;
        finite("robot.turn_speed_deg", r.turn_speed_deg)?;
        length("robot.max_linear_speed_px", r.max_linear_speed_px, true)?;
        non_negative("robot.max_angular_speed_deg", r.max_angular_speed_deg)?;
        let kind = r.kinematics;
        // Each model's own fields, refused for a model that has no use for them.
        use KinematicsKind::{Ackermann, DiffDrive, Omni};
        let only = |field: &str, given: Option<f64>, kinds: &[KinematicsKind]| match given {
            Some(v) if !kinds.contains(&kind) => check(
                false,
                field,
                format!("{v:?}"),
                match kinds {
                    [Ackermann] => "is only for kinematics = \"ackermann\"",
                    [Omni] => "is only for kinematics = \"omni\"",
                    [DiffDrive, Omni] => "is only for kinematics = \"diff_drive\" or \"omni\"",
                    [DiffDrive, Ackermann] => {
                        "is only for kinematics = \"diff_drive\" or \"ackermann\""
                    }
                    _ => "is only for kinematics = \"diff_drive\", \"omni\" or \"ackermann\"",
                },
            ),
            _ => Ok(()),
        };
        only(
            "robot.accel_max_px",
            r.accel_max_px,
            &[DiffDrive, Omni, Ackermann],
        )?;
        only("robot.alpha_max_deg", r.alpha_max_deg, &[DiffDrive, Omni])?;
        only(
            "robot.wheel_base_px",
            r.wheel_base_px,
            &[DiffDrive, Ackermann],
        )?;
        only(
            "robot.max_lateral_speed_px",
            r.max_lateral_speed_px,
            &[Omni],
        )?;
        only("robot.steer_max_deg", r.steer_max_deg, &[Ackermann])?;
        only(
            "robot.steer_rate_max_deg",
            r.steer_rate_max_deg,
            &[Ackermann],
        )?;
        for (field, v) in [
            ("robot.accel_max_px", r.accel_max_px),
            ("robot.wheel_base_px", r.wheel_base_px),
        ] {
            if let Some(v) = v {
                length(field, v, false)?;
            }
        }
        if let Some(v) = r.max_lateral_speed_px {
            length("robot.max_lateral_speed_px", v, true)?;
        }
        for (field, v) in [
            ("robot.alpha_max_deg", r.alpha_max_deg),
            ("robot.steer_rate_max_deg", r.steer_rate_max_deg),
        ] {
            if let Some(v) = v {
                check(
                    v.is_finite() && v > 0.0,
                    field,
                    format!("{v:?}"),
                    "must be a positive number of degrees",
                )?;
            }
        }
        if let Some(v) = r.steer_max_deg {
            check(
                v.is_finite() && v > 0.0 && v < 90.0,
                "robot.steer_max_deg",
                format!("{v:?}"),
                "must be between 0 and 90 degrees (both excluded)",
            )?;
        }
        check(
            kind != Ackermann || r.wheel_base_px.is_some(),
            "robot.wheel_base_px",
            "unset",
            "must be given for kinematics = \"ackermann\" (the distance between the axles, px)",
        )?;
        let rectangle = r.shape == Shape::Rectangle;
        for (field, v) in [
            ("robot.length_px", r.length_px),
            ("robot.width_px", r.width_px),
            ("robot.offset_px", r.offset_px),
        ] {
            if let (false, Some(v)) = (rectangle, v) {
                check(
                    false,
                    field,
                    format!("{v:?}"),
                    "is only for shape = \"rectangle\"",
                )?;
            }
        }
        let polygon = r.shape == Shape::Polygon;
        if !polygon && !r.vertices.is_empty() {
            check(
                false,
                "robot.vertices",
                format!("{:?}", r.vertices),
                "is only for shape = \"polygon\"",
            )?;
        }
        if polygon {
            let finite = r
                .vertices
                .iter()
                .flatten()
                .all(|v| v.abs() <= MAX_LENGTH_PX);
            check(
                finite && super::scene::is_convex_polygon(&r.vertices),
                "robot.vertices",
                format!("{:?}", r.vertices),
                "must be at least three corners of a convex polygon, in order round it",
            )?;
            check(
                super::scene::is_inside_convex(&r.vertices, [0.0, 0.0]),
                "robot.vertices",
                format!("{:?}", r.vertices),
                "must hold the robot's position [0, 0] (the point it turns about)",
            )?;
        }
        if rectangle {
            for (field, v) in [
                ("robot.length_px", r.length_px),
                ("robot.width_px", r.width_px),
            ] {
                match v {
                    Some(v) => length(field, v, false)?,
                    None => check(
                        false,
                        field,
                        "unset",
                        "must be given for shape = \"rectangle\"",
                    )?,
                }
            }
            if let Some(v) = r.offset_px {
                finite("robot.offset_px", v)?;
                length("robot.offset_px", v.abs(), true)?;
            }
        }
        length("robot.motion_noise_px", r.motion_noise_px, true)?;
        non_negative("robot.motion_noise_deg", r.motion_noise_deg)?;
        non_negative("robot.goal_noise_deg", r.goal_noise_deg)?;
        length("robot.goal_noise_px", r.goal_noise_px, true)?;
        Ok(())
    }

    /// The rectangle footprint's length, width and centre offset, px (`None` for a disc).
    pub fn rectangle(&self) -> Option<(f64, f64, f64)> {
        match (self.shape, self.length_px, self.width_px) {
            (Shape::Rectangle, Some(l), Some(w)) => Some((l, w, self.offset_px.unwrap_or(0.0))),
            _ => None,
        }
    }

    /// The footprint's corners in the robot's frame (`[ahead px, left px]`, counter-clockwise
    /// for a rectangle): a rectangle's four or a polygon's vertices; empty for a disc.
    pub fn outline(&self) -> Vec<[f64; 2]> {
        if let Some((l, w, offset)) = self.rectangle() {
            let (a, b) = (l / 2.0, w / 2.0);
            return vec![
                [offset - a, -b],
                [offset + a, -b],
                [offset + a, b],
                [offset - a, b],
            ];
        }
        match self.shape {
            Shape::Polygon => self.vertices.clone(),
            _ => Vec::new(),
        }
    }

    /// The radius of the disc about the robot's position that holds its footprint, px: what
    /// the free-space grid, placement, other robots and moving obstacles take the robot for.
    pub fn circumscribed_px(&self) -> f64 {
        match self.shape {
            Shape::Disc => self.radius_px,
            _ => (self.outline().iter())
                .map(|[x, y]| x.hypot(*y))
                .fold(0.0, f64::max),
        }
    }

    /// The discs, in the robot's frame (`[ahead px, left px]`, radius px), that the collision
    /// checks take a rectangle footprint for: a row of them along it, each holding a
    /// `length / n` by `width` piece, so they hold the whole rectangle and reach beyond it by
    /// at most their radius less half a piece (docs/model.md "Footprints"); a polygon's along
    /// its edges. Empty for a disc.
    pub fn cover(&self) -> Vec<([f64; 2], f64)> {
        if self.shape == Shape::Polygon {
            return self.edge_cover();
        }
        let Some((l, w, offset)) = self.rectangle() else {
            return Vec::new();
        };
        // Pieces no longer than half the width: the discs reach a little beyond the sides
        // (0.12 of the width) and a quarter of the width beyond the ends at most.
        let n = ((2.0 * l / w).ceil() as usize).clamp(1, MAX_COVER_DISCS);
        let piece = l / n as f64;
        let r = (piece / 2.0).hypot(w / 2.0);
        (0..n)
            .map(|i| ([offset - l / 2.0 + piece * (i as f64 + 0.5), 0.0], r))
            .collect()
    }

    /// A polygon's discs: centred along its edges, each overlapping the next by half, so every
    /// point of the outline lies in one of them (an obstacle cannot get inside without crossing
    /// it, and every disc's sweep is checked); radius `max(1, perimeter / 96)` px.
    fn edge_cover(&self) -> Vec<([f64; 2], f64)> {
        let v = &self.vertices;
        let n = v.len();
        let edge = |i: usize| {
            let ([x0, y0], [x1, y1]) = (v[i], v[(i + 1) % n]);
            (x1 - x0).hypot(y1 - y0)
        };
        let perimeter: f64 = (0..n).map(edge).sum();
        let r = (perimeter / 96.0).max(1.0);
        let mut out = Vec::new();
        for i in 0..n {
            let ([x0, y0], [x1, y1]) = (v[i], v[(i + 1) % n]);
            let k = ((edge(i) / (1.5 * r)).ceil() as usize).max(1);
            for j in 0..k {
                let t = j as f64 / k as f64;
                out.push(([x0 + (x1 - x0) * t, y0 + (y1 - y0) * t], r));
            }
        }
        out
    }

    /// A car's largest steering angle, degrees: `steer_max_deg`, unset 30.
    pub fn steer_limit_deg(&self) -> f64 {
        self.steer_max_deg.unwrap_or(DEFAULT_STEER_MAX_DEG)
    }

    /// A car's distance between its axles, px: `wheel_base_px` (which a validated `ackermann`
    /// robot gives), else the robot's diameter.
    pub fn axle_base_px(&self) -> f64 {
        self.wheel_base_px.unwrap_or(2.0 * self.radius_px)
    }

    /// The largest sideways speed, px per step: `max_lateral_speed_px` for an omnidirectional
    /// robot (unset: `max_linear_speed_px`), 0 for the others.
    pub fn lateral_speed_px(&self) -> f64 {
        match self.kinematics {
            KinematicsKind::Omni => self
                .max_lateral_speed_px
                .unwrap_or(self.max_linear_speed_px),
            _ => 0.0,
        }
    }

    /// How many numbers a continuous action of this robot holds: 3 for `omni`, else 2.
    pub fn action_size(&self) -> usize {
        match self.kinematics {
            KinematicsKind::Omni => 3,
            _ => 2,
        }
    }

    /// The full value of each dimension of a normalised continuous action (what `1.0` in
    /// that dimension commands): `[v_max px, w_max deg]`, `[v_max px, vy_max px, w_max deg]`
    /// for `omni`, `[v_max px, steer_max deg]` for `ackermann`.
    pub fn action_scale(&self) -> Vec<f64> {
        let (v, w) = (self.max_linear_speed_px, self.max_angular_speed_deg);
        match self.kinematics {
            KinematicsKind::Omni => vec![v, self.lateral_speed_px(), w],
            KinematicsKind::Ackermann => {
                vec![v, self.steer_limit_deg()]
            }
            _ => vec![v, w],
        }
    }

    /// What a continuous action of this robot holds, for messages: `"(v, w)"`, `"(vx, vy, w)"`
    /// or `"(v, steer)"`.
    pub fn continuous_names(&self) -> &'static str {
        match self.kinematics {
            KinematicsKind::Omni => "(vx, vy, w)",
            KinematicsKind::Ackermann => "(v, steer)",
            _ => "(v, w)",
        }
    }
}

impl LaserConfig {
    /// Checks every laser field, naming the first one out of range.
    pub(super) fn validate(&self) -> Result<(), ConfigError> {
        let l = self;
        check(
            (1..=MAX_BEAMS).contains(&l.beams),
            "laser.beams",
            l.beams,
            "must be between 1 and 4096",
        )?;
        check(
            l.fov_deg.is_finite() && (0.0..=360.0).contains(&l.fov_deg),
            "laser.fov_deg",
            format!("{:?}", l.fov_deg),
            "must be between 0 and 360",
        )?;
        length("laser.range_px", l.range_px, false)?;
        length("laser.noise_sigma_px", l.noise_sigma_px, true)?;
        fraction("laser.dropout", l.dropout)?;
        check(
            l.angle_jitter_deg.is_finite() && (0.0..=90.0).contains(&l.angle_jitter_deg),
            "laser.angle_jitter_deg",
            format!("{:?}", l.angle_jitter_deg),
            "must be between 0 and 90 degrees",
        )?;
        Ok(())
    }
}
