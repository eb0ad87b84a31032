//! Pictures of episodes, lone or team, running or finished (like the paper's Figures 7-9): the
//! whole scene with each robot's path, start, goal and body, and the moving obstacles. A lone
//! robot's picture is its team of one's: a team's robots are drawn as the lone robot is, each in
//! its own colour.

use crate::config::RobotConfig;
use crate::eval::{EpisodeRecord, RobotLook, TeamRecord};
use crate::geometry::Point;
use crate::render::chart::policy_colour;
use crate::render::{Canvas, GOAL, MOVER, PATH, START};
use crate::sim::{Episode, Laser, Movers, Pose, Track};
use crate::Scene;
use image::{Rgb, RgbImage};

/// `colour` mixed half-way with white, for goals.
pub(crate) fn faded(colour: Rgb<u8>) -> Rgb<u8> {
    Rgb(colour.0.map(|c| ((u16::from(c) + 255) / 2) as u8))
}

/// A robot as an episode's picture draws it.
pub(crate) struct Drawn<'a> {
    pub body: &'a RobotConfig,
    pub start: Pose,
    /// Where it is (or ended).
    pub pose: Pose,
    pub goal: Point,
    pub goal_tolerance_px: f64,
    /// Its centre at every step.
    pub path: &'a [Point],
    /// Its laser and last readings.
    pub scan: (&'a Laser, &'a [f64]),
    /// Whether it is in the scene: a robot taken out is drawn without its body, and without its
    /// goal when it arrived there.
    pub present: bool,
    /// Whether it reached its (last) goal.
    pub arrived: bool,
    /// Its path and body, its start, and its goal.
    pub colours: [Rgb<u8>; 3],
}

impl<'a> Drawn<'a> {
    /// Robot `k` of `n`, its `episode` running, as it stands: in the scene, with its path so far
    /// and its current scan, in [`Drawn::colours`].
    pub(crate) fn running(episode: &'a Episode, path: &'a [Point], k: usize, n: usize) -> Self {
        Self {
            body: &episode.config().robot,
            start: episode.start(),
            pose: episode.pose(),
            goal: episode.goal(),
            goal_tolerance_px: episode.config().episode.goal_tolerance_px,
            path,
            scan: (episode.laser(), episode.readings()),
            present: true,
            arrived: episode.status() == crate::sim::Status::Success,
            colours: Self::colours(k, n),
        }
    }

    /// Robot `k`'s colours among `n` robots: a lone robot's path, start and goal colours for a
    /// team of one, else its own colour, faded for its start and goal.
    pub(crate) fn colours(k: usize, n: usize) -> [Rgb<u8>; 3] {
        match n {
            1 => [PATH, START, GOAL],
            _ => [
                policy_colour(k),
                faded(policy_colour(k)),
                faded(policy_colour(k)),
            ],
        }
    }
}

/// The moving obstacles of a picture.
pub(crate) enum Obstacles<'a> {
    /// As they are now, in a running episode.
    Live(Option<&'a Movers>),
    /// Their tracks over a finished episode, each drawn where it ended.
    Tracks(&'a [Track]),
}

/// The picture of `robots` in `scene`: each goal as a disc of its tolerance, a finished
/// episode's obstacle tracks (faded, each obstacle where it ended), each path (2 px), the
/// obstacles as they are in a running one, the last laser scan in its colour classes when there
/// is one robot (a team's scans would hide its paths), each start and each robot in the scene,
/// as its body.
pub(crate) fn episode_image(
    scene: &Scene,
    robots: &[Drawn<'_>],
    obstacles: Obstacles<'_>,
    scale: f64,
) -> RgbImage {
    let mut canvas = Canvas::new(scene, scale);
    let least = 4.0 / scale;
    for r in robots.iter().filter(|r| r.present || !r.arrived) {
        canvas.fill_disc(r.goal, r.goal_tolerance_px.max(least), r.colours[2]);
    }
    if let Obstacles::Tracks(tracks) = obstacles {
        canvas.tracks(tracks);
        for track in tracks {
            if let Some(last) = track.last() {
                canvas.mover(track.body, last, MOVER);
            }
        }
    }
    for r in robots {
        canvas.path(r.path, 2.0, r.colours[0]);
    }
    if let Obstacles::Live(Some(movers)) = obstacles {
        canvas.movers(movers);
    }
    if let [r] = robots {
        canvas.scan(r.scan.0, r.pose, r.scan.1);
    }
    for r in robots {
        canvas.body(r.start, r.body, least, r.colours[1]);
    }
    for r in robots.iter().filter(|r| r.present) {
        canvas.body(r.pose, r.body, least, r.colours[0]);
    }
    canvas.into_image()
}

/// The picture of a lone robot's episode: its path in blue, its start in red, its goal in green.
/// Needs the record's trajectory and world (`None` once the record is stripped).
pub fn trajectory_image(record: &EpisodeRecord, scale: f64) -> Option<RgbImage> {
    let world = record.world.as_ref()?;
    let config = world.config();
    let laser = Laser::new(&config.laser);
    let look = RobotLook {
        body: config.robot.clone(),
        laser,
        goal_tolerance_px: config.episode.goal_tolerance_px,
    };
    let tracks = Obstacles::Tracks(&record.mover_tracks);
    Some(finished_image(
        world.scene(),
        &[(record, &look)],
        tracks,
        scale,
    ))
}

/// The picture of a team episode: robot `k` in the colour of
/// [`crate::render::chart::policy_colour`]`(k)`, its start and goal faded; a team of one in the
/// lone robot's colours, so its picture is the lone robot's. Needs the robots' trajectories and
/// the record's picture (`None` once they are dropped).
pub fn team_image(record: &TeamRecord, scale: f64) -> Option<RgbImage> {
    let picture = record.picture.as_ref()?;
    let robots: Vec<_> = record.robots.iter().zip(&picture.robots).collect();
    let tracks = Obstacles::Tracks(&picture.mover_tracks);
    Some(finished_image(&picture.scene, &robots, tracks, scale))
}

/// The picture of finished episodes' `robots` (each robot's record and how it looks) in `scene`:
/// robot `k` of `n` in [`Drawn::colours`], each with its trajectory and last scan.
fn finished_image(
    scene: &Scene,
    robots: &[(&EpisodeRecord, &RobotLook)],
    obstacles: Obstacles<'_>,
    scale: f64,
) -> RgbImage {
    let paths: Vec<Vec<Point>> = robots
        .iter()
        .map(|(r, _)| r.trajectory.iter().map(|p| p.position()).collect())
        .collect();
    let n = robots.len();
    let drawn: Vec<Drawn<'_>> = robots
        .iter()
        .zip(&paths)
        .enumerate()
        .map(|(k, ((r, look), path))| Drawn {
            body: &look.body,
            start: r.start,
            pose: r.end,
            goal: r.goal,
            goal_tolerance_px: look.goal_tolerance_px,
            path,
            scan: (&look.laser, &r.last_readings),
            present: true,
            arrived: false,
            colours: Drawn::colours(k, n),
        })
        .collect();
    episode_image(scene, &drawn, obstacles, scale)
}
