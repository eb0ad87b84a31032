//! A lone robot's evaluation into a run directory: the sequence `ronap run`, `ronap compare` and
//! Python's `ronap.evaluate` share.

use super::into::{run_into, Episodes, FileRows, Ran, Tallies};
use crate::eval::{
    EpisodeRecord, EvalOptions, Evaluator, Figures, RunEnd, RunResult, Summary, Tally,
};
use crate::io::figures;
use crate::io::{finish, lone_headers, manifest, EpisodeRows, Layout, RunWriter};
use crate::io::{OutputError, RunManifest};
use crate::job::{animate, player, RunRequest};
use crate::policy::{PolicyError, PolicyFactory};
use std::sync::atomic::AtomicBool;

/// A finished evaluation: the records kept, the summary of every episode of the run and the
/// manifest that went to `summary.json` (or would have, for a run without a directory).
#[derive(Debug)]
pub struct Evaluation {
    /// How the run stopped, and the records the caller chose to keep (in seed order).
    pub result: RunResult,
    /// The figures of every finished episode (those of a resumed run's earlier process too).
    pub summary: Summary,
    /// The manifest.
    pub manifest: RunManifest,
    /// The run directory's files could not all be written.
    pub write_error: Option<OutputError>,
}

/// Runs an evaluation and, given a `writer`, writes it into its directory as it goes:
/// `episodes.csv`, `timing.csv` (and the exact figures a resume needs) row by row in seed order
/// under their partial names, per-episode files (and the animations the writer asks for, from
/// the steps recorded) as episodes finish, `summary.json` at the end,
/// when the run files take their final names (also after an interruption or a failing episode,
/// so finished episodes are never lost; not after a write error, so no file under a final name
/// is ever half-written). Memory stays flat however many episodes: only the records `keep`
/// accepts are kept. A resumed `writer` runs only the seeds its run had not finished.
/// `on_record` hears every finished episode (progress).
pub fn evaluate_into(
    request: RunRequest<'_>,
    factory: &dyn PolicyFactory,
    on_record: &(dyn Fn(&EpisodeRecord) + Sync),
    keep: &dyn Fn(&EpisodeRecord) -> bool,
) -> Result<Evaluation, PolicyError> {
    let config = request.evaluator.config();
    let layout = Layout::of(config);
    let mut lone = Lone {
        layout,
        tally: Tally::measuring(layout.metrics),
        steps_before: 0,
        keep,
        kept: Vec::new(),
    };
    let episodes = LoneEpisodes {
        evaluator: request.evaluator,
        factory,
        policy: &request.info.policy,
    };
    let Ran {
        mut result,
        options,
        streams,
        mut write_error,
    } = run_into(&request, &episodes, &mut lone, on_record)?;
    result.records = lone.kept;
    let tally = &lone.tally;
    let summary = tally.summary(result.wall_time_s, tally.steps() - lone.steps_before);
    let manifest = manifest(config, &options, request.info, &result, &summary);
    if let (Some(w), None) = (&request.writer, &write_error) {
        write_error = finish(w, streams, &manifest, &result).err();
    }
    Ok(Evaluation {
        result,
        summary,
        manifest,
        write_error,
    })
}

/// A lone robot's episodes, by policies from a factory.
struct LoneEpisodes<'a> {
    evaluator: &'a Evaluator,
    factory: &'a dyn PolicyFactory,
    /// The policy's name, for players' titles.
    policy: &'a str,
}

impl Episodes<EpisodeRecord> for LoneEpisodes<'_> {
    fn stream(
        &self,
        options: &EvalOptions,
        cancel: &AtomicBool,
        on_finish: &(dyn Fn(&EpisodeRecord) + Sync),
        sink: &mut dyn FnMut(EpisodeRecord) -> bool,
    ) -> Result<RunEnd, PolicyError> {
        self.evaluator
            .stream(self.factory, options, cancel, on_finish, sink)
    }

    fn files(&self, writer: &RunWriter, r: &EpisodeRecord) {
        writer.episode(r);
        animate::write_if_asked(writer, r.seed, r.outcome, || {
            animate::lone(self.evaluator, r)
        });
        player::write_if_asked(writer, r.seed, r.outcome, || {
            player::lone_record(self.evaluator, r, self.policy)
        });
    }
}

/// A lone robot's rows and figures, and the records kept.
struct Lone<'a> {
    layout: Layout,
    tally: Tally,
    steps_before: u64,
    keep: &'a dyn Fn(&EpisodeRecord) -> bool,
    kept: Vec<EpisodeRecord>,
}

impl Tallies<EpisodeRecord> for Lone<'_> {
    fn headers(&self) -> [Option<Vec<String>>; 4] {
        lone_headers(self.layout)
    }

    fn restore(&mut self, row: &csv::StringRecord) -> Result<(), String> {
        let (_, f) = figures::parse_lone(row, self.layout.metrics.len())?;
        self.tally.add(&f);
        Ok(())
    }

    fn start(&mut self) {
        self.steps_before = self.tally.steps();
    }

    fn add(&mut self, r: EpisodeRecord, write: &mut dyn FnMut(&[FileRows]) -> bool) -> bool {
        let f = Figures::of(&r);
        if !write(&EpisodeRows::with(&r, &f, self.layout).files()) {
            return false;
        }
        self.tally.add(&f);
        if (self.keep)(&r) {
            self.kept.push(r);
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::{EvalOptions, Evaluator};
    use crate::io::{RunFiles, RunInfo, RunWriter};
    use crate::policy::{Decision, Policy};
    use crate::sim::Scenes;
    use crate::{Episode, World};
    use std::sync::atomic::AtomicBool;

    /// Gives up at once, except on seed 0, where it fails after a while (so seed 1 finishes
    /// first on another worker).
    struct FailsOnSeedZero {
        seed: u64,
    }

    impl Policy for FailsOnSeedZero {
        fn reset(&mut self, _: &World, episode: &Episode) -> Result<(), PolicyError> {
            self.seed = episode.seed();
            Ok(())
        }

        fn act(&mut self, _: &Episode) -> Result<Decision, PolicyError> {
            if self.seed == 0 {
                std::thread::sleep(std::time::Duration::from_millis(300));
                return Err(PolicyError::Failed("broken".into()));
            }
            Ok(Decision::GiveUp("test".into()))
        }
    }

    struct Factory;

    impl PolicyFactory for Factory {
        fn make(&self) -> Result<Box<dyn Policy>, PolicyError> {
            Ok(Box::new(FailsOnSeedZero { seed: 0 }))
        }

        fn name(&self) -> String {
            "fails-on-seed-0".into()
        }
    }

    fn files(dir: &std::path::Path) -> Vec<(String, Vec<u8>)> {
        let mut out: Vec<_> = std::fs::read_dir(dir)
            .unwrap()
            .flatten()
            .filter(|e| e.path().is_file())
            .map(|e| {
                let name = e.file_name().to_string_lossy().into_owned();
                (name, std::fs::read(e.path()).unwrap())
            })
            .collect();
        out.sort();
        out
    }

    #[test]
    fn a_replacing_run_whose_first_seed_fails_keeps_the_run_it_would_replace() {
        let config = crate::SimConfig::default().validate().unwrap();
        let evaluator = Evaluator::new(config, Scenes::MazePerSeed);
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().join("run");
        let options = EvalOptions {
            seeds: vec![0u64, 1, 2, 3].into(),
            threads: 2,
            ..EvalOptions::default()
        };
        let info = RunInfo {
            policy: "random".into(),
            scenes: crate::sim::SceneSpec::MazePerSeed,
            map: None,
        };
        let cancel = AtomicBool::new(false);
        let run = |writer: RunWriter, factory: &dyn PolicyFactory| {
            let request = RunRequest {
                evaluator: &evaluator,
                options: &options,
                info: &info,
                writer: Some(writer),
                cancel: &cancel,
            };
            evaluate_into(request, factory, &|_| {}, &|_| false).unwrap()
        };
        let first = RunWriter::create(&dir, RunFiles::default(), 0, false).unwrap();
        let random =
            crate::policy::factory("random", evaluator.config().observation_size()).unwrap();
        assert!(run(first, random.as_ref()).write_error.is_none());
        let before = files(&dir);
        assert!(before.iter().any(|(n, _)| n == "summary.json"));
        // Replaced by a run whose seed 1 finishes while seed 0 fails: nothing of it reached the
        // run files, so the finished run stays as it was.
        let again = RunWriter::create(&dir, RunFiles::default(), 0, true).unwrap();
        let failed = run(again, &Factory);
        assert!(failed.result.error.is_some());
        assert_eq!(files(&dir), before);
    }
}
