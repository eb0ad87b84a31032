//! A comparison's files: the tables (for a terminal, Markdown and HTML from one description),
//! the pictures, `compare.json`, `seeds.csv`, and `report.md` / `report.html` (self-contained,
//! pictures inlined). Every file is written atomically.

use super::result::{Comparison, PolicyResult};
use super::stats::ALPHA;
use crate::eval::Outcome;
use crate::io::{write_atomic, OutputError};
use crate::render::chart;
use base64::Engine as _;
use std::fmt::Write as _;
use std::path::Path;

/// A table: a header row and rows of cells.
#[derive(Clone, Debug, PartialEq)]
pub struct Table {
    /// Column names.
    pub header: Vec<String>,
    /// Rows, each as long as the header.
    pub rows: Vec<Vec<String>>,
}

impl Table {
    /// The table aligned in columns for a terminal (first column left, the rest right).
    pub fn text(&self) -> String {
        let cols = self.header.len();
        let width = |c: usize| {
            std::iter::once(&self.header)
                .chain(&self.rows)
                .map(|r| r.get(c).map_or(0, |s| s.chars().count()))
                .max()
                .unwrap_or(0)
        };
        let widths: Vec<usize> = (0..cols).map(width).collect();
        let line = |r: &Vec<String>| {
            let cells: Vec<String> = (0..cols)
                .map(|c| {
                    let s = r.get(c).map_or("", String::as_str);
                    let w = widths[c];
                    if c == 0 {
                        format!("{s:<w$}")
                    } else {
                        format!("{s:>w$}")
                    }
                })
                .collect();
            cells.join("  ").trim_end().to_string() + "\n"
        };
        let rule = "-".repeat(widths.iter().sum::<usize>() + 2 * cols.saturating_sub(1)) + "\n";
        let mut out = line(&self.header);
        out.push_str(&rule);
        for r in &self.rows {
            out.push_str(&line(r));
        }
        out
    }

    fn markdown(&self) -> String {
        let esc = |s: &str| s.replace('|', "\\|");
        let mut out = format!(
            "| {} |\n|{}\n",
            self.header
                .iter()
                .map(|h| esc(h))
                .collect::<Vec<_>>()
                .join(" | "),
            self.header
                .iter()
                .enumerate()
                .map(|(i, _)| if i == 0 { " --- |" } else { " ---: |" })
                .collect::<String>()
        );
        for r in &self.rows {
            let _ = writeln!(
                out,
                "| {} |",
                r.iter().map(|c| esc(c)).collect::<Vec<_>>().join(" | ")
            );
        }
        out
    }

    fn html(&self) -> String {
        let mut out = String::from("<table>\n<tr>");
        for h in &self.header {
            let _ = write!(out, "<th>{}</th>", escape(h));
        }
        out.push_str("</tr>\n");
        for r in &self.rows {
            out.push_str("<tr>");
            for c in r {
                let _ = write!(out, "<td>{}</td>", escape(c));
            }
            out.push_str("</tr>\n");
        }
        out.push_str("</table>\n");
        out
    }
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

fn pct(x: f64) -> String {
    format!("{:.1}%", 100.0 * x)
}

/// A difference of rates in percentage points, signed.
fn signed(x: f64) -> String {
    format!("{:+.1}", 100.0 * x)
}

fn p_value(p: f64) -> String {
    if p < 1e-300 {
        // Below what a double holds after the adjustment.
        "< 1e-300".to_string()
    } else if p < 1e-4 {
        format!("{p:.1e}")
    } else {
        format!("{p:.4}")
    }
}

impl Comparison {
    /// The seeds in words: `1000 seeds (0 to 999)`, or `12 seeds (a list from 3 to 40)`.
    pub fn seeds_text(&self) -> String {
        if self.seeds_contiguous {
            format!(
                "{} seeds ({} to {})",
                self.seed_count, self.seed_start, self.seed_last
            )
        } else {
            format!(
                "{} seeds (a list from {} to {})",
                self.seed_count, self.seed_start, self.seed_last
            )
        }
    }

    /// The per-policy table.
    pub fn policy_table(&self) -> Table {
        let moving = self.policies.iter().any(|p| p.summary.moving.is_some());
        let mut header: Vec<String> = [
            "policy",
            "success (95% CI)",
            "SPL",
            "collisions/ep",
            "mean steps",
            "mean path px",
            "time-outs",
            "gave up",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        if moving {
            header.push("moving contacts/ep".into());
        }
        let ends_collision = self.policies.iter().any(|p| p.summary.collision_ends > 0);
        let ends_reward = self.policies.iter().any(|p| p.summary.reward_min_ends > 0);
        if ends_collision {
            header.push("ended by collision".into());
        }
        if ends_reward {
            header.push("ended by reward_min".into());
        }
        // The metrics asked for beyond the standard ones (the same for every policy).
        let metrics: Vec<String> = self
            .policies
            .first()
            .map(|p| p.summary.metrics.iter().map(|m| m.name.clone()).collect())
            .unwrap_or_default();
        header.extend(metrics.iter().cloned());
        let rows = self
            .policies
            .iter()
            .map(|p| {
                let s = &p.summary;
                let mut row = vec![
                    p.label.clone(),
                    format!(
                        "{} ({}-{})",
                        pct(s.success_rate),
                        pct(s.success_ci95[0]),
                        pct(s.success_ci95[1])
                    ),
                    format!("{:.3}", s.spl),
                    format!("{:.2}", s.collisions_per_episode),
                    format!("{:.1}", s.mean_steps),
                    format!("{:.1}", s.mean_path_length_px),
                    s.timeouts.to_string(),
                    s.stuck.to_string(),
                ];
                if moving {
                    row.push(s.moving.as_ref().map_or(String::new(), |m| {
                        format!("{:.2}", m.dynamic_collisions_per_episode)
                    }));
                }
                if ends_collision {
                    row.push(s.collision_ends.to_string());
                }
                if ends_reward {
                    row.push(s.reward_min_ends.to_string());
                }
                for name in &metrics {
                    let m = s.metrics.iter().find(|m| &m.name == name);
                    row.push(match m {
                        Some(m) if m.episodes > 0 => format!("{:.3}", m.mean),
                        _ => String::new(),
                    });
                }
                row
            })
            .collect();
        Table { header, rows }
    }

    /// The team table of a team comparison (none otherwise).
    pub fn team_table(&self) -> Option<Table> {
        if self.policies.iter().all(|p| p.team.is_none()) {
            return None;
        }
        let header = [
            "policy",
            "team success (95% CI)",
            "robots arrived",
            "deadlocks",
            "mean makespan",
            "robot contacts/ep",
            "wall collisions/ep",
            "mean path px (team)",
            "SPL",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        let rows = self
            .policies
            .iter()
            .map(|p| match &p.team {
                Some(t) => vec![
                    p.label.clone(),
                    format!(
                        "{} ({}-{})",
                        pct(t.team_success_rate),
                        pct(t.team_success_ci95[0]),
                        pct(t.team_success_ci95[1])
                    ),
                    pct(t.robot_success_rate),
                    t.deadlocks.to_string(),
                    if t.team_successes > 0 {
                        format!("{:.1}", t.mean_makespan)
                    } else {
                        "-".to_string()
                    },
                    format!("{:.2}", t.robot_collisions_per_episode),
                    format!("{:.2}", t.collisions_per_episode),
                    format!("{:.1}", t.mean_path_length_px),
                    format!("{:.3}", t.spl),
                ],
                None => vec![p.label.clone()],
            })
            .collect();
        Some(Table { header, rows })
    }

    /// The headings of the policy tables: the team's and the robots', or the policies'.
    fn policy_headings(&self) -> (&'static str, &'static str) {
        (
            "Teams (a success: every robot arrived)",
            "Robots (every robot of every team episode)",
        )
    }

    /// The per-pair table.
    pub fn pair_table(&self) -> Table {
        let team = self.policies.iter().any(|p| p.team.is_some());
        let header = [
            "pair (a vs b)",
            if team {
                "team success a-b, pp (95% CI)"
            } else {
                "success a-b, pp (95% CI)"
            },
            "only a / only b",
            "McNemar p",
            "Holm p",
            "SPL a-b (95% CI)",
        ]
        .iter()
        .map(|s| s.to_string())
        .chain([format!(
            "better (success: Holm p < {ALPHA}; SPL: 95% CI excludes 0)"
        )])
        .collect();
        let rows = self
            .pairs
            .iter()
            .map(|p| {
                vec![
                    format!("{} vs {}", p.a, p.b),
                    match p.success_diff_ci95 {
                        Some([lo, hi]) => format!(
                            "{} ({:+.1} to {:+.1})",
                            signed(p.success_diff),
                            100.0 * lo,
                            100.0 * hi
                        ),
                        None => signed(p.success_diff),
                    },
                    format!("{} / {}", p.a_only, p.b_only),
                    p_value(p.mcnemar_p),
                    p_value(p.holm_p),
                    match p.spl_diff_ci95 {
                        Some([lo, hi]) => format!("{:+.3} ({lo:+.3} to {hi:+.3})", p.spl_diff),
                        None => format!("{:+.3}", p.spl_diff),
                    },
                    p.verdict.clone(),
                ]
            })
            .collect();
        Table { header, rows }
    }

    /// Success by difficulty bin, one table per figure.
    pub fn difficulty_tables(&self) -> Vec<(String, Table)> {
        let Some(by) = &self.by_difficulty else {
            return Vec::new();
        };
        by.iter()
            .map(|b| {
                let mut header = vec![b.figure.name().to_string(), "seeds".to_string()];
                header.extend(self.policies.iter().map(|p| format!("{} success", p.label)));
                let rows =
                    b.bins
                        .iter()
                        .map(|bin| {
                            let mut row = vec![bin.bin.label.clone(), bin.seeds.to_string()];
                            row.extend(bin.success_rate.iter().zip(&bin.success_ci95).map(
                                |(r, ci)| format!("{} ({}-{})", pct(*r), pct(ci[0]), pct(ci[1])),
                            ));
                            row
                        })
                        .collect();
                let title = if b.unbinned > 0 {
                    format!(
                        "by {} ({} seeds without a path left out)",
                        b.figure.name(),
                        b.unbinned
                    )
                } else {
                    format!("by {}", b.figure.name())
                };
                (title, Table { header, rows })
            })
            .collect()
    }

    /// Everything a terminal shows at the end of `ronap compare`.
    pub fn table(&self) -> String {
        let mut out = format!(
            "{} on {}\n{}\n\n",
            self.seeds_text(),
            self.scenes,
            self.success_rule
        );
        if let Some(t) = self.team_table() {
            let (team, robots) = self.policy_headings();
            let _ = write!(out, "{team}\n{}\n{robots}\n", t.text());
        }
        out.push_str(&self.policy_table().text());
        out.push('\n');
        out.push_str(&self.pair_table().text());
        for (title, t) in self.difficulty_tables() {
            let _ = write!(out, "\n{title}\n{}", t.text());
        }
        out
    }

    /// `seeds.csv`: each seed's difficulty (when computed) and each policy's outcome, SPL and
    /// steps there.
    pub fn write_seeds(&self, out: &mut dyn std::io::Write) -> std::io::Result<()> {
        let mut w = csv::Writer::from_writer(out);
        let with_difficulty = !self.difficulty.is_empty();
        let mut header = vec!["seed".to_string()];
        if with_difficulty {
            for h in [
                "straight_px",
                "geodesic_px",
                "ratio",
                "narrowest_gap_px",
                "turns",
            ] {
                header.push(h.into());
            }
        }
        for p in &self.policies {
            for h in ["outcome", "spl", "steps"] {
                header.push(format!("{}_{h}", p.label));
            }
        }
        w.write_record(&header)?;
        let opt =
            |v: Option<f64>, digits: usize| v.map_or(String::new(), |v| format!("{v:.digits$}"));
        for i in 0..self.seed_count {
            let mut row = vec![self.policies[0].seeds[i].seed.to_string()];
            if with_difficulty {
                match self.difficulty.get(i).copied().flatten() {
                    Some(d) => {
                        row.push(format!("{:.3}", d.straight_px));
                        row.push(opt(d.geodesic_px, 3));
                        row.push(opt(d.ratio, 4));
                        row.push(opt(d.narrowest_gap_px, 3));
                        row.push(d.turns.map_or(String::new(), |t| t.to_string()));
                    }
                    None => row.extend(std::iter::repeat_n(String::new(), 5)),
                }
            }
            for p in &self.policies {
                let s = &p.seeds[i];
                row.push(s.outcome.name().into());
                row.push(format!("{:.4}", s.spl));
                row.push(s.steps.to_string());
            }
            w.write_record(&row)?;
        }
        w.flush()
    }
}

/// A picture of the report: its file name, what it shows, and the PNG.
struct Picture {
    file: &'static str,
    alt: String,
    png: Vec<u8>,
}

fn png(image: &image::RgbImage) -> Result<Vec<u8>, image::ImageError> {
    crate::render::png_bytes(image)
}

/// The comparison's pictures.
fn pictures(
    c: &Comparison,
    sheet: Option<&image::RgbImage>,
) -> Vec<(&'static str, String, image::RgbImage)> {
    let bars: Vec<chart::PolicyBars> = c
        .policies
        .iter()
        .map(|p: &PolicyResult| {
            // A team comparison's bars are the team's success (what the pairs test).
            let (rate, ci) = match &p.team {
                Some(t) => (t.team_success_rate, t.team_success_ci95),
                None => (p.summary.success_rate, p.summary.success_ci95),
            };
            chart::PolicyBars {
                name: p.label.clone(),
                success_rate: rate,
                success_ci95: ci,
                spl: p.seeds.iter().map(|s| s.spl).collect(),
            }
        })
        .collect();
    let e = &c.config.episode;
    let title = match c.config.team_size() {
        0 => format!(
            "{} seeds, {}; success: within {} px of the goal in {} steps",
            c.seed_count, c.scenes, e.goal_tolerance_px, e.max_steps
        ),
        n => format!(
            "{} seeds, {}; team success: all {n} robots arrive in {} steps",
            c.seed_count, c.scenes, e.max_steps
        ),
    };
    let names: Vec<String> = c.policies.iter().map(|p| p.label.clone()).collect();
    let seeds: Vec<u64> = c.policies[0].seeds.iter().map(|s| s.seed).collect();
    let outcomes: Vec<Vec<Outcome>> = c
        .policies
        .iter()
        .map(|p| p.seeds.iter().map(|s| s.outcome).collect())
        .collect();
    let mut out = vec![
        (
            "compare.png",
            "Success rate with 95% intervals, and SPL distributions".to_string(),
            chart::compare_chart(&title, &bars),
        ),
        (
            "outcomes.png",
            "Each seed's outcome per policy; the bottom row marks disagreements".to_string(),
            chart::outcome_strip(&names, &seeds, &outcomes),
        ),
    ];
    if let Some(sheet) = sheet {
        out.push((
            "disagreements.png",
            "Trajectories on the seeds where the policies disagree most".to_string(),
            sheet.clone(),
        ));
    }
    if let Some(by) = &c.by_difficulty {
        if let Some(first) = by.first() {
            let bins: Vec<String> = first.bins.iter().map(|b| b.bin.label.clone()).collect();
            let series: Vec<chart::Series> = c
                .policies
                .iter()
                .enumerate()
                .map(|(k, p)| chart::Series {
                    name: p.label.clone(),
                    values: first
                        .bins
                        .iter()
                        .map(|b| (b.success_rate[k], b.success_ci95[k]))
                        .collect(),
                })
                .collect();
            out.push((
                "difficulty.png",
                format!("Success by {}", first.figure.name()),
                chart::grouped_bars(
                    &format!(
                        "success by {} ({} bins of about equal size)",
                        first.figure.name(),
                        first.bins.len()
                    ),
                    &bins,
                    &series,
                ),
            ));
        }
    }
    out
}

/// Every file a comparison writes into its directory (besides `runs/`).
pub const FILES: [&str; 8] = [
    "compare.png",
    "outcomes.png",
    "disagreements.png",
    "difficulty.png",
    "seeds.csv",
    "compare.json",
    "report.md",
    "report.html",
];

/// Refuses `dir` when it holds a comparison ([`OutputError::Finished`]) or files of something else
/// ([`OutputError::NotARun`]): a comparison writes only into an empty or new directory, unless
/// told to replace.
pub fn check_empty(dir: &Path) -> Result<(), OutputError> {
    if dir.join("compare.json").exists() {
        return Err(OutputError::Finished {
            dir: dir.to_path_buf(),
            file: "compare.json",
        });
    }
    // A run is named by its summary (whatever entry comes first).
    if dir.join("summary.json").exists() {
        return Err(OutputError::NotARun {
            dir: dir.to_path_buf(),
            file: "summary.json".into(),
        });
    }
    let mut entries = std::fs::read_dir(dir).into_iter().flatten().flatten();
    let other = entries.find(|e| {
        let name = e.file_name();
        // An interrupted comparison's runs/ (each run there guards itself).
        name != "runs" && name != crate::io::LOCK_FILE
    });
    match other {
        Some(e) => Err(OutputError::NotARun {
            dir: dir.to_path_buf(),
            file: e.file_name().to_string_lossy().into_owned(),
        }),
        None => Ok(()),
    }
}

/// Removes what an earlier comparison wrote into `dir` (the files of [`FILES`] and the players in
/// `players/`, not `runs/`), so a directory never mixes two comparisons.
pub fn remove_earlier(dir: &Path) -> Result<(), OutputError> {
    let players = std::fs::read_dir(dir.join("players"))
        .into_iter()
        .flatten()
        .flatten()
        .map(|e| e.path())
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with("seed-") && n.ends_with(".html"))
        });
    for path in FILES.iter().map(|f| dir.join(f)).chain(players) {
        match std::fs::remove_file(&path) {
            Ok(()) => {}
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(source) => return Err(OutputError::Io { path, source }),
        }
    }
    Ok(())
}

/// Writes every file of the comparison into `dir`; the report links the players of `players`
/// (seeds, each `players/seed-SEED.html`).
pub fn write_all(
    dir: &Path,
    c: &Comparison,
    sheet: Option<&image::RgbImage>,
    players: &[u64],
) -> Result<(), OutputError> {
    let mut shown = Vec::new();
    for (file, alt, image) in pictures(c, sheet) {
        let bytes = png(&image).map_err(|e| OutputError::Format {
            path: dir.join(file),
            message: e.to_string(),
        })?;
        write_atomic(&dir.join(file), |w| w.write_all(&bytes))?;
        shown.push(Picture {
            file,
            alt,
            png: bytes,
        });
    }
    write_atomic(&dir.join("seeds.csv"), |w| c.write_seeds(w))?;
    write_atomic(&dir.join("compare.json"), |w| {
        serde_json::to_writer_pretty(&mut *w, c)?;
        w.write_all(b"\n")
    })?;
    let config = toml::to_string(c.config.as_sim_config()).unwrap_or_default();
    let shown = Shown {
        pictures: &shown,
        players,
    };
    save_text(&dir.join("report.md"), &markdown(c, &shown, &config))?;
    save_text(&dir.join("report.html"), &html(c, &shown, &config))?;
    Ok(())
}

/// Writes `text` to `path` atomically.
fn save_text(path: &Path, text: &str) -> Result<(), OutputError> {
    write_atomic(path, |w| w.write_all(text.as_bytes()))
}

fn intro(c: &Comparison) -> String {
    let names: Vec<&str> = c.policies.iter().map(|p| p.name.as_str()).collect();
    format!(
        "{} policies ({}) on the same {}, {}. Each pair is tested on the seeds where exactly one \
         of them succeeded (McNemar's exact test, p-values Holm-adjusted over the {} pairs; a \
         difference is called significant below {}); SPL differences are paired by seed with a \
         95% bootstrap interval (not adjusted for the number of pairs). A pair with fewer than {} \
         seeds where exactly one succeeded cannot show a significant success difference at all.",
        c.policies.len(),
        names.join(", "),
        c.seeds_text(),
        c.scenes,
        c.pairs.len(),
        ALPHA,
        super::stats::min_discordant()
    )
}

fn runs_note(c: &Comparison) -> Vec<String> {
    c.policies
        .iter()
        .map(|p| {
            let dir = p
                .run_dir
                .as_ref()
                .map_or("(not written)".to_string(), |d| d.display().to_string());
            format!(
                "{}: `{}` {} {}",
                p.label,
                p.name,
                if p.reused { "read from" } else { "run into" },
                dir
            )
        })
        .collect()
}

/// What a report shows beside its tables: the pictures, and the seeds whose players it links.
struct Shown<'a> {
    pictures: &'a [Picture],
    players: &'a [u64],
}

/// The line above the links to the players of `players` (seeds), of the seeds of `c` where one
/// policy succeeded and another failed.
fn players_intro(c: &Comparison, players: &[u64]) -> String {
    let all = super::disagreements::success_disagreements(&c.policies, None).len();
    let seeds = |n: usize| {
        if n == 1 {
            "seed".to_string()
        } else {
            format!("{n} seeds")
        }
    };
    let which = if players.len() < all {
        format!(
            "the {} that disagree most of the {} where one policy succeeded and another failed \
             (`--players all` for every one)",
            seeds(players.len()),
            seeds(all)
        )
    } else {
        format!(
            "the {} where one policy succeeded and another failed",
            seeds(all)
        )
    };
    format!(
        "Each policy's episode side by side on one timeline (play, step, scrub, follow a robot), \
         for {which}:"
    )
}

fn markdown(c: &Comparison, shown: &Shown<'_>, config: &str) -> String {
    let pictures = shown.pictures;
    let mut md = String::from("# ronap compare\n\n");
    let _ = writeln!(md, "{}\n\n**{}**\n", intro(c), c.success_rule);
    match c.team_table() {
        Some(t) => {
            let (team, robots) = c.policy_headings();
            let _ = writeln!(md, "## {team}\n\n{}", t.markdown());
            let _ = writeln!(md, "## {robots}\n\n{}", c.policy_table().markdown());
        }
        None => {
            let _ = writeln!(md, "## Policies\n\n{}", c.policy_table().markdown());
        }
    }
    let _ = writeln!(md, "## Pairs\n\n{}", c.pair_table().markdown());
    for p in pictures {
        let _ = writeln!(md, "![{}]({})\n", p.alt, p.file);
    }
    if !shown.players.is_empty() {
        let links: Vec<String> = shown
            .players
            .iter()
            .map(|s| format!("[seed {s}](players/seed-{s:06}.html)"))
            .collect();
        let _ = writeln!(
            md,
            "## Players\n\n{}\n{}\n",
            players_intro(c, shown.players),
            links.join(", ")
        );
    }
    let tables = c.difficulty_tables();
    if !tables.is_empty() {
        md.push_str("## By difficulty\n\n");
        for (title, t) in tables {
            let _ = writeln!(md, "### {title}\n\n{}", t.markdown());
        }
    }
    md.push_str("## Runs\n\n");
    for line in runs_note(c) {
        let _ = writeln!(md, "- {line}");
    }
    let _ = writeln!(
        md,
        "\n## Reproduce\n\n```sh\n{}\n```\n\nronap {}\n\n## Configuration\n\n```toml\n{}```",
        c.command, c.ronap_version, config
    );
    md
}

fn html(c: &Comparison, shown: &Shown<'_>, config: &str) -> String {
    let pictures = shown.pictures;
    let mut h = String::from(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <title>ronap compare</title>\n<style>\n\
         body{font-family:system-ui,sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;color:#222}\n\
         table{border-collapse:collapse;margin:1em 0}th,td{border:1px solid #ccc;padding:4px 8px}\n\
         td{text-align:right}td:first-child{text-align:left}th{background:#f3f3f3}\n\
         img{max-width:100%;border:1px solid #ddd;margin:0.5em 0}pre{background:#f6f6f6;padding:1em;overflow:auto}\n\
         </style>\n</head>\n<body>\n<h1>ronap compare</h1>\n",
    );
    let _ = writeln!(
        h,
        "<p>{}</p>\n<p><strong>{}</strong></p>",
        escape(&intro(c)),
        escape(&c.success_rule)
    );
    match c.team_table() {
        Some(t) => {
            let (team, robots) = c.policy_headings();
            let _ = writeln!(h, "<h2>{team}</h2>\n{}", t.html());
            let _ = writeln!(h, "<h2>{robots}</h2>\n{}", c.policy_table().html());
        }
        None => {
            let _ = writeln!(h, "<h2>Policies</h2>\n{}", c.policy_table().html());
        }
    }
    let _ = writeln!(h, "<h2>Pairs</h2>\n{}", c.pair_table().html());
    let b64 = base64::engine::general_purpose::STANDARD;
    for p in pictures {
        let _ = writeln!(
            h,
            "<figure><img alt=\"{}\" src=\"data:image/png;base64,{}\"><figcaption>{}</figcaption></figure>",
            escape(&p.alt),
            b64.encode(&p.png),
            escape(&p.alt)
        );
    }
    if !shown.players.is_empty() {
        let _ = write!(
            h,
            "<h2>Players</h2>\n<p>{}</p>\n<p class=\"players\">",
            escape(&players_intro(c, shown.players))
        );
        for s in shown.players {
            let _ = write!(h, " <a href=\"players/seed-{s:06}.html\">seed {s}</a>");
        }
        h.push_str("</p>\n");
    }
    let tables = c.difficulty_tables();
    if !tables.is_empty() {
        h.push_str("<h2>By difficulty</h2>\n");
        for (title, t) in tables {
            let _ = writeln!(h, "<h3>{}</h3>\n{}", escape(&title), t.html());
        }
    }
    h.push_str("<h2>Runs</h2>\n<ul>\n");
    for line in runs_note(c) {
        let _ = writeln!(h, "<li>{}</li>", escape(&line.replace('`', "")));
    }
    let _ = write!(
        h,
        "</ul>\n<h2>Reproduce</h2>\n<pre>{}</pre>\n<p>ronap {}</p>\n<h2>Configuration</h2>\n<pre>{}</pre>\n</body>\n</html>\n",
        escape(&c.command),
        escape(&c.ronap_version),
        escape(config)
    );
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tables_align_and_escape() {
        let t = Table {
            header: vec!["policy".into(), "success".into()],
            rows: vec![
                vec!["a|b".into(), "50.0%".into()],
                vec!["<c>".into(), "5%".into()],
            ],
        };
        let text = t.text();
        assert_eq!(text.lines().nth(2), Some("a|b       50.0%"));
        assert_eq!(text.lines().nth(1), Some("-".repeat(15).as_str()));
        assert!(t.markdown().contains("a\\|b"));
        assert!(t.html().contains("&lt;c&gt;"));
    }
}
