//! Seeing what the still scene does not have: laser beams that read an obstacle nearer than the
//! scene's walls would give (a moving or appeared obstacle), for the policies that give way to it.

use crate::sim::Episode;

/// A reading shorter than the still scene's by more than this (plus three noise deviations) is
/// an obstacle the scene does not have, px.
const SLACK_PX: f64 = 1.0;

/// The beams that see an obstacle the still scene does not have: each as (direction relative to
/// the heading, degrees, counter-clockwise; reading, px). One extra scan of the still scene.
pub fn unexpected(episode: &Episode) -> Vec<(f64, f64)> {
    let laser = episode.laser();
    let pose = episode.pose();
    let mut still = vec![0.0; laser.beams()];
    laser.scan(episode.scene(), pose.position(), pose.z_deg, &mut still);
    let slack = SLACK_PX + 3.0 * episode.config().laser.noise_sigma_px;
    episode
        .readings()
        .iter()
        .zip(&still)
        .enumerate()
        .filter(|(_, (&seen, &wall))| seen < wall - slack)
        .map(|(i, (&seen, _))| (laser.beam_angle_deg(i, 0.0), seen))
        .collect()
}
