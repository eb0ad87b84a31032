//! Pictures of team episodes as they run: the whole scene with every robot's path, start and goal
//! in its own colour (the colours of [`crate::render::chart::policy_colour`], repeating after
//! ten). Finished episodes' pictures, lone or team, are drawn in `trajectory`.

use crate::geometry::Point;
use crate::render::chart::{policy_colour, POLICY_COUNT};
use crate::render::gif::{AnimationError, GifWriter};
use crate::render::trajectory::{episode_image, faded, Drawn, Obstacles};
use crate::render::Canvas;
use crate::sim::Team;
use image::{Rgb, RgbImage};

/// The picture of a team episode as it stands, as a lone robot's [`crate::render::top_down`] is
/// drawn: each robot's goal as a disc of the goal tolerance, its path so far (`paths[k]`), its
/// start and, while it is in the scene, the robot with its heading, each robot in its own colour
/// (a team of one in the lone robot's, with its laser scan); moving obstacles as they are now.
pub fn team_frame(team: &Team, paths: &[Vec<Point>], scale: f64) -> RgbImage {
    let n = team.robots().len();
    let robots: Vec<Drawn<'_>> = team
        .robots()
        .iter()
        .enumerate()
        .map(|(k, r)| Drawn {
            present: team.present(k),
            ..Drawn::running(r, paths.get(k).map_or(&[][..], Vec::as_slice), k, n)
        })
        .collect();
    let movers = Obstacles::Live(team.movers());
    episode_image(team.robot(0).scene(), &robots, movers, scale)
}

/// The picture of a team's set-up before it moves: each robot's goals, in its visiting order, as
/// faded discs joined by thin lines from its start (where it will head, not where it drove), and
/// each robot at its start with its heading, in its own colour; moving obstacles where they start.
pub fn team_setup(team: &Team, scale: f64) -> RgbImage {
    let first = team.robot(0);
    let mut canvas = Canvas::new(first.scene(), scale);
    let least = 3.0 / scale;
    for (k, r) in team.robots().iter().enumerate() {
        let colour = faded(policy_colour(k));
        let mut legs = vec![r.start().position()];
        legs.extend_from_slice(team.goals(k));
        canvas.path(&legs, 1.0, colour);
        let tolerance = r.config().episode.goal_tolerance_px.max(least);
        for &g in team.goals(k) {
            canvas.fill_disc(g, tolerance, colour);
        }
    }
    if let Some(movers) = team.movers() {
        canvas.movers(movers);
    }
    for (k, r) in team.robots().iter().enumerate() {
        canvas.body(r.start(), &r.config().robot, least, policy_colour(k));
    }
    canvas.into_image()
}

/// Every colour of team pictures: the scene's and moving obstacles' ([`crate::render::PALETTE`]),
/// each robot colour and its faded goal colour.
pub fn team_palette() -> Vec<Rgb<u8>> {
    let mut palette = crate::render::PALETTE.to_vec();
    palette.extend((0..POLICY_COUNT).map(policy_colour));
    palette.extend((0..POLICY_COUNT).map(|k| faded(policy_colour(k))));
    palette
}

/// A GIF encoder for frames of a team of `robots` of `width` x `height` pixels: in the team
/// palette, or a team of one in a lone robot's ([`crate::render::PALETTE`]), so its animation is
/// the lone robot's.
pub fn team_gif_writer(
    width: u32,
    height: u32,
    robots: usize,
) -> Result<GifWriter<Vec<u8>>, AnimationError> {
    let too_large = || AnimationError::TooLarge { width, height };
    let palette = match robots {
        1 => crate::render::PALETTE.to_vec(),
        _ => team_palette(),
    };
    Ok(GifWriter::with_palette(
        Vec::new(),
        u16::try_from(width).map_err(|_| too_large())?,
        u16::try_from(height).map_err(|_| too_large())?,
        &palette,
    )?)
}
