//! Pictures of team episodes: the whole scene with every robot's path, start and goal in its own
//! colour (the colours of [`crate::render::chart::policy_colour`], repeating after ten).

use crate::eval::{Evaluator, TeamRecord};
use crate::geometry::Point;
use crate::policy::TeamPolicy;
use crate::render::chart::{policy_colour, POLICY_COUNT};
use crate::render::gif::{Animation, AnimationError, GifOptions, GifWriter};
use crate::render::Canvas;
use crate::run::RunError;
use crate::sim::team::Team;
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
pub fn team_frame(team: &Team, paths: &[Vec<Point>], scale: f64) -> RgbImage {
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
        let radius = r.config().robot.radius_px.max(least);
        canvas.robot(r.start(), radius, policy_colour(k));
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

/// A GIF encoder for team frames of `width` x `height` pixels, in the team palette.
pub fn team_gif_writer(width: u32, height: u32) -> Result<GifWriter<Vec<u8>>, AnimationError> {
    let too_large = || AnimationError::TooLarge { width, height };
    Ok(GifWriter::with_palette(
        Vec::new(),
        u16::try_from(width).map_err(|_| too_large())?,
        u16::try_from(height).map_err(|_| too_large())?,
        &team_palette(),
    )?)
}

/// A team episode that could not be animated.
#[derive(Debug, thiserror::Error)]
pub enum TeamAnimationError {
    /// The episode could not be run again.
    #[error(transparent)]
    Run(#[from] RunError),
    /// The frames could not be encoded.
    #[error(transparent)]
    Animation(#[from] AnimationError),
}

/// Runs team episode `seed` again with `policy` (fresh from its factory; robot `k`'s named
/// `names[k]`)
/// and draws it from above ([`team_frame`] at `options.scale`) every `options.stride` steps.
/// Returns the animation and the re-run's record (a policy that is not deterministic may play
/// the episode otherwise than the run did).
pub fn animate_team(
    evaluator: &Evaluator,
    policy: &mut dyn TeamPolicy,
    names: &[String],
    seed: u64,
    options: &GifOptions,
) -> Result<(Animation, TeamRecord), TeamAnimationError> {
    let stride = options.stride.max(1);
    let worlds = evaluator.worlds().team(seed);
    let Some(world) = worlds.first() else {
        let source =
            crate::sim::placement::EpisodeError::Moving("a team needs at least one robot".into());
        return Err(RunError::Episode { seed, source }.into());
    };
    let (width, height) = Canvas::new(world.scene(), options.scale)
        .into_image()
        .dimensions();
    let mut writer = team_gif_writer(width, height)?;
    let mut paths: Vec<Vec<Point>> = Vec::new();
    let mut pending: Option<RgbImage> = None;
    let mut failed: Option<gif::EncodingError> = None;
    let mut watch = |team: &Team| {
        if paths.is_empty() {
            paths = vec![Vec::new(); team.robots().len()];
        }
        for (k, path) in paths.iter_mut().enumerate() {
            let p = team.robot(k).pose().position();
            if team.present(k) && path.last() != Some(&p) {
                path.push(p);
            }
        }
        if failed.is_some() || (team.steps() % stride != 0 && !team.is_done()) {
            return;
        }
        if let Some(before) = pending.take() {
            if let Err(e) = writer.add(&before, options.frame_delay_cs) {
                failed = Some(e);
                return;
            }
        }
        pending = Some(team_frame(team, &paths, options.scale));
    };
    let record =
        evaluator.watch_team_episode(policy, names, seed, Default::default(), &mut watch)?;
    if let Some(e) = failed {
        return Err(AnimationError::from(e).into());
    }
    if let Some(last) = pending {
        writer
            .add(&last, options.last_frame_delay_cs)
            .map_err(AnimationError::from)?;
    }
    let frames = writer.frames();
    let bytes = writer.finish().map_err(AnimationError::from)?;
    Ok((
        Animation {
            bytes,
            frames,
            steps: record.steps as usize,
            size: (width, height),
        },
        record,
    ))
}
