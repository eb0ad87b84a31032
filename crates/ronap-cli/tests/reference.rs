//! The reference pages in `docs/reference/` against the code: `cli.md` is rendered from the clap
//! definitions and `config.md` from `ronap config`'s documented TOML, and each must equal its
//! committed file; every column of every CSV file a run, a team run, a comparison, a data
//! collection and a training write must be named in `outputs.md`.
//!
//! After changing a flag or a configuration field, regenerate the pages with the command that
//! [`REGENERATE`] gives, and commit them.

use crate::util::{ok, repo_root, ronap};
use clap::CommandFactory;
use std::fmt::Write as _;
use std::path::Path;

/// The one-line command that rewrites the generated reference pages.
const REGENERATE: &str =
    "RONAP_UPDATE_DOCS=1 cargo test --release --locked -p ronap-cli --test integration reference";

/// Compares a generated page with its committed file; rewrites the file instead when
/// `RONAP_UPDATE_DOCS` is set.
fn check_generated(relative: &str, generated: &str) {
    let path = repo_root().join(relative);
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    if committed == generated {
        return;
    }
    if std::env::var_os("RONAP_UPDATE_DOCS").is_some() {
        std::fs::write(&path, generated).unwrap();
        return;
    }
    let line = committed
        .lines()
        .zip(generated.lines())
        .position(|(a, b)| a != b)
        .unwrap_or_else(|| committed.lines().count().min(generated.lines().count()));
    panic!(
        "{relative} is out of date with the code (first difference at line {}:\n  committed: {:?}\n  generated: {:?}).\nRegenerate it with:\n  {REGENERATE}",
        line + 1,
        committed.lines().nth(line).unwrap_or("<end of file>"),
        generated.lines().nth(line).unwrap_or("<end of file>"),
    );
}

/// Text on one line, for a Markdown list item or table cell.
fn one_line(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// A flag or argument as a user types it: `-s, --seeds <N>`, `<FILE>`.
fn arg_name(arg: &clap::Arg) -> String {
    let values: Vec<String> = arg
        .get_value_names()
        .map(|names| names.iter().map(|n| format!("<{n}>")).collect())
        .unwrap_or_else(|| vec![format!("<{}>", arg.get_id().as_str().to_uppercase())]);
    if arg.is_positional() {
        return values.join(" ");
    }
    let mut name = String::new();
    if let Some(short) = arg.get_short() {
        name.push_str(&format!("-{short}"));
    }
    if let Some(long) = arg.get_long() {
        if !name.is_empty() {
            name.push_str(", ");
        }
        name.push_str(&format!("--{long}"));
    }
    if arg.get_action().takes_values() {
        name.push(' ');
        // A value that may be left out (`ronap config --scenario` alone prints an example).
        let optional = arg.get_num_args().is_some_and(|n| n.min_values() == 0);
        if optional {
            name.push_str(&format!("[{}]", values.join(" ")));
        } else {
            name.push_str(&values.join(" "));
        }
    }
    name
}

/// One command's section of `cli.md`, then its subcommands'.
fn render_command(out: &mut String, cmd: &mut clap::Command, path: &str) {
    let usage = cmd.render_usage().to_string();
    let usage = usage.trim().trim_start_matches("Usage:").trim();
    writeln!(out, "## `{path}`\n").unwrap();
    if let Some(about) = cmd.get_long_about().or(cmd.get_about()) {
        writeln!(out, "{}\n", about.to_string().trim()).unwrap();
    }
    writeln!(out, "```text\n{}\n```\n", usage.replace("\n       ", "\n")).unwrap();
    let args: Vec<&clap::Arg> = cmd
        .get_arguments()
        .filter(|a| !a.is_hide_set() && !matches!(a.get_id().as_str(), "help" | "version"))
        .collect();
    if !args.is_empty() {
        let mut heading: Option<&str> = None;
        for arg in &args {
            if arg.get_help_heading() != heading {
                heading = arg.get_help_heading();
                if let Some(h) = heading {
                    writeln!(out, "\n{h}:\n").unwrap();
                }
            }
            let help = arg
                .get_long_help()
                .or(arg.get_help())
                .map(|h| one_line(&h.to_string()))
                .unwrap_or_default();
            write!(out, "- `{}`", arg_name(arg)).unwrap();
            if !help.is_empty() {
                write!(out, ": {help}").unwrap();
            }
            let defaults: Vec<String> = arg
                .get_default_values()
                .iter()
                .map(|v| v.to_string_lossy().into_owned())
                .collect();
            if arg.get_action().takes_values() && !defaults.is_empty() {
                write!(out, " [default: `{}`]", defaults.join(",")).unwrap();
            }
            let possible: Vec<String> = arg
                .get_possible_values()
                .iter()
                .filter(|p| !p.is_hide_set())
                .map(|p| format!("`{}`", p.get_name()))
                .collect();
            if arg.get_action().takes_values() && !possible.is_empty() {
                write!(out, " [one of: {}]", possible.join(", ")).unwrap();
            }
            let aliases: Vec<String> = arg
                .get_visible_aliases()
                .unwrap_or_default()
                .iter()
                .map(|a| format!("`--{a}`"))
                .collect();
            if !aliases.is_empty() {
                write!(out, " [aliases: {}]", aliases.join(", ")).unwrap();
            }
            out.push('\n');
        }
        out.push('\n');
    }
    let names: Vec<String> = cmd
        .get_subcommands()
        .filter(|s| !s.is_hide_set())
        .map(|s| s.get_name().to_string())
        .collect();
    for name in names {
        if name == "help" {
            continue;
        }
        if let Some(sub) = cmd.find_subcommand_mut(&name) {
            let mut sub = sub.clone();
            render_command(out, &mut sub, &format!("{path} {name}"));
        }
    }
}

/// `docs/reference/cli.md`: every command, flag, default and choice, from the clap definitions.
fn cli_reference() -> String {
    let mut cmd = ronap_cli::Cli::command();
    cmd.build();
    let mut out = String::from(
        "# Command-line reference\n\n\
         <!-- Generated from the clap definitions in crates/ronap-cli by the test \
         crates/ronap-cli/tests/reference.rs; do not edit by hand. -->\n\n\
         Every command of `ronap`, its flags, their defaults and choices, as `ronap COMMAND --help` \
         prints them. Flags that set a configuration field override the `--config` or \
         `--scenario` file; [config.md](config.md) lists those fields. Exit codes: 0 done, 1 a \
         gate failed (`--min-success`), 2 bad input (one line on stderr naming the flag, file or \
         value). `ronap --version` prints the package version and the model version.\n\n",
    );
    let names: Vec<String> = cmd
        .get_subcommands()
        .filter(|s| !s.is_hide_set() && s.get_name() != "help")
        .map(|s| s.get_name().to_string())
        .collect();
    out.push_str("Commands:\n\n");
    for name in &names {
        let about = cmd
            .find_subcommand(name)
            .and_then(|s| s.get_about())
            .map(|a| one_line(&a.to_string()))
            .unwrap_or_default();
        writeln!(out, "- [`ronap {name}`](#ronap-{name}): {about}").unwrap();
    }
    out.push('\n');
    render_command(&mut out, &mut cmd, "ronap");
    while out.ends_with("\n\n") {
        out.pop();
    }
    out
}

/// One field of `config.md`: its section, name, meaning, value and whether it is set by default.
struct Field {
    section: String,
    name: String,
    doc: String,
    value: String,
    set: bool,
}

/// The fields of a documented TOML text as `ronap config` prints it, in order, each section's
/// introduction (the comment before an array-of-tables header) beside them.
fn parse_documented(text: &str) -> (Vec<Field>, Vec<(String, String)>) {
    let mut fields = Vec::new();
    let mut intros = Vec::new();
    let mut section = String::new();
    let mut doc: Vec<String> = Vec::new();
    for line in text.lines() {
        let line = line.trim_end();
        if line.is_empty() {
            doc.clear();
            continue;
        }
        let header = line.trim_start_matches("# ");
        if header.starts_with('[') && !header.contains('=') {
            let name = header.trim_matches(|c| c == '[' || c == ']').to_string();
            if header.starts_with("[[") && !doc.is_empty() {
                intros.push((name.clone(), doc.join(" ")));
            }
            section = name;
            doc.clear();
            continue;
        }
        let (commented, body) = match line.strip_prefix("# ") {
            Some(rest) => (true, rest),
            None => (false, line),
        };
        let assignment = body.split_once(" = ").filter(|(key, _)| {
            !key.is_empty() && key.chars().all(|c| c.is_ascii_lowercase() || c == '_')
        });
        match assignment {
            Some((key, value)) if !section.is_empty() => {
                fields.push(Field {
                    section: section.clone(),
                    name: key.to_string(),
                    doc: doc.join(" "),
                    value: value.to_string(),
                    set: !commented,
                });
                doc.clear();
            }
            _ if commented => doc.push(body.to_string()),
            _ => doc.clear(),
        }
    }
    (fields, intros)
}

/// The TOML type of a value as written (an unset one without an example: as its documentation
/// describes it, a table `{ ... }` or a choice of quoted words).
fn value_type(value: &str, doc: &str) -> &'static str {
    if value == "..." {
        return if doc.contains(": { ") {
            "table"
        } else if doc.contains('"') {
            "string"
        } else {
            "see meaning"
        };
    }
    match value.chars().next() {
        Some('"') => "string",
        Some('[') if value.starts_with("[[") || value.starts_with("[ [") => "array of [x, y]",
        Some('[') => "array of numbers",
        Some('{') => "table",
        _ if value == "true" || value == "false" => "boolean",
        _ if value.contains('.') || value.contains('e') || value == "inf" => "float",
        _ => "integer",
    }
}

/// The unit of a field, from its name and its documentation.
fn unit(section: &str, name: &str, doc: &str) -> &'static str {
    let doc = doc.trim_end_matches('.');
    let rules: [(bool, &str); 15] = [
        (doc.contains("px per step^2"), "px/step^2"),
        (doc.contains("degrees per step^2"), "deg/step^2"),
        (doc.contains("px per step"), "px/step"),
        (doc.contains("degrees per step"), "deg/step"),
        (doc.contains("per px^2"), "1/px^2"),
        (doc.contains(", px^2"), "px^2"),
        (doc.contains("per px of"), "reward/px"),
        (
            (section == "reward" && matches!(name, "collision" | "turn" | "success"))
                || name == "reward_min",
            "reward",
        ),
        (
            name.ends_with("_px") || doc.ends_with(", px") || doc.contains(", px "),
            "px",
        ),
        (doc.contains("[x px, y px, heading deg]"), "px, deg"),
        (doc.contains("[x px, y px]") || doc.contains("], px"), "px"),
        (name.ends_with("_deg") || doc.contains(", degrees"), "deg"),
        (
            name.ends_with("_steps") || doc.starts_with("Steps"),
            "steps",
        ),
        (doc.contains("0 to 1") || doc.contains("0-1"), "fraction"),
        (name == "then" || name == "pattern", ""),
    ];
    rules
        .iter()
        .find(|(hit, _)| *hit)
        .map(|&(_, u)| u)
        .unwrap_or("")
}

/// A table cell: pipes escaped, on one line.
fn cell(text: &str) -> String {
    one_line(text).replace('|', "\\|")
}

/// A scenario whose first `[[moving]]` and `[[robots]]` entries leave every field at its default
/// and whose later entries set the optional ones.
const ENTRIES: &str = r#"
[[moving]]
count = 1

[[moving]]
motion = "linear"
direction_deg = 45.0
start = [100.0, 100.0]

[[moving]]
motion = "orca"
pattern = "circle"
pattern_center = [500.0, 500.0]
pattern_radius_px = 100.0
jitter_px = 5.0
max_speed_px = 3.0
sees_robots = true

[[moving]]
motion = "social_force"
goal = [800.0, 800.0]

[[robots]]
count = 1

[[robots]]
start = [100.0, 100.0, 0.0]
goal = [900.0, 900.0]
policy = "geodesic"
radius_px = 5.0
move_speed_px = 5.0
turn_speed_deg = 15.0
laser_beams = 17
laser_range_px = 50.0
laser_fov_deg = 180.0
jitter_px = 2.0

[[obstacles]]
shape = "box"
min = [100.0, 100.0]
max = [120.0, 120.0]
"#;

/// `ronap config` with a scenario file holding `text`.
fn documented_with(text: &str) -> String {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("entries.toml");
    std::fs::write(&file, text).unwrap();
    ok(&ronap(&["config", "--scenario", file.to_str().unwrap()]))
}

/// `docs/reference/config.md`: every configuration and scenario field, from `ronap config`.
fn config_reference() -> String {
    let defaults = ok(&ronap(&["config"]));
    // The first entry of each array of tables has every field at its default; the others set
    // the optional fields, which gives their types and an example value.
    let entries = documented_with(ENTRIES);
    let (mut fields, intros) = parse_documented(&defaults);
    let (entry_fields, entry_intros) = parse_documented(&entries);
    fields.retain(|f| !matches!(f.section.as_str(), "moving" | "robots" | "obstacles"));
    let mut first_entries: Vec<Field> = Vec::new();
    for f in entry_fields
        .into_iter()
        .filter(|f| matches!(f.section.as_str(), "moving" | "robots"))
    {
        match first_entries
            .iter_mut()
            .find(|e| e.section == f.section && e.name == f.name)
        {
            Some(known) if !known.set && f.set && known.value == "..." => {
                known.value = f.value;
            }
            Some(_) => {}
            None => first_entries.push(f),
        }
    }
    fields.extend(first_entries);
    let intro_of = |name: &str| {
        entry_intros
            .iter()
            .chain(intros.iter())
            .find(|(n, _)| n == name)
            .map(|(_, t)| t.clone())
            .unwrap_or_default()
    };
    let mut out = String::from(
        "# Configuration and scenario reference\n\n\
         <!-- Generated from `ronap config` (crates/ronap-core/src/config/docs.rs) by the test \
         crates/ronap-cli/tests/reference.rs; do not edit by hand. -->\n\n\
         Every field of a configuration (`--config FILE.toml`) or scenario (`--scenario \
         FILE.toml`) file: the two are the same format. A field left out takes its default; an \
         unknown field or a wrong type is an error naming the file, line, key and value. \
         `ronap config` prints every default as a file to edit, and `ronap config --scenario` a \
         complete example with obstacles of every kind. In Python each field is a keyword \
         `section_field=value` or a nested dict (`config={\"maze\": {\"cols\": 5}}`). Units: px \
         are scene pixels (x right, y up), deg are degrees counter-clockwise from +x, a step is \
         one action. The model behind each field is described in [../model.md](../model.md).\n",
    );
    let mut section = String::new();
    for f in &fields {
        if f.section != section {
            section = f.section.clone();
            let array = matches!(section.as_str(), "moving" | "robots");
            let title = if array {
                format!("[[{section}]]")
            } else {
                format!("[{section}]")
            };
            writeln!(out, "\n## `{title}`\n").unwrap();
            let intro = intro_of(&section);
            if !intro.is_empty() {
                writeln!(out, "{}\n", intro.trim()).unwrap();
            }
            out.push_str(
                "| field | type | default | unit | meaning |\n| --- | --- | --- | --- | --- |\n",
            );
        }
        let default = if f.set {
            format!("`{}`", f.value)
        } else if f.value == "..." {
            "unset (see meaning)".to_string()
        } else {
            format!("unset (e.g. `{}`)", f.value)
        };
        writeln!(
            out,
            "| `{}` | {} | {} | {} | {} |",
            f.name,
            value_type(&f.value, &f.doc),
            cell(&default),
            unit(&f.section, &f.name, &f.doc),
            cell(&f.doc)
        )
        .unwrap();
    }
    writeln!(
        out,
        "\n## `[[obstacles]]`\n\n{}\n\n\
         | shape | fields | unit |\n| --- | --- | --- |\n\
         | `\"box\"` | `min = [x, y]`, `max = [x, y]`: the lower-left and upper-right corners | px |\n\
         | `\"disc\"` | `center = [x, y]`, `radius_px` | px |\n\
         | `\"polygon\"` | `points = [[x, y], ...]`: the corners of a convex polygon | px |",
        intro_of("obstacles").trim()
    )
    .unwrap();
    out
}

#[test]
fn cli_reference_matches_the_clap_definitions() {
    let generated = cli_reference();
    // Every long flag of every command is in the page, whatever its rendering.
    fn flags(cmd: &clap::Command, out: &mut Vec<String>) {
        for arg in cmd.get_arguments().filter(|a| !a.is_hide_set()) {
            if let Some(long) = arg.get_long() {
                out.push(format!("--{long}"));
            }
        }
        for sub in cmd.get_subcommands() {
            flags(sub, out);
        }
    }
    let mut all = Vec::new();
    flags(&ronap_cli::Cli::command(), &mut all);
    for flag in &all {
        assert!(
            generated.contains(flag.as_str()),
            "{flag} missing from cli.md"
        );
    }
    assert!(all.len() > 100, "only {} flags found", all.len());
    check_generated("docs/reference/cli.md", &generated);
}

#[test]
fn config_reference_matches_the_schema() {
    let generated = config_reference();
    for needle in [
        "`kind`",
        "`[[moving]]`",
        "`[[robots]]`",
        "`[[obstacles]]`",
        "`sees_robots`",
        "`shaping_gamma`",
    ] {
        assert!(
            generated.contains(needle),
            "{needle} missing from config.md"
        );
    }
    check_generated("docs/reference/config.md", &generated);
}

/// The header of a CSV file, as column names.
fn header(path: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let first = text.lines().next().unwrap_or_default();
    first.split(',').map(|c| c.trim().to_string()).collect()
}

/// The first file in `dir` whose name ends with `suffix`.
fn first_file(dir: &Path, suffix: &str) -> std::path::PathBuf {
    let mut names: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.to_string_lossy().ends_with(suffix))
        .collect();
    names.sort();
    names
        .into_iter()
        .next()
        .unwrap_or_else(|| panic!("no *{suffix} in {}", dir.display()))
}

#[test]
fn every_output_column_is_in_the_outputs_reference() {
    let outputs = std::fs::read_to_string(repo_root().join("docs/reference/outputs.md")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let path = |name: &str| d.join(name).to_str().unwrap().to_string();
    // A lone robot among moving obstacles with the crowd metrics, and a team of two with them.
    std::fs::write(
        d.join("lone.toml"),
        "[metrics]\ncrowd = true\n\n[[moving]]\ncount = 3\nmotion = \"random_walk\"\n",
    )
    .unwrap();
    std::fs::write(
        d.join("team.toml"),
        "[metrics]\ncrowd = true\n\n[[moving]]\ncount = 2\n\n[[robots]]\ncount = 2\ngoal_count = 2\n",
    )
    .unwrap();
    let seeds = ["--seeds", "2", "--max-steps", "60"];
    let lone = path("lone");
    let team = path("team");
    ok(&ronap(
        &[
            &["run", "--policy", "geodesic", "--log-steps", "--out", &lone],
            &["--scenario", &path("lone.toml")][..],
            &seeds[..],
        ]
        .concat(),
    ));
    ok(&ronap(
        &[
            &["run", "--policy", "geodesic", "--log-steps", "--out", &team],
            &["--scenario", &path("team.toml")][..],
            &seeds[..],
        ]
        .concat(),
    ));
    let compared = path("compare");
    ok(&ronap(
        &[
            &[
                "compare", "--policy", "apf", "--policy", "random", "--out", &compared,
            ][..],
            &["--by", "difficulty"][..],
            &seeds[..],
        ]
        .concat(),
    ));
    let data = path("data.csv");
    ok(&ronap(&[
        "collect",
        "--expert",
        "geodesic",
        "--samples",
        "20",
        "--out",
        &data,
    ]));
    let weights = path("dqn.safetensors");
    ok(&ronap(&[
        "train",
        "dqn",
        "--steps",
        "400",
        "--eval-every",
        "200",
        "--eval-seeds",
        "2",
        "--out",
        &weights,
    ]));
    let files = [
        d.join("lone/episodes.csv"),
        d.join("lone/timing.csv"),
        first_file(&d.join("lone/steps"), ".csv"),
        d.join("team/episodes.csv"),
        d.join("team/robots.csv"),
        d.join("team/timing.csv"),
        first_file(&d.join("team/steps"), ".csv"),
        d.join("compare/seeds.csv"),
        d.join("data.csv"),
        d.join("dqn-training.csv"),
    ];
    let mut missing = Vec::new();
    for file in &files {
        for column in header(file) {
            // Per-beam and per-policy columns are written once, as `laser_0`, `d_1` and `POLICY_spl`.
            let per_beam = |prefix: &str, first: &str| {
                column
                    .strip_prefix(prefix)
                    .filter(|n| n.chars().all(|c| c.is_ascii_digit()))
                    .map(|_| first.to_string())
            };
            let column = match per_beam("laser_", "laser_0").or_else(|| per_beam("d_", "d_1")) {
                Some(first) => first,
                None => ["apf_", "random_"]
                    .iter()
                    .find_map(|p| column.strip_prefix(p))
                    .map_or(column.clone(), |rest| format!("POLICY_{rest}")),
            };
            if !outputs.contains(&format!("`{column}`")) {
                missing.push(format!("{column} (in {})", file.display()));
            }
        }
    }
    assert!(
        missing.is_empty(),
        "columns missing from docs/reference/outputs.md (write each as `name` with its meaning):\n  {}",
        missing.join("\n  ")
    );
}
