//! Trajectory pictures like the paper's Figures 7-9: a finished episode over its whole scene.

use crate::eval::EpisodeRecord;
use crate::render::{Canvas, GOAL, MOVER, PATH, START};
use crate::sim::Laser;

/// The picture of an episode: the whole scene, the path in blue, the start in red, the goal in
/// green, the last laser scan in its colour classes, and moving obstacles' tracks faded with each
/// obstacle where it was at the end. Needs the record's trajectory and world
/// (`None` once the record is stripped).
pub fn trajectory_image(record: &EpisodeRecord, scale: f64) -> Option<image::RgbImage> {
    let world = record.world.as_ref()?;
    let config = world.config();
    let mut canvas = Canvas::new(world.scene(), scale);
    let least = 4.0 / scale;
    canvas.fill_disc(
        record.goal,
        config.episode.goal_tolerance_px.max(least),
        GOAL,
    );
    let points: Vec<_> = record.trajectory.iter().map(|p| p.position()).collect();
    canvas.tracks(&record.mover_tracks);
    for track in &record.mover_tracks {
        if let Some(last) = track.last() {
            canvas.mover(track.body, last, MOVER);
        }
    }
    canvas.path(&points, 2.0, PATH);
    let laser = Laser::new(&config.laser);
    canvas.scan(&laser, record.end, &record.last_readings);
    canvas.body(record.start, &config.robot, least, START);
    canvas.body(record.end, &config.robot, least, PATH);
    Some(canvas.into_image())
}
