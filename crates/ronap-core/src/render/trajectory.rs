//! Pictures of finished episodes like the paper's Figures 7-9: the whole scene with each robot's
//! path, start, goal and end, and moving obstacles' tracks. A lone robot's picture is its team
//! of one's: a team's robots are drawn as the lone robot is, each in its own colour.

use crate::config::RobotConfig;
use crate::eval::{EpisodeRecord, TeamRecord};
use crate::geometry::Point;
use crate::render::chart::policy_colour;
use crate::render::team::faded;
use crate::render::{Canvas, GOAL, MOVER, PATH, START};
use crate::sim::{Laser, Pose, Track};
use crate::Scene;
use image::{Rgb, RgbImage};

/// A robot of a finished episode as its picture draws it.
struct Drawn<'a> {
    body: &'a RobotConfig,
    start: Pose,
    end: Pose,
    goal: Point,
    goal_tolerance_px: f64,
    /// Its centre at every step.
    path: &'a [Point],
    /// Its laser and last readings.
    scan: (&'a Laser, &'a [f64]),
    /// Its path and end, its start, and its goal.
    colours: [Rgb<u8>; 3],
}

/// The picture of robots' finished episodes in `scene`: each goal as a disc of its tolerance,
/// moving obstacles' `tracks` faded with each obstacle where it was at the end, each path (2 px),
/// the last laser scan in its colour classes when there is one robot (a team's scans would hide
/// its paths), each start and where each robot ended, as its body.
fn episode_image(scene: &Scene, robots: &[Drawn<'_>], tracks: &[Track], scale: f64) -> RgbImage {
    let mut canvas = Canvas::new(scene, scale);
    let least = 4.0 / scale;
    for r in robots {
        canvas.fill_disc(r.goal, r.goal_tolerance_px.max(least), r.colours[2]);
    }
    canvas.tracks(tracks);
    for track in tracks {
        if let Some(last) = track.last() {
            canvas.mover(track.body, last, MOVER);
        }
    }
    for r in robots {
        canvas.path(r.path, 2.0, r.colours[0]);
    }
    if let [r] = robots {
        canvas.scan(r.scan.0, r.end, r.scan.1);
    }
    for r in robots {
        canvas.body(r.start, r.body, least, r.colours[1]);
    }
    for r in robots {
        canvas.body(r.end, r.body, least, r.colours[0]);
    }
    canvas.into_image()
}

/// The picture of a lone robot's episode: its path in blue, its start in red, its goal in green.
/// Needs the record's trajectory and world (`None` once the record is stripped).
pub fn trajectory_image(record: &EpisodeRecord, scale: f64) -> Option<RgbImage> {
    let world = record.world.as_ref()?;
    let config = world.config();
    let path: Vec<_> = record.trajectory.iter().map(|p| p.position()).collect();
    let laser = Laser::new(&config.laser);
    let robot = Drawn {
        body: &config.robot,
        start: record.start,
        end: record.end,
        goal: record.goal,
        goal_tolerance_px: config.episode.goal_tolerance_px,
        path: &path,
        scan: (&laser, &record.last_readings),
        colours: [PATH, START, GOAL],
    };
    Some(episode_image(
        world.scene(),
        &[robot],
        &record.mover_tracks,
        scale,
    ))
}

/// The picture of a team episode: robot `k` in the colour of
/// [`crate::render::chart::policy_colour`]`(k)`, its start and goal faded; a team of one in the
/// lone robot's colours, so its picture is the lone robot's. Needs the record's paths and picture
/// (`None` once they are dropped).
pub fn team_image(record: &TeamRecord, scale: f64) -> Option<RgbImage> {
    let picture = record.picture.as_ref()?;
    let robots: Vec<Drawn<'_>> = record
        .robots
        .iter()
        .zip(&picture.robots)
        .enumerate()
        .map(|(k, (r, look))| Drawn {
            body: &look.body,
            start: r.start,
            end: r.end,
            goal: r.goal,
            goal_tolerance_px: look.goal_tolerance_px,
            path: record.paths.get(k).map_or(&[][..], Vec::as_slice),
            scan: (&look.laser, &look.last_readings),
            colours: match record.robots.len() {
                1 => [PATH, START, GOAL],
                _ => [
                    policy_colour(k),
                    faded(policy_colour(k)),
                    faded(policy_colour(k)),
                ],
            },
        })
        .collect();
    Some(episode_image(
        &picture.scene,
        &robots,
        &picture.mover_tracks,
        scale,
    ))
}
