//! Animations of a run's own episodes (`ronap run --gif SEED`), drawn from the steps the run
//! recorded for those seeds ([`crate::eval::EvalOptions::steps_of`]): the recorded actions are
//! stepped again in the model, no policy is asked again, so a GIF always shows the episode its
//! row in `episodes.csv` describes.

use crate::eval::{EpisodeRecord, Evaluator, Outcome, TeamRecord};
use crate::io::RunWriter;
use crate::job::{replay_team, RobotLog};
use crate::render::{animate, Animation, GifOptions};

/// Writes the animation `draw` makes of episode `seed` into `writer`'s run, if the run asks for
/// one of that seed (`--gif`).
pub(crate) fn write_if_asked(
    writer: &RunWriter,
    seed: u64,
    outcome: Outcome,
    draw: impl FnOnce() -> Result<Animation, String>,
) {
    if writer.gif_seeds().contains(&seed) {
        let gif = draw();
        writer.animation(
            seed,
            outcome,
            gif.as_ref().map(|a| &a.bytes[..]).map_err(Clone::clone),
        );
    }
}

/// The top-view animation of lone episode `record`, whose steps were recorded.
pub(crate) fn lone(evaluator: &Evaluator, record: &EpisodeRecord) -> Result<Animation, String> {
    let episode = evaluator
        .worlds()
        .episode(record.seed)
        .map_err(|e| e.to_string())?;
    let actions: Vec<_> = record.step_log.iter().map(|s| s.action).collect();
    animate(episode, &actions, None, &GifOptions::default()).map_err(|e| e.to_string())
}

/// The top-view animation of team episode `record`, whose robots' steps were recorded: a team of
/// one at a lone robot's scale (its animation is the lone robot's, byte for byte), a team of
/// several about 500 pixels along the scene's longer side.
pub(crate) fn team(evaluator: &Evaluator, record: &TeamRecord) -> Result<Animation, String> {
    let seed = record.seed;
    let mut options = GifOptions::default();
    if record.robots.len() > 1 {
        let scene_side = evaluator
            .worlds()
            .team(seed)
            .first()
            .map_or(1000.0, |w| w.scene().width().max(w.scene().height()));
        options.scale = (500.0 / scene_side).clamp(0.1, 4.0);
    }
    let logs = RobotLog::of_record(record);
    replay_team(evaluator, seed, &logs, &options).map_err(|e| e.to_string())
}
