//! Pictures of team episodes: the whole scene with every robot's path, start and goal in its own
//! colour (the colours of [`crate::render::chart::policy_colour`], repeating after ten).

use crate::eval::TeamRecord;
use crate::render::chart::policy_colour;
use crate::render::Canvas;
use image::{Rgb, RgbImage};

/// `colour` mixed half-way with white, for goals.
fn faded(colour: Rgb<u8>) -> Rgb<u8> {
    Rgb(colour.0.map(|c| ((u16::from(c) + 255) / 2) as u8))
}

/// The picture of a team episode: each robot's path (2 px), its goal as a faded disc of the goal
/// tolerance, its start as a ring and where it ended as a disc. Needs the record's paths and
/// scene (`None` once they are dropped).
pub fn team_image(record: &TeamRecord, scale: f64) -> Option<RgbImage> {
    let scene = record.scene.as_ref()?;
    let mut canvas = Canvas::new(scene, scale);
    let least = 3.0 / scale;
    for (k, r) in record.robots.iter().enumerate() {
        canvas.fill_disc(r.goal, (10.0f64).max(least), faded(policy_colour(k)));
    }
    for (k, path) in record.paths.iter().enumerate() {
        canvas.path(path, 2.0, policy_colour(k));
    }
    for (k, r) in record.robots.iter().enumerate() {
        let colour = policy_colour(k);
        let radius = 5.0f64.max(least);
        // The start as a ring, the end as a disc.
        canvas.fill_disc(r.start.position(), radius * 1.2, colour);
        canvas.fill_disc(r.start.position(), radius * 0.6, Rgb([255, 255, 255]));
        if let Some(last) = record.paths.get(k).and_then(|p| p.last()) {
            canvas.fill_disc(*last, radius, colour);
        }
    }
    Some(canvas.into_image())
}

/// The picture of a team episode as it stands: each robot's goal as a faded disc of the goal
/// tolerance, its path so far (`paths[k]`) and, while it is in the scene, the robot with its
/// heading, all in its own colour; moving obstacles as they are now.
pub fn team_frame(
    team: &crate::sim::team::Team,
    paths: &[Vec<crate::geometry::Point>],
    scale: f64,
) -> RgbImage {
    let first = team.robot(0);
    let mut canvas = Canvas::new(first.scene(), scale);
    let least = 3.0 / scale;
    for (k, r) in team.robots().iter().enumerate() {
        if !team.present(k) && r.status() == crate::sim::episode::Status::Success {
            continue;
        }
        let tolerance = r.config().episode.goal_tolerance_px;
        canvas.fill_disc(r.goal(), tolerance.max(least), faded(policy_colour(k)));
    }
    for (k, path) in paths.iter().enumerate() {
        canvas.path(path, 2.0, policy_colour(k));
    }
    if let Some(movers) = team.movers() {
        canvas.movers(movers);
    }
    for (k, r) in team.robots().iter().enumerate() {
        if team.present(k) {
            let radius = r.config().robot.radius_px.max(least);
            canvas.robot(r.pose(), radius, policy_colour(k));
        }
    }
    canvas.into_image()
}
