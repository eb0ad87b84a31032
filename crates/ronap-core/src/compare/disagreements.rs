//! The seeds where the compared policies disagree: which they are, the contact sheet of their
//! trajectories, and an HTML player of each (`players/seed-SEED.html`: every policy's episode
//! side by side on one timeline), each episode run again with the same seed.

use super::{CompareError, Comparison, Contender, PolicyResult};
use crate::eval::{Evaluator, Recording};
use crate::io::{write_atomic, OutputError};
use crate::render::chart;
use crate::render::{player_page, PlayerPage, Trace};
use std::path::Path;

/// The seeds where the policies disagree most (a split between success and failure first, the
/// most even splits first, then the widest SPL spread), at most `rows` of them.
pub fn disagreements(policies: &[PolicyResult], rows: usize) -> Vec<usize> {
    let n = policies.first().map_or(0, |p| p.seeds.len());
    let mut scored: Vec<(usize, f64, usize)> = (0..n)
        .filter_map(|i| {
            let wins = policies.iter().filter(|p| p.seeds[i].success()).count();
            let split = wins.min(policies.len() - wins);
            let spl = policies.iter().map(|p| p.seeds[i].spl);
            let spread =
                spl.clone().fold(f64::NEG_INFINITY, f64::max) - spl.fold(f64::INFINITY, f64::min);
            (split > 0 || spread > 0.05).then_some((split, spread, i))
        })
        .collect();
    scored.sort_by(|a, b| b.0.cmp(&a.0).then(b.1.total_cmp(&a.1)).then(a.2.cmp(&b.2)));
    scored.into_iter().take(rows).map(|(_, _, i)| i).collect()
}

/// The contact sheet of the seeds where the policies disagree most: each policy's trajectory
/// there (the episode run again, recording its path; a team's, every robot's paths). `None` when
/// they agree everywhere.
pub(super) fn disagreement_sheet(
    evaluator: &Evaluator,
    contenders: &[Contender],
    comparison: &Comparison,
    rows: usize,
) -> Result<Option<image::RgbImage>, CompareError> {
    let chosen = disagreements(&comparison.policies, rows);
    if chosen.is_empty() {
        return Ok(None);
    }
    let made = |c: &Contender, source| CompareError::Policy {
        policy: c.name.clone(),
        source,
    };
    let team = evaluator.config().team_size() > 0;
    // A lone robot's policies are made once; a team's afresh for each episode.
    let mut policies = Vec::new();
    for c in contenders {
        policies.push(match team {
            true => None,
            false => Some(c.factory.make().map_err(|e| made(c, e))?),
        });
    }
    let recording = Recording {
        trajectory: true,
        steps: false,
    };
    // Pictures 160 pixels along the scene's longer side.
    let scale = |scene: &crate::Scene| 160.0 / scene.width().max(scene.height()).max(1.0);
    let mut sheet_rows = Vec::new();
    for &i in &chosen {
        let seed = comparison.policies[0].seeds[i].seed;
        let mut cells = Vec::new();
        for (c, policy) in contenders.iter().zip(policies.iter_mut()) {
            let drawn = match (&c.team, policy.as_deref_mut()) {
                (Some(factory), _) if team => {
                    let mut policy = factory.make().map_err(|e| made(c, e))?;
                    let names = factory.names();
                    evaluator
                        .run_team_episode(policy.as_mut(), &names, seed, recording)
                        .map(|r| {
                            let picture = r
                                .picture
                                .as_ref()
                                .and_then(|p| crate::render::team_image(&r, scale(&p.scene)));
                            (picture, r.outcome, r.steps)
                        })
                        .map_err(|e| e.to_string())
                }
                (_, Some(policy)) => evaluator
                    .run_episode(policy, seed, recording)
                    .map(|r| {
                        let picture = r
                            .world
                            .as_ref()
                            .and_then(|w| crate::render::trajectory_image(&r, scale(w.scene())));
                        (picture, r.outcome, r.steps)
                    })
                    .map_err(|e| e.to_string()),
                // A team scenario's contender always has a team policy (the comparison checks).
                (_, None) => Err("no team policy".to_string()),
            };
            cells.push(match drawn {
                Ok((picture, outcome, steps)) => (
                    picture.unwrap_or_else(|| image::RgbImage::new(1, 1)),
                    format!("{}, {steps} steps", outcome.name()),
                ),
                Err(e) => (image::RgbImage::new(1, 1), format!("failed: {e}")),
            });
        }
        sheet_rows.push(chart::SheetRow {
            label: format!("seed {seed}"),
            cells,
        });
    }
    let columns: Vec<String> = comparison
        .policies
        .iter()
        .map(|p| p.label.clone())
        .collect();
    Ok(Some(chart::contact_sheet(&columns, &sheet_rows, 160)))
}

/// The seeds where the policies' successes differ (one succeeded, another did not), the most
/// even splits first, at most `most` of them (`None`: all).
pub fn success_disagreements(policies: &[PolicyResult], most: Option<usize>) -> Vec<usize> {
    let n = policies.first().map_or(0, |p| p.seeds.len());
    let mixed = |i: &usize| {
        let wins = policies.iter().filter(|p| p.seeds[*i].success()).count();
        wins > 0 && wins < policies.len()
    };
    let all = disagreements(policies, n).into_iter().filter(mixed);
    all.take(most.unwrap_or(usize::MAX)).collect()
}

/// Writes the player of each seed where the policies' successes differ (all, or the `most` that
/// disagree most, in [`disagreements`]' order) into `dir/players/seed-SEED.html`: every policy's
/// episode of the seed, run again recording its steps, side by side on one timeline. Returns
/// those seeds.
pub(super) fn write_players(
    evaluator: &Evaluator,
    contenders: &[Contender],
    comparison: &Comparison,
    dir: &Path,
    most: Option<usize>,
) -> Result<Vec<u64>, CompareError> {
    let chosen = success_disagreements(&comparison.policies, most);
    if chosen.is_empty() {
        return Ok(Vec::new());
    }
    let players = dir.join("players");
    std::fs::create_dir_all(&players).map_err(|source| OutputError::Io {
        path: players.clone(),
        source,
    })?;
    let recording = Recording {
        trajectory: false,
        steps: true,
    };
    let made = |c: &Contender, e| CompareError::Policy {
        policy: c.name.clone(),
        source: e,
    };
    let team = evaluator.config().team_size() > 0;
    let mut seeds = Vec::new();
    for &i in &chosen {
        let seed = comparison.policies[0].seeds[i].seed;
        let path = players.join(format!("seed-{seed:06}.html"));
        let mut traces: Vec<Trace> = Vec::new();
        for (c, p) in contenders.iter().zip(&comparison.policies) {
            let trace = match (&c.team, team) {
                (Some(factory), true) => {
                    let mut policy = factory.make().map_err(|e| made(c, e))?;
                    evaluator
                        .run_team_episode(policy.as_mut(), &factory.names(), seed, recording)
                        .map_err(|e| e.to_string())
                        .and_then(|r| crate::job::team_record(evaluator, &r, &p.label))
                }
                _ => {
                    let mut policy = c.factory.make().map_err(|e| made(c, e))?;
                    evaluator
                        .run_episode(policy.as_mut(), seed, recording)
                        .map_err(|e| e.to_string())
                        .and_then(|r| crate::job::lone_record(evaluator, &r, &p.label))
                }
            };
            traces.push(trace.map_err(|message| OutputError::Format {
                path: path.clone(),
                message: format!("policy {}: {message}", c.name),
            })?);
        }
        let outcomes: Vec<String> = comparison
            .policies
            .iter()
            .map(|p| format!("{} {}", p.label, p.seeds[i].outcome.name()))
            .collect();
        let page = PlayerPage {
            title: format!("ronap compare: seed {seed}"),
            traces: &traces,
            note: Some(format!(
                "{}; every policy's episode of this seed on one timeline",
                outcomes.join(", ")
            )),
        };
        let html = player_page(&page).map_err(|e| OutputError::Format {
            path: path.clone(),
            message: e.to_string(),
        })?;
        write_atomic(&path, |w| w.write_all(html.as_bytes()))?;
        seeds.push(seed);
    }
    Ok(seeds)
}
