//! The configuration as documented TOML: a comment on every field with its meaning and unit
//! (`ronap config`), and the complete example scenario (`ronap config --scenario`).

use crate::config::{MotionKind, MovingConfig, MovingShape, ObstacleConfig, Patrol, SimConfig};

/// Every configuration field: section, name, and what it means with its unit. Fields that are
/// unset by default carry an example value, written commented out.
const FIELD_DOCS: &[(&str, &str, &str, Option<&str>)] = &[
    ("scene", "kind", "Where episodes take place: \"maze\" (the paper's), \"warehouse\" or \"map\" (an image or ROS YAML file).", None),
    ("scene", "seed", "Generated scenes: one scene, of this seed, for every episode. Unset: each episode's seed draws its own.", Some("7")),
    ("scene", "file", "Map scenes: the PNG/PGM image or ROS map_server YAML file, relative to this file.", Some("\"map.png\"")),
    ("maze", "cols", "Number of cell columns.", None),
    ("maze", "rows", "Number of cell rows.", None),
    ("maze", "cell_px", "Side of a square cell, px.", None),
    ("maze", "loops", "Fraction of the perfect maze's interior walls removed afterwards, 0 to 1 (0: perfect maze).", None),
    ("maze", "wall_thickness_px", "Wall thickness, px.", None),
    ("warehouse", "rack_pairs", "Pairs of rack rows (two racks back to back), bottom to top.", None),
    ("warehouse", "racks_per_row", "Racks along one row.", None),
    ("warehouse", "rack_length_px", "Length of a rack along its row, px.", None),
    ("warehouse", "rack_depth_px", "Depth of one rack (a pair is twice as deep), px.", None),
    ("warehouse", "aisle_px", "Width of the aisles, cross aisles and border aisle, px.", None),
    ("warehouse", "cross_aisle_every", "A cross aisle after every this many racks (0: none).", None),
    ("warehouse", "loading_px", "Depth of the free loading area along the bottom, px.", None),
    ("warehouse", "clutter", "Fraction of aisle spots holding a pallet, 0 to 1 (kept passable for the robot).", None),
    ("warehouse", "pallet_px", "Side of a square pallet, px.", None),
    ("warehouse", "wall_thickness_px", "Thickness of the outer walls, px.", None),
    ("map", "threshold", "Image maps: grey value (0-255) at or below which a pixel is an obstacle.", None),
    ("map", "resolution_px", "Image maps: scene px per image pixel.", None),
    ("robot", "radius_px", "Robot disc radius, px.", None),
    ("robot", "move_speed_px", "Distance of one AHEAD step, px (v_m).", None),
    ("robot", "turn_speed_deg", "Heading change of one LEFT or RIGHT step, degrees (v_r).", None),
    ("robot", "max_linear_speed_px", "Continuous actions: largest |v|, px per step.", None),
    ("robot", "max_angular_speed_deg", "Continuous actions: largest |w|, degrees per step.", None),
    ("robot", "on_collision", "A step that would touch an obstacle: \"revert\" (stay, go on; the paper) or \"terminate\" (end the episode).", None),
    ("robot", "shape", "Footprint: \"disc\" (radius_px; the default), \"rectangle\" (length_px x width_px) or \"polygon\" (vertices); for the last two radius_px becomes the circumscribed radius, which the free-space grid, placement, other robots and moving obstacles use.", Some("\"rectangle\"")),
    ("robot", "length_px", "Rectangle footprint: length along the heading, px.", Some("20.0")),
    ("robot", "width_px", "Rectangle footprint: width across the heading, px.", Some("10.0")),
    ("robot", "offset_px", "Rectangle footprint: how far its centre lies ahead of the robot's position (the point it turns about), px. Unset: 0.", Some("0.0")),
    ("robot", "vertices", "Polygon footprint: the corners of a convex polygon round the robot's position, [ahead px, left px], in order.", Some("[[10.0, 0.0], [-6.0, 6.0], [-6.0, -6.0]]")),
    ("robot", "kinematics", "How the body answers a command: \"discrete\" (the paper's; default), \"unicycle\" (the same body, for continuous (v, w)), \"diff_drive\" ((v, w) under acceleration and wheel limits), \"omni\" ((vx, vy, w)) or \"ackermann\" ((v, steer); cannot turn on the spot).", Some("\"diff_drive\"")),
    ("robot", "accel_max_px", "diff_drive, omni, ackermann: largest change of the speed in one step, px per step per step. Unset: none.", Some("1.0")),
    ("robot", "alpha_max_deg", "diff_drive, omni: largest change of the turn rate in one step, degrees per step per step. Unset: none.", Some("5.0")),
    ("robot", "wheel_base_px", "diff_drive: distance between the wheels, each kept within max_linear_speed_px; ackermann (required): distance between the axles, px.", Some("8.0")),
    ("robot", "max_lateral_speed_px", "omni: largest sideways speed |vy|, px per step. Unset: max_linear_speed_px.", Some("3.0")),
    ("robot", "steer_max_deg", "ackermann: largest steering angle, degrees. Unset: 30.", Some("40.0")),
    ("robot", "steer_rate_max_deg", "ackermann: largest change of the steering angle in one step, degrees. Unset: none.", Some("15.0")),
    ("robot", "motion_noise_px", "Standard deviation of Gaussian noise on the executed speed (and sideways speed), px per step (0: none; its own random stream).", Some("0.1")),
    ("robot", "motion_noise_deg", "Standard deviation of Gaussian noise on the executed turn rate, degrees per step (0: none).", Some("0.5")),
    ("robot", "goal_noise_deg", "Standard deviation of Gaussian noise on the sensed goal bearing (the observation's goal direction), degrees (0: none; its own random stream).", Some("2.0")),
    ("robot", "goal_noise_px", "Standard deviation of Gaussian noise on the sensed goal distance, px (0: none).", Some("5.0")),
    ("laser", "beams", "Number of laser beams m.", None),
    ("laser", "fov_deg", "Angle the beams cover, centred on the heading, degrees.", None),
    ("laser", "range_px", "Largest reading d_max, px.", None),
    ("laser", "noise_sigma_px", "Standard deviation of Gaussian reading noise, px (0: none).", None),
    ("laser", "dropout", "Probability that a beam returns nothing in a scan (it reads range_px), 0 to 1 (its own random stream).", Some("0.05")),
    ("laser", "angle_jitter_deg", "Standard deviation of Gaussian noise on each beam's angle, drawn afresh every scan, degrees (its own random stream).", Some("1.0")),
    ("episode", "goal_tolerance_px", "Success when the goal distance falls below this, px (epsilon).", None),
    ("episode", "max_steps", "Steps before a time-out.", None),
    ("episode", "reward_min", "End the episode when the summed reward falls to this (R_min). Unset: never.", Some("-50.0")),
    ("episode", "min_goal_distance_px", "Least straight-line distance between a drawn start and goal, px.", None),
    ("episode", "start", "Fixed start pose [x px, y px, heading deg]. Unset: drawn from the seed.", Some("[150.0, 150.0, 0.0]")),
    ("episode", "goal", "Fixed goal [x px, y px]. Unset: drawn from the seed.", Some("[850.0, 850.0]")),
    ("episode", "grid_px", "Cell side of the free-space grid for connected regions and planners, px.", None),
    ("episode", "safety_radius_px", "A step is near a moving obstacle when the gap to one is below this, px. Unset: two robot radii.", Some("10.0")),
    ("episode", "collision_ends", "Any contact (a wall, a moving obstacle, another robot) ends the episode as a collision, as crowd-navigation papers count it (robot.on_collision = \"terminate\" for every robot).", None),
    ("episode", "deadlock_steps", "Several robots: the episode ends as a deadlock when no robot of a team of two or more has moved for this many steps.", None),
    ("team", "comm_range_px", "Several robots: range of each robot's broadcast (pose, goal, message), px.", None),
    ("team", "message_size", "Several robots: floats in the message a policy broadcasts each step (0: pose and goal only).", None),
    ("team", "neighbours", "Several robots: nearest senders in the observation, after the paper's values (0: the paper's observation).", None),
    ("observation", "history", "Frames a policy observes, newest first, then the last history - 1 actions (three values each: LEFT, AHEAD, RIGHT); 1: the paper's 18 values.", None),
    ("reward", "collision", "r_a: added on a step that collided.", None),
    ("reward", "progress_per_px", "r_b: per px of progress towards the goal (negative when moving away).", None),
    ("reward", "turn", "r_c: added on LEFT and RIGHT (scaled by |w| / w_max for continuous actions).", None),
    ("reward", "success", "r_d: added on reaching the goal.", None),
    ("reward", "shaping", "How progress is paid to a learner: \"none\" (r_b, the paper's) or \"geodesic\" (r_b replaced by F = gamma Phi(s') - Phi(s), Phi = -progress_per_px x geodesic distance to the goal, 0 once an episode ends other than by a time-out: keeps the optimal policy, pays nothing for dead ends; episodes.csv keeps the paper's return).", None),
    ("reward", "shaping_gamma", "gamma of the geodesic shaping term; the learner's discount keeps its optimal policy exactly (ronap train dqn sets it to its --gamma unless --shaping-gamma is given).", None),
    ("apf", "gravity_gain", "APF policy: attraction gain xi, per px^2.", None),
    ("apf", "repulsion_gain", "APF policy: repulsion gain eta, px^2.", None),
    ("apf", "influence_px", "APF policy: distance d0 beyond which obstacles do not repel, px.", None),
    ("apf", "lattice_px", "APF policy: spacing of the positions the descent steps between, px.", None),
    ("apf", "repel_moving", "APF policy: also steer away from the moving obstacles within laser range.", None),
    ("orca", "time_horizon_steps", "orca policy: steps over which velocities are kept clear of other agents.", None),
    ("orca", "obstacle_time_horizon_steps", "orca policy: steps over which velocities are kept clear of still obstacles.", None),
    ("orca", "max_neighbours", "orca policy: most agents avoided at once (the nearest).", None),
    ("orca", "speed_px", "orca policy: preferred (and largest) speed, px per step. Unset: the robot's max_linear_speed_px (continuous actions) or move_speed_px (discrete); below max_linear_speed_px, a turning step can still cover it.", Some("4.0")),
    ("orca", "sense_range_px", "orca policy: how far the robot senses other agents (their positions and velocities), px. Unset: the laser's range.", Some("100.0")),
    ("orca", "safety_margin_px", "orca policy: added to the robot's radius in ORCA, px (agents meeting in a crowd at a radius a step can otherwise overlap).", None),
    ("orca", "actions", "orca policy: \"continuous\" ((v, w) tracking the velocity) or \"discrete\" (the action whose result lies closest).", None),
    ("social_force", "speed_px", "social-force policy: preferred (and largest) speed, px per step. Unset: the robot's max_linear_speed_px (continuous actions) or move_speed_px (discrete).", Some("4.0")),
    ("social_force", "sense_range_px", "social-force policy: how far the robot senses other agents, px. Unset: the laser's range.", Some("100.0")),
    ("social_force", "actions", "social-force policy: \"continuous\" ((v, w) tracking the velocity) or \"discrete\" (the action whose result lies closest).", None),
    ("social_force", "forces", "social-force policy: { relaxation_steps (tau, steps), agent_strength_px (A, px/step^2), agent_range_px (B, px), obstacle_strength_px, obstacle_range_px, lambda (weight of an agent behind, 0-1), neighbour_dist_px } (Helbing-Molnar 1995 at 20 px a metre, 4 steps a second).", None),
    ("dwa", "horizon_steps", "dwa policy: steps each sampled command is rolled out for.", None),
    ("dwa", "speed_samples", "dwa policy: linear speeds sampled across the window.", None),
    ("dwa", "turn_samples", "dwa policy: turn rates sampled across the window.", None),
    ("dwa", "linear_accel_px", "dwa policy: largest change of the linear speed in a step, px per step^2 (the window round the last command).", None),
    ("dwa", "angular_accel_deg", "dwa policy: largest change of the turn rate in a step, degrees per step^2.", None),
    ("dwa", "heading_weight", "dwa policy: weight of facing the path's aim at the rollout's end.", None),
    ("dwa", "clearance_weight", "dwa policy: weight of the share of the rollout's steps before its first contact.", None),
    ("dwa", "speed_weight", "dwa policy: weight of the speed (as a fraction of the largest).", None),
    ("dwa", "safety_margin_px", "dwa policy: a rollout step nearer than this to anything sensed (beyond the bodies) is a contact, px.", None),
    ("dwa", "sense_range_px", "dwa policy: how far the robot senses moving agents, px. Unset: the laser's range.", Some("100.0")),
    ("dwa", "actions", "dwa policy: \"continuous\" (sampled (v, w)) or \"discrete\" (LEFT, AHEAD, RIGHT, each taken once then AHEAD).", None),
    ("metrics", "crowd", "Measure the crowd metrics: time_to_goal, intrusion_ratio, min_separation_px, ttc_min, path_irregularity, jerk (columns in episodes.csv or a team's robots.csv, means in summary.json).", None),
    ("metrics", "discomfort_px", "Crowd metrics: a step intrudes when a moving obstacle or another robot is closer than this beyond the two bodies, px.", None),
];

/// Every field of a `[[moving]]` entry and what it means.
const MOVING_DOCS: &[(&str, &str)] = &[
    ("count", "How many obstacles this entry makes."),
    (
        "shape",
        "\"disc\" (radius_px) or \"box\" (size_px, axis-aligned).",
    ),
    ("radius_px", "Disc radius, px."),
    ("size_px", "Box width and height, px."),
    (
        "start",
        "Fixed start of the centre [x, y], px. Unset: drawn in free space from the seed.",
    ),
    (
        "motion",
        "\"still\", \"linear\", \"waypoints\", \"random_walk\", \"appear\", \"orca\" or \"social_force\" (pedestrians with a goal that avoid the others by ORCA, or are pushed by the social force model).",
    ),
    ("speed_px", "Distance moved per step, px."),
    (
        "direction_deg",
        "linear: direction of travel, degrees. Unset: drawn from the seed.",
    ),
    (
        "turn_sigma_deg",
        "random_walk: standard deviation of the heading change per step, degrees.",
    ),
    (
        "points",
        "waypoints: the points patrolled [[x, y], ...], px.",
    ),
    ("mode", "waypoints: \"loop\" or \"ping_pong\"."),
    ("from_step", "appear: earliest step of appearance."),
    ("to_step", "appear: latest step of appearance."),
    (
        "min_robot_distance_px",
        "Least gap to the robot where the obstacle starts or appears, px.",
    ),
    (
        "then",
        "appear: how it moves once there: \"still\", \"linear\" or \"random_walk\".",
    ),
    (
        "goal",
        "orca, social_force: fixed goal [x, y], px. Unset: from the pattern, else drawn in free space.",
    ),
    (
        "max_speed_px",
        "orca, social_force: largest speed, px per step (speed_px is the preferred one). Unset: speed_px.",
    ),
    (
        "on_arrival",
        "orca, social_force: at its goal \"stay\", \"new_goal\" (draw another) or \"vanish\".",
    ),
    (
        "sees_robots",
        "orca, social_force: whether it avoids the robots too (false: CrowdNav's invisible robot).",
    ),
    (
        "pattern",
        "orca, social_force: start and goal by a crowd pattern, \"circle\" (opposite points), \"square\" (opposite sides) or \"random\" (drawn in free space). Unset: drawn.",
    ),
    (
        "pattern_center",
        "The pattern's centre [x, y], px. Unset: the scene's centre.",
    ),
    (
        "pattern_radius_px",
        "The circle's radius, or the square's half side, px.",
    ),
    (
        "jitter_px",
        "A pattern's start and goal move by up to this in x and y, px.",
    ),
    (
        "orca",
        "orca: { time_horizon_steps = 20, obstacle_time_horizon_steps = 20, neighbour_dist_px = 200, max_neighbours = 10, safety_margin_px = 1 } (RVO2's agent settings, in steps and px).",
    ),
    (
        "social_force",
        "social_force: { relaxation_steps = 2, agent_strength_px = 8.75, agent_range_px = 6, obstacle_strength_px = 62.5, obstacle_range_px = 4, lambda = 0.5, neighbour_dist_px = 60 } (Helbing-Molnar 1995 at 20 px a metre, 4 steps a second).",
    ),
];

/// Every field of a `[[crowd]]` entry and what it means.
const CROWD_DOCS: &[(&str, &str)] = &[
    ("count", "How many pedestrians this entry makes."),
    (
        "pattern",
        "\"circle\" (start on a circle, goal at the opposite point), \"square\" (start on one side of a square, goal on the opposite side) or \"random\" (start and goal drawn in free space).",
    ),
    (
        "motion",
        "\"orca\" (avoid the others by ORCA) or \"social_force\" (pushed by the social force model).",
    ),
    ("radius_px", "Disc radius, px."),
    ("speed_px", "Preferred speed, px per step."),
    (
        "max_speed_px",
        "Largest speed, px per step. Unset: speed_px.",
    ),
    (
        "pattern_center",
        "The pattern's centre [x, y], px. Unset: the scene's centre.",
    ),
    (
        "pattern_radius_px",
        "The circle's radius, or the square's half side, px (circle and square need it).",
    ),
    (
        "jitter_px",
        "Starts and goals move by up to this in x and y, px.",
    ),
    (
        "on_arrival",
        "At its goal \"stay\", \"new_goal\" (draw another) or \"vanish\".",
    ),
    (
        "sees_robots",
        "Whether they avoid the robots too (false: CrowdNav's invisible robot).",
    ),
    (
        "min_robot_distance_px",
        "Least gap between a pedestrian's start or goal and the robot's start and goal, px.",
    ),
    (
        "robot_follows",
        "circle, square: the robot starts at the pattern's bottom point (cx, cy - R) heading up and heads for its top point (cx, cy + R), as CrowdNav puts it (leave episode.start and episode.goal unset).",
    ),
    (
        "orca",
        "orca: { time_horizon_steps = 20, obstacle_time_horizon_steps = 20, neighbour_dist_px = 200, max_neighbours = 10, safety_margin_px = 1 }.",
    ),
    (
        "social_force",
        "social_force: { relaxation_steps = 2, agent_strength_px = 8.75, agent_range_px = 6, obstacle_strength_px = 62.5, obstacle_range_px = 4, lambda = 0.5, neighbour_dist_px = 60 }.",
    ),
];

/// Every field of a `[[robots]]` entry and what it means.
const ROBOTS_DOCS: &[(&str, &str)] = &[
    ("count", "How many robots this entry makes."),
    (
        "start",
        "Fixed start pose [x px, y px, heading deg] (count 1). Unset: drawn from the seed.",
    ),
    (
        "goal",
        "Fixed goal [x, y], px (count 1). Unset: drawn from the seed.",
    ),
    (
        "policy",
        "The policy that drives them (any --policy name). Unset: the run's.",
    ),
    ("radius_px", "Disc radius, px. Unset: robot.radius_px."),
    (
        "move_speed_px",
        "Distance of one AHEAD step, px. Unset: robot.move_speed_px.",
    ),
    (
        "turn_speed_deg",
        "Heading change of LEFT / RIGHT, degrees. Unset: robot.turn_speed_deg.",
    ),
    ("laser_beams", "Laser beams. Unset: laser.beams."),
    ("laser_range_px", "Laser range, px. Unset: laser.range_px."),
    (
        "laser_fov_deg",
        "Laser field of view, degrees. Unset: laser.fov_deg.",
    ),
    (
        "on_arrival",
        "On reaching the (last) goal: \"stay\" (an obstacle there) or \"vanish\" (leave the scene).",
    ),
    (
        "goals",
        "Fixed goals [[x, y], ...] visited one after the other (count 1). Unset: goal_count drawn.",
    ),
    ("goal_count", "Goals drawn from the seed, visited one after the other."),
    (
        "order",
        "Visiting order: \"given\", \"nearest\" (greedy, geodesic) or \"optimal\" (shortest tour).",
    ),
    (
        "jitter_px",
        "Moves the fixed start and goal by up to this much in x and y, px (uniform, from the seed's own stream). Unset: 0.",
    ),
];

fn commented(block: &str) -> String {
    block.lines().map(|l| format!("# {l}\n")).collect()
}

impl SimConfig {
    /// The configuration as TOML with a comment on every field (meaning and unit), ready to copy
    /// and edit. Unset optional fields appear commented out with an example value; with no static
    /// or moving obstacles, an example of each appears commented out.
    pub fn to_documented_toml(&self) -> String {
        let mut out = String::from(
            "# ronap scenario: everything about a task (scene, robot, laser, episode, reward, static\n\
             # and moving obstacles). Pass it with --scenario FILE.toml (flags override it), or to\n\
             # ronap.NavEnv(scenario=...). Units: px (scene pixels, x right, y up) and degrees\n\
             # (counter-clockwise from +x).\n",
        );
        let mut value =
            toml::Value::try_from(self).unwrap_or(toml::Value::Table(Default::default()));
        // [team] is left out of written configurations when it has its defaults: show them here.
        if let (Some(table), Ok(team)) = (value.as_table_mut(), toml::Value::try_from(&self.team)) {
            table.entry("team").or_insert(team);
        }
        // So are [observation], [orca], [social_force], [dwa], [metrics] and reward shaping.
        if let (Some(table), Ok(metrics)) =
            (value.as_table_mut(), toml::Value::try_from(&self.metrics))
        {
            table.entry("metrics").or_insert(metrics);
        }
        if let (Some(table), Ok(orca)) = (value.as_table_mut(), toml::Value::try_from(&self.orca)) {
            table.entry("orca").or_insert(orca);
        }
        if let (Some(table), Ok(sf)) = (
            value.as_table_mut(),
            toml::Value::try_from(&self.social_force),
        ) {
            table.entry("social_force").or_insert(sf);
        }
        if let (Some(table), Ok(dwa)) = (value.as_table_mut(), toml::Value::try_from(&self.dwa)) {
            table.entry("dwa").or_insert(dwa);
        }
        if let (Some(table), Ok(observation)) = (
            value.as_table_mut(),
            toml::Value::try_from(&self.observation),
        ) {
            table.entry("observation").or_insert(observation);
        }
        if let Some(episode) = value.get_mut("episode").and_then(|r| r.as_table_mut()) {
            episode
                .entry("collision_ends")
                .or_insert(toml::Value::Boolean(self.episode.collision_ends));
        }
        if let Some(reward) = value.get_mut("reward").and_then(|r| r.as_table_mut()) {
            if let Ok(kind) = toml::Value::try_from(self.reward.shaping) {
                reward.entry("shaping").or_insert(kind);
            }
            reward
                .entry("shaping_gamma")
                .or_insert(toml::Value::Float(self.reward.shaping_gamma));
        }
        let mut section = "";
        for &(sec, field, doc, example) in FIELD_DOCS {
            if sec != section {
                out.push_str(&format!("\n[{sec}]\n"));
                section = sec;
            }
            out.push_str(&format!("# {doc}\n"));
            match value.get(sec).and_then(|s| s.get(field)) {
                Some(v) => out.push_str(&format!("{field} = {v}\n")),
                None => out.push_str(&format!("# {field} = {}\n", example.unwrap_or("..."))),
            }
        }
        out.push_str(
            "\n# Static obstacles added to the scene, any number: shape = \"box\" (min, max corners),\n\
             # \"disc\" (center, radius_px) or \"polygon\" (points: the corners of a convex polygon).\n",
        );
        let obstacles = value.get("obstacles").and_then(|v| v.as_array());
        match obstacles.filter(|a| !a.is_empty()) {
            Some(list) => {
                for o in list {
                    out.push_str("[[obstacles]]\n");
                    out.push_str(&inline_fields(o));
                }
            }
            None => out.push_str(&commented(
                "[[obstacles]]\nshape = \"disc\"\ncenter = [500.0, 500.0]\nradius_px = 20.0\n",
            )),
        }
        out.push_str(
            "\n# Moving obstacles, any number of entries; each makes `count` obstacles alike. They\n\
             # move first in each step, then the robot; contact either way is a dynamic collision.\n",
        );
        let moving = value.get("moving").and_then(|v| v.as_array());
        match moving.filter(|a| !a.is_empty()) {
            Some(list) => {
                for m in list {
                    out.push_str("[[moving]]\n");
                    for &(field, doc) in MOVING_DOCS {
                        out.push_str(&format!("# {doc}\n"));
                        match m.get(field) {
                            Some(v) => out.push_str(&format!("{field} = {v}\n")),
                            None => out.push_str(&format!("# {field} = ...\n")),
                        }
                    }
                }
            }
            None => out.push_str(&commented(
                "[[moving]]\ncount = 5\nshape = \"disc\"\nradius_px = 8.0\nmotion = \"random_walk\"\nspeed_px = 2.0\n",
            )),
        }
        out.push_str(
            "\n# Crowds of reactive pedestrians, any number of entries; each makes `count` pedestrians\n\
             # placed by a pattern (after the [[moving]] entries' obstacles, from their random stream).\n",
        );
        let crowds = value.get("crowd").and_then(|v| v.as_array());
        match crowds.filter(|a| !a.is_empty()) {
            Some(list) => {
                for c in list {
                    out.push_str("[[crowd]]\n");
                    for &(field, doc) in CROWD_DOCS {
                        out.push_str(&format!("# {doc}\n"));
                        match c.get(field) {
                            Some(v) => out.push_str(&format!("{field} = {v}\n")),
                            None => out.push_str(&format!("# {field} = ...\n")),
                        }
                    }
                }
            }
            None => out.push_str(&commented(
                "[[crowd]]\ncount = 5\npattern = \"circle\"\npattern_radius_px = 80.0\nmotion = \"orca\"\nspeed_px = 2.0\n",
            )),
        }
        out.push_str(
            "\n# Several robots, any number of entries; each makes `count` robots alike, and a field\n\
             # left out takes [robot]'s, [laser]'s or [episode]'s value. All robots act at once;\n\
             # robots whose motions would touch stay where they were (a robot collision).\n",
        );
        let robots = value.get("robots").and_then(|v| v.as_array());
        match robots.filter(|a| !a.is_empty()) {
            Some(list) => {
                for r in list {
                    out.push_str("[[robots]]\n");
                    for &(field, doc) in ROBOTS_DOCS {
                        out.push_str(&format!("# {doc}\n"));
                        match r.get(field) {
                            Some(v) => out.push_str(&format!("{field} = {v}\n")),
                            None => out.push_str(&format!("# {field} = ...\n")),
                        }
                    }
                }
            }
            None => out.push_str(&commented(
                "[[robots]]\ncount = 4\npolicy = \"geodesic\"\non_arrival = \"stay\"\n",
            )),
        }
        out
    }

    /// A scenario that shows every kind of entry: the default maze with a pillar, a rotated
    /// shelf, crossing walkers, a patrol, a linear mover and obstacles that appear mid-episode.
    pub fn example_scenario() -> Self {
        let obstacles = vec![
            ObstacleConfig::Disc {
                center: [450.0, 450.0],
                radius_px: 12.0,
            },
            ObstacleConfig::Polygon {
                points: vec![
                    [620.0, 300.0],
                    [660.0, 320.0],
                    [650.0, 340.0],
                    [610.0, 320.0],
                ],
            },
        ];
        let moving = vec![
            MovingConfig {
                count: 4,
                ..MovingConfig::default()
            },
            MovingConfig {
                shape: MovingShape::Box,
                motion: MotionKind::Waypoints,
                points: vec![[150.0, 850.0], [850.0, 850.0]],
                mode: Patrol::PingPong,
                speed_px: 3.0,
                ..MovingConfig::default()
            },
            MovingConfig {
                motion: MotionKind::Linear,
                direction_deg: Some(45.0),
                ..MovingConfig::default()
            },
            MovingConfig {
                count: 2,
                motion: MotionKind::Appear,
                from_step: 20,
                to_step: 100,
                ..MovingConfig::default()
            },
        ];
        Self {
            obstacles,
            moving,
            ..Self::default()
        }
    }
}

/// The fields of one array-of-tables entry as `key = value` lines.
fn inline_fields(entry: &toml::Value) -> String {
    entry
        .as_table()
        .map(|t| t.iter().map(|(k, v)| format!("{k} = {v}\n")).collect())
        .unwrap_or_default()
}

#[cfg(test)]
mod documented_tests {
    use super::*;
    use crate::config::Shaping;

    #[test]
    fn every_field_is_documented_and_the_text_reads_back() {
        let mut c = SimConfig::default();
        c.episode.goal = Some([1.0, 2.0]);
        let text = c.to_documented_toml();
        assert_eq!(SimConfig::from_toml_str(&text).unwrap(), c);
        assert!(text.contains("# start = [150.0, 150.0, 0.0]"));
        assert!(text.contains("goal = [1.0, 2.0]"));
        // Every serialised field (and every optional one) has a line of its own.
        c.episode.reward_min = Some(-1.0);
        c.episode.start = Some([0.0; 3]);
        c.episode.safety_radius_px = Some(3.0);
        c.episode.collision_ends = true;
        c.scene.seed = Some(1);
        c.scene.file = Some("m.png".into());
        c.team.neighbours = 1;
        c.observation.history = 2;
        c.reward.shaping = Shaping::Geodesic;
        c.reward.shaping_gamma = 0.9;
        c.metrics.crowd = true;
        c.orca.sense_range_px = Some(50.0);
        c.orca.speed_px = Some(4.0);
        c.social_force.sense_range_px = Some(50.0);
        c.social_force.speed_px = Some(4.0);
        c.dwa.sense_range_px = Some(50.0);
        c.robot.shape = crate::config::Shape::Rectangle;
        c.robot.length_px = Some(20.0);
        c.robot.width_px = Some(10.0);
        c.robot.offset_px = Some(1.0);
        c.robot.vertices = vec![[10.0, 0.0], [-6.0, 6.0], [-6.0, -6.0]];
        c.robot.kinematics = crate::config::KinematicsKind::Omni;
        c.robot.accel_max_px = Some(1.0);
        c.robot.alpha_max_deg = Some(5.0);
        c.robot.wheel_base_px = Some(8.0);
        c.robot.max_lateral_speed_px = Some(3.0);
        c.robot.steer_max_deg = Some(40.0);
        c.robot.steer_rate_max_deg = Some(15.0);
        c.robot.motion_noise_px = 0.1;
        c.robot.motion_noise_deg = 0.5;
        c.robot.goal_noise_deg = 2.0;
        c.robot.goal_noise_px = 5.0;
        c.laser.dropout = 0.05;
        c.laser.angle_jitter_deg = 1.0;
        let full = toml::Value::try_from(&c).unwrap();
        let mut count = 0;
        for (sec, table) in full.as_table().unwrap() {
            let Some(table) = table.as_table() else {
                continue;
            };
            for field in table.keys() {
                assert!(
                    FIELD_DOCS.iter().any(|(s, f, _, _)| s == sec && f == field),
                    "{sec}.{field} has no documentation"
                );
                count += 1;
            }
        }
        assert_eq!(count, FIELD_DOCS.len());
    }

    #[test]
    fn every_crowd_field_is_documented_and_reads_back() {
        let crowd = crate::config::CrowdConfig {
            max_speed_px: Some(3.0),
            pattern_center: Some([1.0, 2.0]),
            pattern_radius_px: 5.0,
            jitter_px: 1.0,
            robot_follows: true,
            orca: crate::config::AgentOrca {
                max_neighbours: 3,
                ..Default::default()
            },
            social_force: crate::config::Forces {
                lambda: 0.2,
                ..Default::default()
            },
            ..Default::default()
        };
        let full = toml::Value::try_from(&crowd).unwrap();
        let keys: Vec<_> = full.as_table().unwrap().keys().cloned().collect();
        let documented: Vec<_> = CROWD_DOCS.iter().map(|(f, _)| f.to_string()).collect();
        let mut sorted = documented.clone();
        sorted.sort();
        assert_eq!(keys, sorted);
        let c = SimConfig {
            crowd: vec![crowd],
            ..SimConfig::default()
        };
        let text = c.to_documented_toml();
        assert_eq!(SimConfig::from_toml_str(&text).unwrap(), c);
        assert!(SimConfig::default()
            .to_documented_toml()
            .contains("# [[crowd]]\n"));
    }
}
