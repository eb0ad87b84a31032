//! `figures.csv.partial`: the exact figures of each finished episode of a run under way, one row
//! per episode in seed order, so that a resumed run's summary equals an uninterrupted run's bit
//! for bit (`episodes.csv` rounds its numbers). Floats are written as the hexadecimal bits of
//! the `f64`; the file is removed once the run is complete.

use crate::eval::metric::Kind;
use crate::eval::{Figures, Outcome, RobotFigures, TeamFigures};
use crate::sim::DynamicMetrics;

/// The file's name inside a run directory (it only ever exists as a partial file).
pub const FIGURES_FILE: &str = "figures.csv";

const TEAM_BASE: [&str; 11] = [
    "seed",
    "outcome",
    "deadlock",
    "makespan",
    "path_length_bits",
    "collisions",
    "robot_collisions",
    "sum_of_costs",
    "makespan_lower_bound",
    "sum_of_costs_lower_bound",
    "waiting_steps",
];

/// A robot's fields: a lone robot's columns after `seed`, and each robot's of a team.
const ROBOT_FIELDS: [&str; 9] = [
    "outcome",
    "steps",
    "collisions",
    "path_length_bits",
    "spl_bits",
    "return_bits",
    "dynamic_collisions",
    "min_clearance_bits",
    "near_steps",
];

/// The exact-figure column of each metric of `kinds`.
fn metric_columns(kinds: &[Kind]) -> impl Iterator<Item = String> + '_ {
    kinds.iter().map(|k| format!("{}_bits", k.column.name))
}

/// Columns for a lone robot's episodes measuring the metrics of `kinds`.
pub fn lone_columns(kinds: &[Kind]) -> Vec<String> {
    let mut columns: Vec<String> = std::iter::once("seed")
        .chain(ROBOT_FIELDS)
        .map(str::to_string)
        .collect();
    columns.extend(metric_columns(kinds));
    columns
}

/// Columns for team episodes of `robots` robots measuring the metrics of `kinds`.
pub fn team_columns(robots: usize, kinds: &[Kind]) -> Vec<String> {
    let mut columns: Vec<String> = TEAM_BASE.iter().map(|c| c.to_string()).collect();
    for k in 0..robots {
        columns.extend(ROBOT_FIELDS.iter().map(|f| format!("robot{k}_{f}")));
        columns.extend(metric_columns(kinds).map(|f| format!("robot{k}_{f}")));
    }
    columns
}

fn bits(x: f64) -> String {
    format!("{:016x}", x.to_bits())
}

/// The row of a lone robot's episode of `seed`.
pub fn lone_row(seed: u64, f: &Figures) -> Vec<String> {
    let mut row = vec![
        seed.to_string(),
        f.outcome.name().to_string(),
        f.steps.to_string(),
        f.collisions.to_string(),
        bits(f.path_length_px),
        bits(f.spl),
        bits(f.total_reward),
    ];
    match f.dynamic {
        Some(d) => row.extend([
            d.collisions.to_string(),
            bits(d.min_clearance_px),
            d.near_steps.to_string(),
        ]),
        None => row.extend([String::new(), String::new(), String::new()]),
    }
    row.extend(metric_bits(&f.metrics));
    row
}

/// The exact figures of metric `values`, empty for none.
fn metric_bits(values: &[Option<f64>]) -> impl Iterator<Item = String> + '_ {
    values.iter().map(|v| v.map_or(String::new(), bits))
}

/// The row of a team episode of `seed`: the team's figures, then each robot's (`robots[k]`).
pub fn team_row(seed: u64, team: &TeamFigures, robots: &[Figures]) -> Vec<String> {
    let mut row = vec![
        seed.to_string(),
        team.outcome.name().to_string(),
        u8::from(team.deadlock).to_string(),
        team.makespan.map_or(String::new(), |m| m.to_string()),
        bits(team.path_length_px),
        team.collisions.to_string(),
        team.robot_collisions.to_string(),
        team.flow
            .sum_of_costs
            .map_or(String::new(), |m| m.to_string()),
        team.flow
            .makespan_lower_bound
            .map_or(String::new(), |m| m.to_string()),
        team.flow
            .sum_of_costs_lower_bound
            .map_or(String::new(), |m| m.to_string()),
        team.flow.waiting_steps.to_string(),
    ];
    for r in robots {
        row.extend([
            r.outcome.name().to_string(),
            r.steps.to_string(),
            r.collisions.to_string(),
            bits(r.path_length_px),
            bits(r.spl),
            bits(r.total_reward),
        ]);
        row.extend(dynamic_fields(r.dynamic));
        row.extend(metric_bits(&r.metrics));
    }
    row
}

/// The moving-obstacle figures of an episode, empty without moving obstacles.
fn dynamic_fields(d: Option<DynamicMetrics>) -> [String; 3] {
    match d {
        Some(d) => [
            d.collisions.to_string(),
            bits(d.min_clearance_px),
            d.near_steps.to_string(),
        ],
        None => [String::new(), String::new(), String::new()],
    }
}

/// Reads fields of a row in order, naming the column of a bad one.
struct Fields<'a> {
    row: &'a csv::StringRecord,
    at: usize,
}

impl Fields<'_> {
    fn text(&mut self) -> Result<&str, String> {
        let field = self
            .row
            .get(self.at)
            .ok_or_else(|| format!("no field {}", self.at + 1))?;
        self.at += 1;
        Ok(field)
    }

    fn parse<T: std::str::FromStr>(&mut self) -> Result<T, String> {
        let at = self.at + 1;
        let text = self.text()?;
        text.parse()
            .map_err(|_| format!("field {at}: {text:?} is not a number"))
    }

    fn bits(&mut self) -> Result<f64, String> {
        let at = self.at + 1;
        let text = self.text()?;
        u64::from_str_radix(text, 16)
            .map(f64::from_bits)
            .map_err(|_| format!("field {at}: {text:?} is not a float's bits"))
    }

    fn outcome(&mut self) -> Result<Outcome, String> {
        let at = self.at + 1;
        let text = self.text()?;
        Outcome::from_name(text).ok_or_else(|| format!("field {at}: {text:?} is not an outcome"))
    }

    /// Passes over `n` fields.
    fn skip(&mut self, n: usize) {
        self.at += n;
    }

    fn optional_bits(&mut self) -> Result<Option<f64>, String> {
        if self.row.get(self.at).is_some_and(str::is_empty) {
            self.at += 1;
            return Ok(None);
        }
        self.bits().map(Some)
    }

    fn optional<T: std::str::FromStr>(&mut self) -> Result<Option<T>, String> {
        if self.row.get(self.at).is_some_and(str::is_empty) {
            self.at += 1;
            return Ok(None);
        }
        self.parse().map(Some)
    }
}

/// A robot's figures from the next fields of `f`, with `metrics` metric values after them.
fn robot_figures(f: &mut Fields<'_>, metrics: usize) -> Result<Figures, String> {
    Ok(Figures {
        outcome: f.outcome()?,
        steps: f.parse()?,
        collisions: f.parse()?,
        path_length_px: f.bits()?,
        spl: f.bits()?,
        total_reward: f.bits()?,
        dynamic: match f.optional::<u32>()? {
            Some(collisions) => Some(DynamicMetrics {
                collisions,
                min_clearance_px: f.bits()?,
                near_steps: f.parse()?,
            }),
            None => {
                f.skip(2);
                None
            }
        },
        metrics: (0..metrics)
            .map(|_| f.optional_bits())
            .collect::<Result<_, _>>()?,
    })
}

/// A lone robot's figures from `row` (made by [`lone_row`] with `metrics` metric values): its
/// seed and figures.
pub fn parse_lone(row: &csv::StringRecord, metrics: usize) -> Result<(u64, Figures), String> {
    let mut f = Fields { row, at: 0 };
    let seed = f.parse()?;
    let figures = robot_figures(&mut f, metrics)?;
    if f.at != row.len() {
        return Err(format!("{} fields, not {}", row.len(), f.at));
    }
    Ok((seed, figures))
}

/// A team episode's figures from `row` (made by [`team_row`] for `robots` robots with `metrics`
/// metric values each): its seed, the team's figures and each robot's as a lone robot's.
pub fn parse_team(
    row: &csv::StringRecord,
    robots: usize,
    metrics: usize,
) -> Result<(u64, TeamFigures, Vec<Figures>), String> {
    let mut f = Fields { row, at: 0 };
    let seed = f.parse()?;
    let mut team = TeamFigures {
        outcome: f.outcome()?,
        deadlock: f.parse::<u8>()? != 0,
        makespan: f.optional()?,
        path_length_px: f.bits()?,
        collisions: f.parse()?,
        robot_collisions: f.parse()?,
        flow: crate::eval::Flow {
            sum_of_costs: f.optional()?,
            makespan_lower_bound: f.optional()?,
            sum_of_costs_lower_bound: f.optional()?,
            waiting_steps: f.parse()?,
        },
        robots: Vec::with_capacity(robots),
    };
    let mut lone = Vec::with_capacity(robots);
    for _ in 0..robots {
        let r = robot_figures(&mut f, metrics)?;
        team.robots.push(RobotFigures {
            outcome: r.outcome,
            steps: r.steps,
            spl: r.spl,
        });
        lone.push(r);
    }
    if f.at != row.len() {
        return Err(format!("{} fields, not {}", row.len(), f.at));
    }
    Ok((seed, team, lone))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn figures_come_back_bit_for_bit() {
        let lone = Figures {
            outcome: Outcome::Stuck,
            steps: 17,
            collisions: 3,
            path_length_px: 0.1 + 0.2,
            spl: -0.0,
            total_reward: -1.0e-300,
            dynamic: Some(DynamicMetrics {
                collisions: 2,
                min_clearance_px: f64::INFINITY,
                near_steps: 5,
            }),
            metrics: Vec::new(),
        };
        let row = csv::StringRecord::from(lone_row(9, &lone));
        let (seed, back) = parse_lone(&row, 0).expect("parses");
        assert_eq!(seed, 9);
        assert_eq!(back.spl.to_bits(), (-0.0f64).to_bits());
        assert_eq!(back.path_length_px.to_bits(), (0.1f64 + 0.2).to_bits());
        assert_eq!(back, lone);
        let plain = Figures {
            dynamic: None,
            ..lone.clone()
        };
        let row = csv::StringRecord::from(lone_row(1, &plain));
        assert_eq!(parse_lone(&row, 0).expect("parses").1, plain);
        // Metric values follow, a missing one as an empty field, after either kind of row.
        for dynamic in [None, lone.dynamic] {
            let measured = Figures {
                dynamic,
                metrics: vec![Some(0.1 + 0.2), None, Some(-0.0)],
                ..lone.clone()
            };
            let row = csv::StringRecord::from(lone_row(2, &measured));
            assert_eq!(
                row.len(),
                lone_columns(&crate::eval::metric::CROWD[..3]).len()
            );
            let back = parse_lone(&row, 3).expect("parses").1;
            assert_eq!(back, measured);
            assert_eq!(back.metrics[2].map(f64::to_bits), Some((-0.0f64).to_bits()));
        }

        let team = TeamFigures {
            outcome: Outcome::Deadlock,
            deadlock: true,
            makespan: None,
            path_length_px: 12.5,
            collisions: 1,
            robot_collisions: 4,
            flow: crate::eval::Flow {
                sum_of_costs: Some(40),
                makespan_lower_bound: None,
                sum_of_costs_lower_bound: Some(7),
                waiting_steps: 3,
            },
            robots: vec![RobotFigures {
                outcome: Outcome::Stuck,
                steps: 17,
                spl: -0.0,
            }],
        };
        let row = csv::StringRecord::from(team_row(4, &team, std::slice::from_ref(&plain)));
        assert_eq!(row.len(), team_columns(1, &[]).len());
        let (seed, t, robots) = parse_team(&row, 1, 0).expect("parses");
        assert_eq!(
            (seed, &t, robots.as_slice()),
            (4, &team, std::slice::from_ref(&plain))
        );
        assert!(parse_team(&row, 2, 0).is_err());
        assert!(parse_team(&row, 1, 1).is_err());
        // A team among moving obstacles keeps each robot's figures there too, after a robot
        // without them.
        let mut two = team.clone();
        two.robots.push(two.robots[0]);
        let row = csv::StringRecord::from(team_row(5, &two, &[plain.clone(), lone.clone()]));
        assert_eq!(row.len(), team_columns(2, &[]).len());
        let (_, _, robots) = parse_team(&row, 2, 0).expect("parses");
        assert_eq!(robots, vec![plain.clone(), lone.clone()]);
        // With a metric each.
        let with = |f: &Figures, v| Figures {
            metrics: vec![v],
            ..f.clone()
        };
        let measured = [with(&plain, None), with(&lone, Some(2.5))];
        let row = csv::StringRecord::from(team_row(6, &two, &measured));
        let kinds = &crate::eval::metric::CROWD[..1];
        assert_eq!(row.len(), team_columns(2, kinds).len());
        let (_, _, robots) = parse_team(&row, 2, 1).expect("parses");
        assert_eq!(robots, measured);
    }
}
