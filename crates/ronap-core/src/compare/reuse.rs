//! Reading a finished run for reuse in a comparison: its manifest checked against the
//! comparison's policy, configuration, scenes and seeds, and its per-seed results read row by
//! row from `episodes.csv` (a team's robots from `robots.csv`).

use super::{CompareError, CompareInfo, SeedResult};
use crate::eval::Evaluator;
use crate::io::{RunManifest, START_GOAL_COLUMNS};
use rayon::prelude::*;
use std::path::Path;

/// Reads the run in `dir` for reuse by policy `name`: its manifest must record the same policy,
/// configuration, scenes and seeds, and a finished run.
pub(super) fn read_run(
    evaluator: &Evaluator,
    dir: &Path,
    name: &str,
    info: &CompareInfo,
    seeds: &[u64],
) -> Result<(RunManifest, Vec<SeedResult>), CompareError> {
    let config = evaluator.config();
    let mismatch = |message: String| CompareError::Mismatch {
        dir: dir.to_path_buf(),
        message,
    };
    let manifest =
        RunManifest::read(&dir.join("summary.json")).map_err(|source| CompareError::Manifest {
            dir: dir.to_path_buf(),
            source: Box::new(source),
        })?;
    if manifest.policy != name {
        return Err(mismatch(format!(
            "a run of policy {:?}, not {name:?}",
            manifest.policy
        )));
    }
    let (first, count) = (seeds[0], seeds.len() as u64);
    let last = seeds[seeds.len() - 1];
    if manifest.model_version != crate::MODEL_VERSION {
        return Err(mismatch(format!(
            "recorded under model version {}; this ronap runs model version {}, whose episodes \
             differ: run it again with this ronap",
            manifest.model_version,
            crate::MODEL_VERSION
        )));
    }
    if manifest.seed_start != first || manifest.seeds_requested != count {
        return Err(mismatch(format!(
            "seeds {}..{} were run there; this comparison uses {first}..{last}",
            manifest.seed_start,
            manifest
                .seed_start
                .saturating_add(manifest.seeds_requested.saturating_sub(1)),
        )));
    }
    if manifest.interrupted || manifest.error.is_some() {
        return Err(mismatch(format!(
            "that run did not finish every seed: `ronap run --resume {}` finishes it",
            dir.display()
        )));
    }
    if manifest.scenes != info.scenes {
        return Err(mismatch(format!(
            "run on {}; this comparison is on {}",
            manifest.scenes, info.scenes
        )));
    }
    let team = config.team_size() > 0;
    if team != manifest.team.is_some() {
        return Err(mismatch(if team {
            "a lone robot's run; this comparison is of a team".into()
        } else {
            "a team's run; this comparison is of a lone robot".into()
        }));
    }
    if &manifest.config != config.as_sim_config() {
        let field = first_difference(&manifest.config, config.as_sim_config());
        return Err(mismatch(format!(
            "its configuration differs from this comparison's ({field})"
        )));
    }
    let (rows, places) = read_results(dir, team).map_err(mismatch)?;
    if rows.iter().map(|r| r.seed).ne(seeds.iter().copied()) {
        return Err(mismatch(
            "episodes.csv does not hold exactly this comparison's seeds".into(),
        ));
    }
    // The tables take a run's rates from summary.json and the pairs from episodes.csv: the two
    // must tell the same story (an edited file would make them contradict each other).
    let (episodes, successes) = match &manifest.team {
        Some(t) => (t.episodes, t.team_successes),
        None => (manifest.summary.episodes, manifest.summary.successes),
    };
    let counted = rows
        .iter()
        .filter(|r| r.outcome == crate::eval::Outcome::Success)
        .count();
    if (episodes, successes) != (rows.len(), counted) {
        return Err(mismatch(format!(
            "episodes.csv holds {counted} successes in {} episodes, summary.json {successes} in \
             {episodes}: the two files disagree",
            rows.len(),
        )));
    }
    // The same seeds in the same scenes start (and a lone robot ends) in the same places: a
    // changed map file or maze generator shows here even when the manifest reads the same.
    let moved = rows
        .par_iter()
        .zip(&places)
        .find_map_first(|(r, recorded)| {
            let here = places_here(evaluator, r.seed);
            (here.as_ref() != Some(recorded)).then_some((r.seed, here))
        });
    if let Some((seed, here)) = moved {
        return Err(mismatch(format!(
            "seed {seed} has another start or goal there ({}) than here ({}): its scenes differ",
            places[rows.iter().position(|r| r.seed == seed).unwrap_or(0)].join(", "),
            here.map_or("none".to_string(), |h| h.join(", "))
        )));
    }
    Ok((manifest, rows))
}

/// The first field (dotted path) where two configurations differ, with both values.
fn first_difference(a: &crate::SimConfig, b: &crate::SimConfig) -> String {
    fn walk(path: &str, a: &serde_json::Value, b: &serde_json::Value) -> Option<String> {
        match (a, b) {
            (serde_json::Value::Object(x), serde_json::Value::Object(y)) => {
                let mut keys: Vec<&String> = x.keys().chain(y.keys()).collect();
                keys.sort();
                keys.dedup();
                keys.into_iter().find_map(|k| {
                    let null = serde_json::Value::Null;
                    let p = if path.is_empty() {
                        k.clone()
                    } else {
                        format!("{path}.{k}")
                    };
                    walk(&p, x.get(k).unwrap_or(&null), y.get(k).unwrap_or(&null))
                })
            }
            _ if a == b => None,
            _ => Some(format!("{path}: {a} there, {b} here")),
        }
    }
    let (a, b) = (serde_json::to_value(a), serde_json::to_value(b));
    match (a, b) {
        (Ok(a), Ok(b)) => walk("", &a, &b).unwrap_or_else(|| "no field differs".into()),
        _ => "cannot be compared".into(),
    }
}

/// Each seed's places as a run's files write them: a lone robot's start and goal (`start_x,
/// start_y, start_heading_deg, goal_x, goal_y`), or each robot of a team's start (`start_x,
/// start_y, start_heading_deg`) in robot order.
type Places = Vec<Vec<String>>;

/// The places of seed `seed`'s episode here, as [`Places`] holds them (`None` when it cannot
/// start).
fn places_here(evaluator: &Evaluator, seed: u64) -> Option<Vec<String>> {
    let cells = |p: crate::sim::Pose| [p.x, p.y, p.z_deg].map(|v| format!("{v:.3}"));
    let config = evaluator.config();
    if config.team_size() > 0 {
        let team = crate::sim::Team::new(config, &evaluator.worlds().team(seed), seed).ok()?;
        Some(
            team.robots()
                .iter()
                .flat_map(|r| cells(r.start()))
                .collect(),
        )
    } else {
        let e = evaluator.worlds().episode(seed).ok()?;
        let goal = [e.goal().x, e.goal().y].map(|v| format!("{v:.3}"));
        Some(cells(e.start()).into_iter().chain(goal).collect())
    }
}

/// The per-seed results of a run in `dir` and each seed's [`Places`]: a lone robot's from
/// `episodes.csv`; a team's from `episodes.csv` (the team's outcome, steps, summed collisions
/// and path length) and `robots.csv` (each robot's start, and the mean of their SPLs as
/// [`SeedResult::of_team`] takes it), read row by row.
fn read_results(dir: &Path, team: bool) -> Result<(Vec<SeedResult>, Places), String> {
    let mut names = vec!["seed", "outcome", "steps", "collisions", "path_length_px"];
    if team {
        names.push("robots");
    } else {
        names.push("spl");
        names.extend(&START_GOAL_COLUMNS[..5]);
    }
    let mut rows = Vec::new();
    let mut places: Places = Vec::new();
    let mut robots: Vec<usize> = Vec::new();
    Columns::each(&dir.join("episodes.csv"), &names, &mut |row| {
        let outcome = crate::eval::Outcome::from_name(row.cell(1)).ok_or_else(|| row.bad(1))?;
        rows.push(SeedResult {
            seed: row.get(0)?,
            outcome,
            steps: row.get(2)?,
            collisions: row.get(3)?,
            path_length_px: row.finite(4)?,
            spl: if team { 0.0 } else { row.finite(5)? },
        });
        if team {
            robots.push(row.get(5)?);
            places.push(Vec::new());
        } else {
            places.push((6..11).map(|k| row.cell(k).to_string()).collect());
        }
        Ok(())
    })?;
    if team {
        let at: std::collections::HashMap<u64, usize> =
            rows.iter().enumerate().map(|(i, r)| (r.seed, i)).collect();
        let mut spl = vec![0.0; rows.len()];
        let mut counted = vec![0; rows.len()];
        let path = dir.join("robots.csv");
        let mut names = vec!["seed", "spl"];
        names.extend(&START_GOAL_COLUMNS[..3]);
        Columns::each(&path, &names, &mut |row| {
            let seed: u64 = row.get(0)?;
            let i = *at
                .get(&seed)
                .ok_or_else(|| format!("{}: seed not in episodes.csv", row.bad(0)))?;
            spl[i] += row.finite(1)?;
            counted[i] += 1;
            places[i].extend((2..5).map(|k| row.cell(k).to_string()));
            Ok(())
        })?;
        for (i, r) in rows.iter_mut().enumerate() {
            if counted[i] != robots[i] {
                return Err(format!(
                    "{}: {} rows of seed {}, whose row in episodes.csv says {} robots",
                    path.display(),
                    counted[i],
                    r.seed,
                    robots[i]
                ));
            }
            r.spl = spl[i] / counted[i].max(1) as f64;
        }
    }
    Ok((rows, places))
}

/// Reading the named columns of a CSV file row by row.
struct Columns;

/// A row of [`Columns::each`]: its cells in the order of the names asked for.
struct Row<'a> {
    path: &'a Path,
    names: &'a [&'a str],
    /// The file's line (the header is line 1).
    line: usize,
    cells: Vec<&'a str>,
}

impl Row<'_> {
    /// Cell `k`.
    fn cell(&self, k: usize) -> &str {
        self.cells[k]
    }

    /// Cell `k`, parsed.
    fn get<T: std::str::FromStr>(&self, k: usize) -> Result<T, String> {
        self.cell(k).parse().map_err(|_| self.bad(k))
    }

    /// Cell `k`, a finite number (`nan` and `inf` parse, but no run writes them).
    fn finite(&self, k: usize) -> Result<f64, String> {
        self.get::<f64>(k).and_then(|x| {
            if x.is_finite() {
                Ok(x)
            } else {
                Err(self.bad(k))
            }
        })
    }

    /// The error of cell `k`: the file, its line, the column and the value.
    fn bad(&self, k: usize) -> String {
        let (path, line, name) = (self.path.display(), self.line, self.names[k]);
        format!("{path}: line {line}: {name} = {:?}", self.cell(k))
    }
}

impl Columns {
    /// Hands each row of the CSV file at `path`, as the columns `names`, to `take`, one at a
    /// time (memory stays flat however long the file); an error names a missing column.
    fn each(
        path: &Path,
        names: &[&str],
        take: &mut dyn FnMut(&Row<'_>) -> Result<(), String>,
    ) -> Result<(), String> {
        let what = |e: &dyn std::fmt::Display| format!("{}: {e}", path.display());
        let lines = crate::bounded::open_lines(path).map_err(|e| what(&e))?;
        let mut reader = csv::Reader::from_reader(lines);
        let headers = reader.headers().map_err(|e| what(&e))?.clone();
        let columns = names
            .iter()
            .map(|name| {
                let found = headers.iter().position(|h| h == *name);
                found.ok_or_else(|| what(&format!("no column {name:?}")))
            })
            .collect::<Result<Vec<usize>, String>>()?;
        let mut record = csv::StringRecord::new();
        let mut line = 1;
        while reader.read_record(&mut record).map_err(|e| what(&e))? {
            line += 1;
            let cells = columns
                .iter()
                .map(|&c| record.get(c).unwrap_or(""))
                .collect();
            take(&Row {
                path,
                names,
                line,
                cells,
            })?;
        }
        Ok(())
    }
}
