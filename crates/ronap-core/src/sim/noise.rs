//! A robot's noise beyond the laser's range noise (docs/model.md "Noise"): motion noise on the
//! executed velocity, goal-sensing noise on the goal's bearing and distance, and the laser's
//! beam dropout and angle jitter. Each draws from its own random stream of the episode's seed
//! (a team's robot from its own), so turning one on changes nothing else; all off, an episode
//! holds none of it and steps as before, bit for bit.

use crate::config::{LaserConfig, RobotConfig};
use crate::sim::kinematics::{Kinematics, Velocity};
use crate::sim::rng::{robot_stream, Rng, Stream};
use rand::Rng as _;
use rand_distr::{Distribution, StandardNormal};

/// The noise of one robot, with its streams.
#[derive(Clone, Debug)]
pub struct RobotNoise {
    /// Standard deviations on the executed speeds (px) and turn rate (degrees), and the stream.
    motion: Option<(f64, f64, Rng)>,
    /// Standard deviations on the sensed goal bearing (degrees) and distance (px), and the
    /// stream.
    goal: Option<(f64, f64, Rng)>,
    /// The probability that a beam returns nothing, and the stream.
    dropout: Option<(f64, Rng)>,
    /// The standard deviation of each beam's angle, degrees, and the stream.
    jitter: Option<(f64, Rng)>,
    /// The last scan's beam-angle offsets, degrees.
    angles: Vec<f64>,
    /// The goal's bearing and distance as last sensed.
    last_goal: Option<(f64, f64)>,
}

/// A normal draw of standard deviation `sigma`.
fn normal(sigma: f64, rng: &mut Rng) -> f64 {
    let z: f64 = StandardNormal.sample(rng);
    sigma * z
}

impl RobotNoise {
    /// The noise of robot `k` (0 for a lone robot) of the episode with `seed`; `None` when the
    /// configuration has none.
    pub fn new(robot: &RobotConfig, laser: &LaserConfig, seed: u64, k: usize) -> Option<Self> {
        let motion = (robot.motion_noise_px > 0.0 || robot.motion_noise_deg > 0.0).then(|| {
            (
                robot.motion_noise_px,
                robot.motion_noise_deg,
                robot_stream(seed, Stream::Motion, k),
            )
        });
        let goal = (robot.goal_noise_deg > 0.0 || robot.goal_noise_px > 0.0).then(|| {
            (
                robot.goal_noise_deg,
                robot.goal_noise_px,
                robot_stream(seed, Stream::GoalSense, k),
            )
        });
        let dropout =
            (laser.dropout > 0.0).then(|| (laser.dropout, robot_stream(seed, Stream::Dropout, k)));
        let jitter = (laser.angle_jitter_deg > 0.0).then(|| {
            (
                laser.angle_jitter_deg,
                robot_stream(seed, Stream::BeamJitter, k),
            )
        });
        let any = motion.is_some() || goal.is_some() || dropout.is_some() || jitter.is_some();
        any.then_some(Self {
            motion,
            goal,
            dropout,
            jitter,
            angles: Vec::new(),
            last_goal: None,
        })
    }

    /// `velocity` as executed: each speed and the turn rate off by a normal draw, then brought
    /// back within the body's limits.
    pub fn executed(&mut self, kinematics: &dyn Kinematics, velocity: Velocity) -> Velocity {
        let Some((px, deg, rng)) = &mut self.motion else {
            return velocity;
        };
        let mut noisy = velocity;
        noisy.v += normal(*px, rng);
        if velocity.vy != 0.0 {
            noisy.vy += normal(*px, rng);
        }
        noisy.w_deg += normal(*deg, rng);
        kinematics.clamp(noisy)
    }

    /// Whether the goal is sensed with noise.
    pub fn senses_goal(&self) -> bool {
        self.goal.is_some()
    }

    /// The goal's bearing (degrees) and distance (px) as sensed from the true ones, kept as
    /// [`RobotNoise::last_goal`].
    pub fn sense_goal(&mut self, bearing_deg: f64, distance_px: f64) -> (f64, f64) {
        let sensed = match &mut self.goal {
            Some((deg, px, rng)) => {
                let b = bearing_deg + normal(*deg, rng);
                let d = (distance_px + normal(*px, rng)).max(0.0);
                (crate::geometry::wrap_deg(b), d)
            }
            None => (bearing_deg, distance_px),
        };
        self.last_goal = Some(sensed);
        sensed
    }

    /// The goal's bearing and distance as last sensed with noise (`None` without goal noise).
    pub fn last_goal(&self) -> Option<(f64, f64)> {
        self.goal.as_ref().and(self.last_goal)
    }

    /// Each beam's angle offset for the next scan, degrees (`None` without jitter).
    pub fn jitter(&mut self, beams: usize) -> Option<&[f64]> {
        let (deg, rng) = self.jitter.as_mut()?;
        self.angles.clear();
        for _ in 0..beams {
            self.angles.push(normal(*deg, rng));
        }
        Some(&self.angles)
    }

    /// Sets each beam that returns nothing this scan to `range_px`.
    pub fn drop_out(&mut self, readings: &mut [f64], range_px: f64) {
        if let Some((p, rng)) = &mut self.dropout {
            for r in readings {
                if rng.random_bool(*p) {
                    *r = range_px;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::sim::robot::DiscreteAction;
    use crate::sim::world::{maze_scene, World};
    use crate::SimConfig;
    use std::sync::Arc;

    /// The poses and observations of `steps` steps of the episode of `seed` under `edit`.
    fn run(edit: impl Fn(&mut SimConfig), seed: u64, steps: usize) -> (Vec<[f64; 3]>, Vec<f32>) {
        let mut c = SimConfig::default();
        edit(&mut c);
        let valid = c.validate().expect("valid");
        let world = World::new(valid.clone(), Arc::new(maze_scene(&valid, seed)));
        let mut e = world.episode(seed).expect("an episode");
        let (mut poses, mut obs) = (Vec::new(), Vec::new());
        for i in 0..steps {
            let a = DiscreteAction::ALL[i * 7 % 5 % 3];
            let r = e.step(a);
            poses.push([r.pose.x, r.pose.y, r.pose.z_deg]);
            obs.extend_from_slice(r.observation);
        }
        (poses, obs)
    }

    #[test]
    fn each_noise_is_its_own_stream_and_repeats_for_its_seed() {
        let all = |c: &mut SimConfig| {
            c.robot.motion_noise_px = 0.3;
            c.robot.motion_noise_deg = 2.0;
            c.robot.goal_noise_deg = 5.0;
            c.laser.dropout = 0.1;
            c.laser.angle_jitter_deg = 1.0;
        };
        assert_eq!(run(all, 4, 200), run(all, 4, 200));
        let plain = run(|_| {}, 4, 200);
        // Goal noise and beam noise leave the motion alone; motion noise moves the robot.
        let sensing = run(
            |c| {
                c.robot.goal_noise_deg = 5.0;
                c.laser.dropout = 0.1;
                c.laser.angle_jitter_deg = 1.0;
            },
            4,
            200,
        );
        assert_eq!(sensing.0, plain.0);
        assert_ne!(sensing.1, plain.1);
        let moved = run(|c| c.robot.motion_noise_px = 0.3, 4, 200);
        assert_ne!(moved.0, plain.0);
        // Each stream alone: goal noise on top of dropout changes only the goal direction.
        let dropout = run(|c| c.laser.dropout = 0.1, 4, 50);
        let both = run(
            |c| {
                c.laser.dropout = 0.1;
                c.robot.goal_noise_deg = 5.0;
            },
            4,
            50,
        );
        let frame = 18;
        for (a, b) in dropout.1.chunks(frame).zip(both.1.chunks(frame)) {
            assert_eq!(a[..17], b[..17]);
        }
        // Every beam dropped reads the full range.
        let gone = run(|c| c.laser.dropout = 1.0, 4, 5);
        for f in gone.1.chunks(frame) {
            assert!(f[..17].iter().all(|&x| x == 1.0));
        }
    }
}
