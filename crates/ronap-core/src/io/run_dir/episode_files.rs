//! The per-episode files of a run directory: trajectory pictures (`png/`) and step logs
//! (`steps/`), and the removal of those an earlier run left.

use crate::eval::{EpisodeRecord, TeamRecord};
use crate::io::atomic::{remove_files_in, save_image, write_atomic, OutputError};
use crate::io::steplog::write_steps;
use crate::render::trajectory_image;
use std::path::Path;

/// Writes the per-episode files a record asks for: its trajectory picture (`png/`) and its step
/// log (`steps/`), each when `picture` / `steps` say so and the record holds what they need.
pub(super) fn write_episode_files(
    dir: &Path,
    record: &EpisodeRecord,
    picture: bool,
    steps: bool,
) -> Result<(), OutputError> {
    if picture {
        if let Some(img) = trajectory_image(record, 1.0) {
            let path = dir.join("png").join(format!(
                "seed-{:06}-{}.png",
                record.seed,
                record.outcome.name()
            ));
            save_image(&path, &img)?;
        }
    }
    if steps {
        let path = dir
            .join("steps")
            .join(format!("seed-{:06}.csv", record.seed));
        write_atomic(&path, |out| write_steps(record, out))?;
    }
    Ok(())
}

/// Writes team episode `record`'s picture (when `picture`) and its robots' step logs (when
/// `steps`), a log per robot.
pub(super) fn write_team_files(
    dir: &Path,
    record: &TeamRecord,
    picture: bool,
    steps: bool,
) -> Result<(), OutputError> {
    if picture {
        if let Some(img) = crate::render::team_image(record, 1.0) {
            let path = dir.join("png").join(format!(
                "seed-{:06}-{}.png",
                record.seed,
                record.outcome.name()
            ));
            save_image(&path, &img)?;
        }
    }
    if !steps {
        return Ok(());
    }
    for (k, robot) in record.robots.iter().enumerate() {
        let path = dir
            .join("steps")
            .join(format!("seed-{:06}-robot-{k}.csv", record.seed));
        write_atomic(&path, |out| write_steps(robot, out))?;
    }
    Ok(())
}

/// Removes the per-episode files an earlier run left in `dir` (`png/seed-*.png`,
/// `steps/seed-*.csv`, the GIFs `ronap replay` drew beside them, `steps/seed-*.gif`,
/// `gif/seed-*.gif` and `html/seed-*.html`), so a reused output directory shows only this run. Nothing else is touched.
pub(super) fn remove_stale_files(dir: &Path) -> Result<(), OutputError> {
    for (sub, ext) in [
        ("png", ".png"),
        ("steps", ".csv"),
        ("steps", ".gif"),
        ("gif", ".gif"),
        ("html", ".html"),
    ] {
        remove_files_in(&dir.join(sub), |name| {
            name.starts_with("seed-") && name.ends_with(ext)
        })?;
    }
    Ok(())
}
