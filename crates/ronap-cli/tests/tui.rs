//! The terminal commands driven as a person would: `ronap` runs in a tmux pane (80x24 unless a
//! test asks for another size), keys are sent with `send-keys`, and the screen is read with
//! `capture-pane`. Each test has its own tmux server. Without tmux the tests print a notice and
//! pass; CI installs it (.ci/run).

use crate::util::{col, ok, ronap, rows, shipped, BIN};
use std::process::Command;
use std::time::{Duration, Instant};

/// A tmux server with one pane running a plain shell.
struct Tmux {
    socket: String,
    socket_path: String,
}

impl Tmux {
    /// A new server with an 80x24 pane, or `None` (with a notice) when tmux is not installed.
    fn start(name: &str) -> Option<Self> {
        Self::start_sized(name, 80, 24)
    }

    /// [`Tmux::start`] with a pane of `width` x `height` cells.
    fn start_sized(name: &str, width: u16, height: u16) -> Option<Self> {
        if Command::new("tmux").arg("-V").output().is_err() {
            eprintln!("tmux is not installed: skipping the terminal test {name}");
            return None;
        }
        let mut tmux = Self {
            socket: format!("ronap-test-{name}-{}", std::process::id()),
            socket_path: String::new(),
        };
        tmux.run(&[
            "new-session",
            "-d",
            "-x",
            &width.to_string(),
            "-y",
            &height.to_string(),
            "env",
            "-i",
            &format!("PATH={}", std::env::var("PATH").unwrap_or_default()),
            "TERM=xterm-256color",
            "HOME=/tmp",
            "PS1=$ ",
            "bash",
            "--norc",
            "--noprofile",
        ]);
        tmux.run(&["set-option", "-g", "remain-on-exit", "on"]);
        tmux.socket_path = tmux
            .run(&["display-message", "-p", "#{socket_path}"])
            .trim()
            .to_string();
        Some(tmux)
    }

    fn run(&self, args: &[&str]) -> String {
        let o = Command::new("tmux")
            .args(["-L", &self.socket])
            .args(args)
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "tmux {args:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        String::from_utf8_lossy(&o.stdout).into_owned()
    }

    /// Types `keys` (tmux key names: `Enter`, `Left`, `C-c`, or literal text).
    fn keys(&self, keys: &[&str]) {
        let mut args = vec!["send-keys", "-t", "0"];
        args.extend(keys);
        self.run(&args);
    }

    /// Types a shell command line and Enter.
    fn line(&self, command: &str) {
        self.run(&["send-keys", "-t", "0", "-l", command]);
        self.keys(&["Enter"]);
    }

    /// The visible screen.
    fn screen(&self) -> String {
        self.run(&["capture-pane", "-p", "-t", "0"])
    }

    /// A tmux format value of the pane, such as `#{alternate_on}`.
    fn format(&self, format: &str) -> String {
        self.run(&["display-message", "-p", "-t", "0", format])
            .trim()
            .to_string()
    }

    /// Waits until the screen satisfies `ready`; fails with the screen after `seconds`.
    fn wait(&self, what: &str, seconds: u64, ready: impl Fn(&str) -> bool) -> String {
        let deadline = Instant::now() + Duration::from_secs(seconds);
        loop {
            let screen = self.screen();
            if ready(&screen) {
                return screen;
            }
            assert!(
                Instant::now() < deadline,
                "waited {seconds} s for {what}; the screen:\n{screen}"
            );
            std::thread::sleep(Duration::from_millis(100));
        }
    }
}

impl Drop for Tmux {
    fn drop(&mut self) {
        let _ = Command::new("tmux")
            .args(["-L", &self.socket, "kill-server"])
            .output();
        // tmux leaves its socket file behind.
        if !self.socket_path.is_empty() {
            let _ = std::fs::remove_file(&self.socket_path);
        }
    }
}

/// Checks that the terminal is back to the shell: main screen, cursor shown, and cooked mode
/// (the line discipline's settings equal to those saved before).
fn assert_restored(tmux: &Tmux, marker: &str) {
    let screen = tmux.wait(marker, 15, |s| s.contains(marker));
    assert_eq!(tmux.format("#{alternate_on}"), "0", "{screen}");
    assert_eq!(tmux.format("#{cursor_flag}"), "1", "{screen}");
    assert!(!screen.contains("ronap view ─"), "{screen}");
    tmux.line("stty -g > after.stty; cmp before.stty after.stty && echo same-tty-settings");
    tmux.wait("the same tty settings", 10, |s| {
        s.lines().any(|l| l.trim() == "same-tty-settings")
    });
}

#[test]
fn view_shows_the_episode_toggles_the_map_and_restores_the_terminal_on_quit() {
    let Some(tmux) = Tmux::start("view") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    tmux.line(&format!(
        "cd {}; stty -g > before.stty",
        dir.path().display()
    ));
    tmux.line(&format!(
        "{} view --policy apf --seed 7 --speed 5; echo after-view rc=$?",
        BIN
    ));
    let screen = tmux.wait("the first-person view", 30, |s| {
        s.contains("first person · seed 7") && s.contains("step 1 ")
    });
    assert_eq!(tmux.format("#{alternate_on}"), "1");
    let lines: Vec<&str> = screen.lines().collect();
    assert!(lines[0].contains("ronap view"), "{screen}");
    // The distance in the upper right of the scene, the status line at the bottom.
    assert!(
        lines[1]
            .split('│')
            .nth(1)
            .unwrap()
            .trim_end()
            .ends_with(" px"),
        "{screen}"
    );
    assert!(lines[23].contains("running · step"), "{screen}");
    assert!(lines[23].contains("collisions 0"), "{screen}");
    assert!(screen.contains("policy     apf"), "{screen}");
    // Rays and the range circle are Braille dots.
    let braille = screen
        .chars()
        .filter(|c| ('\u{2801}'..='\u{28ff}').contains(c))
        .count();
    assert!(braille > 100, "{screen}");

    tmux.keys(&["M"]);
    let screen = tmux.wait("the whole scene", 10, |s| {
        s.contains("whole scene · seed 7")
    });
    assert!(
        !screen.lines().next().unwrap().contains("first person"),
        "{screen}"
    );
    tmux.keys(&["space"]);
    tmux.wait("pause", 10, |s| s.contains("❚❚ paused"));

    // Resized, the screen is laid out again for the new size, and again on the way back.
    for (w, h) in [(100usize, 30usize), (80, 24)] {
        tmux.run(&[
            "resize-window",
            "-t",
            "0",
            "-x",
            &w.to_string(),
            "-y",
            &h.to_string(),
        ]);
        let screen = tmux.wait("the resized screen", 10, |s| {
            let lines: Vec<&str> = s.lines().collect();
            lines.len() == h
                && lines[h - 1].contains("paused · step")
                && lines[h - 2].starts_with('└')
                && lines[h - 2].ends_with('┘')
        });
        for line in screen.lines() {
            assert!(line.chars().count() <= w, "{w}x{h}:\n{screen}");
        }
        assert!(screen
            .lines()
            .next()
            .unwrap()
            .starts_with("┌ whole scene · seed 7"));
        assert_eq!(
            tmux.format("#{pane_width}x#{pane_height}"),
            format!("{w}x{h}")
        );
    }

    tmux.keys(&["q"]);
    assert_restored(&tmux, "after-view rc=0");
}

#[test]
fn view_of_a_team_shows_every_robot_follows_another_on_tab_and_quits() {
    let Some(tmux) = Tmux::start("view-team") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    tmux.line(&format!(
        "cd {}; stty -g > before.stty",
        dir.path().display()
    ));
    let scenario = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenarios/warehouse-team.toml"
    );
    tmux.line(&format!(
        "{BIN} view --policy geodesic --scenario {scenario} --seed 3 --speed 50; \
         echo after-view rc=$?"
    ));
    let screen = tmux.wait("the team's whole scene", 30, |s| {
        s.contains("whole scene · seed 3") && s.contains("at goal 0/8")
    });
    assert!(screen.contains("at goal    0 / 8"), "{screen}");
    assert!(screen.contains("robot 0 · geodesic"), "{screen}");
    // At 80x24 the colour legend gives way to the keys.
    assert!(!screen.contains("robots ● 0 ● 1"), "{screen}");
    assert!(screen.contains("tab     follow the next robot"), "{screen}");
    tmux.keys(&["Tab"]);
    tmux.wait("robot 1 followed", 10, |s| s.contains("robot 1"));
    tmux.keys(&["M"]);
    tmux.wait("robot 1's first-person view", 10, |s| {
        s.contains("first person of robot 1 · seed 3")
    });
    tmux.keys(&["q"]);
    assert_restored(&tmux, "after-view rc=0");
}

/// Runs the team view of `scenario` (geodesic, seed 0) to its end in a `width` x `height` pane
/// and checks that every key is explained and the whole end-of-episode status line is on screen,
/// its collisions with walls and with robots those robots.csv records for the same episode, and
/// the followed robot's those of its own row. Returns the screen at the end (empty without tmux).
fn team_view_ends_fitted(name: &str, scenario: &str, width: u16, height: u16) -> String {
    let Some(tmux) = Tmux::start_sized(name, width, height) else {
        return String::new();
    };
    let dir = tempfile::tempdir().unwrap();
    let scenario = shipped(scenario);
    let scenario = scenario.to_str().unwrap();
    let run = dir.path().join("run");
    ok(&ronap(&[
        "run",
        "--scenario",
        scenario,
        "--policy",
        "geodesic",
        "--seeds",
        "1",
        "--out",
        run.to_str().unwrap(),
    ]));
    let robots = rows(&run.join("robots.csv"));
    let count = |c: &str| -> Vec<u64> {
        let c = col(&robots, c);
        robots[1..].iter().map(|r| r[c].parse().unwrap()).collect()
    };
    let (walls, others) = (count("collisions"), count("robot_collisions"));
    let team = format!(
        "collisions: walls {}, robots {}",
        walls.iter().sum::<u64>(),
        others.iter().sum::<u64>()
    );
    assert!(others.iter().sum::<u64>() > 0, "{robots:?}");

    tmux.line(&format!("cd {}", dir.path().display()));
    tmux.line(&format!(
        "{BIN} view --policy geodesic --scenario {scenario} --seed 0 --speed 1000; \
         echo after-view rc=$?"
    ));
    let screen = tmux.wait("the end of the team episode", 60, |s| s.contains("■ ended"));
    let lines: Vec<&str> = screen.lines().collect();
    assert_eq!(lines.len(), usize::from(height), "{screen}");
    for line in &lines {
        assert!(line.chars().count() <= usize::from(width), "{screen}");
    }
    // The status rows at the bottom, below the panels.
    let status = status_rows(&screen);
    assert!(!status.is_empty(), "{screen}");
    assert!(
        lines[lines.len() - status.len() - 1].starts_with('└'),
        "{screen}"
    );
    let joined = status.join(" ");
    assert!(joined.contains(&team), "{team} not in:\n{screen}");
    assert!(joined.contains("step "), "{screen}");
    assert!(joined.contains("at goal "), "{screen}");
    assert!(joined.contains("1000 steps/s"), "{screen}");
    assert!(
        joined.contains("deadlock: no robot moved")
            || joined.contains("TaskComplete")
            || joined.contains("robots at their goals"),
        "{screen}"
    );
    // Every key, with what it does.
    for (key, what) in [
        ("space", "pause / resume"),
        ("+ -", "faster / slower"),
        ("tab", "follow the next robot"),
        ("m", "whole scene / first person"),
        ("s", "one step, when paused"),
        ("r n", "restart / next seed"),
        ("q", "quit"),
    ] {
        let help = format!("│{key:<8}{what}");
        assert!(screen.contains(&help), "{help:?} not in:\n{screen}");
    }
    // The followed robot, robot 0: its own row.
    let own = format!("collisions walls {}, robots {}", walls[0], others[0]);
    assert!(screen.contains(&own), "{own} not in:\n{screen}");
    assert!(screen.contains(&format!("collisions {}", &team["collisions: ".len()..])));
    tmux.keys(&["q"]);
    tmux.wait("the shell", 15, |s| s.contains("after-view rc=0"));
    screen
}

/// The rows of an ended view's status line: from the one that starts with the mark to the
/// bottom.
fn status_rows(screen: &str) -> Vec<String> {
    let lines: Vec<&str> = screen.lines().collect();
    lines
        .iter()
        .position(|l| l.starts_with(" ■ ended"))
        .map_or_else(Vec::new, |first| {
            lines[first..].iter().map(|l| l.to_string()).collect()
        })
}

#[test]
fn team_view_at_80_by_24_shows_every_key_and_the_whole_end_of_episode_status() {
    let screen = team_view_ends_fitted("view-team-80", "corridor-swap.toml", 80, 24);
    let status = status_rows(&screen);
    if let Some(first) = status.first() {
        // Too long for one row of 80: the message goes on the next row, whole.
        assert_eq!(status.len(), 2, "{status:?}");
        assert!(first.contains("collisions: walls"), "{status:?}");
        assert!(status[1].contains("deadlock: no robot moved"), "{status:?}");
    }
}

#[test]
fn team_view_at_120_by_40_shows_every_key_and_the_whole_end_of_episode_status() {
    let screen = team_view_ends_fitted("view-team-120", "hall-robots.toml", 120, 40);
    if !screen.is_empty() {
        let status = status_rows(&screen);
        // Room for the colour legend too.
        assert!(screen.contains("robots ● 0 ● 1"), "{screen}");
        assert!(status.len() <= 2, "{status:?}");
        assert!(
            status
                .join(" ")
                .contains("ended with 25 of 100 robots at their goals"),
            "{status:?}"
        );
    }
}

#[test]
fn view_restores_the_terminal_on_ctrl_c_and_sigterm() {
    let Some(tmux) = Tmux::start("view-signals") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    tmux.line(&format!(
        "cd {}; stty -g > before.stty",
        dir.path().display()
    ));
    let view = format!("{} view --policy random --seed 3 --speed 50", BIN);
    tmux.line(&format!("{view}; echo after-ctrl-c rc=$?"));
    tmux.wait("the view", 30, |s| s.contains("first person · seed 3"));
    tmux.keys(&["C-c"]);
    assert_restored(&tmux, "after-ctrl-c rc=130");

    tmux.line("clear");
    // The view writes nothing we could read its process id from: a shell that records its own
    // and becomes ronap does.
    tmux.line(&format!(
        "bash -c 'echo $$ > view.pid; exec {view}'; echo after-term rc=$?"
    ));
    tmux.wait("the view", 30, |s| s.contains("first person · seed 3"));
    let pid = std::fs::read_to_string(dir.path().join("view.pid")).unwrap();
    // bash's own kill: no procps needed.
    let killed = Command::new("bash")
        .args(["-c", &format!("kill -TERM {}", pid.trim())])
        .status()
        .unwrap();
    assert!(killed.success());
    assert_restored(&tmux, "after-term rc=143");

    // The terminal goes away (a closed SSH connection): SIGHUP, and a terminal that reads
    // end-of-file forever. The process must end, not spin.
    tmux.line(&format!(
        "bash -c 'echo $$ > view.pid; exec {view}'; echo after-hangup rc=$?"
    ));
    tmux.wait("the view", 30, |s| s.contains("first person · seed 3"));
    let pid = std::fs::read_to_string(dir.path().join("view.pid")).unwrap();
    let stat = std::path::PathBuf::from(format!("/proc/{}/stat", pid.trim()));
    // Running, as opposed to gone or a zombie waiting to be reaped.
    let running = || {
        std::fs::read_to_string(&stat).is_ok_and(|s| {
            s.rsplit(')')
                .next()
                .and_then(|r| r.split_whitespace().next())
                != Some("Z")
        })
    };
    assert!(running());
    tmux.run(&["kill-server"]);
    let deadline = Instant::now() + Duration::from_secs(10);
    while running() {
        assert!(
            Instant::now() < deadline,
            "ronap view ({}) still runs after its terminal hung up",
            pid.trim()
        );
        std::thread::sleep(Duration::from_millis(100));
    }
}

/// The data rows of a data log, as maps from column to value.
fn log_rows(path: &std::path::Path) -> Vec<std::collections::HashMap<String, String>> {
    let mut r = csv::Reader::from_path(path).unwrap();
    let header: Vec<String> = r.headers().unwrap().iter().map(String::from).collect();
    r.records()
        .map(|rec| {
            header
                .iter()
                .cloned()
                .zip(rec.unwrap().iter().map(String::from))
                .collect()
        })
        .collect()
}

#[test]
fn collect_human_records_one_row_per_armed_arrow_as_it_is_taken() {
    let Some(tmux) = Tmux::start("collect") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("tester_rows.csv");
    tmux.line(&format!(
        "cd {}; stty -g > before.stty",
        dir.path().display()
    ));
    tmux.line(&format!(
        "{} collect --human --user tester --seed-start 5 --out tester_rows.csv; echo after-collect rc=$?",
        BIN
    ));
    let rows_shown = |n: u64| move |s: &str| s.contains(&format!("rows       {n} of 10000"));
    tmux.wait("the collect screen", 30, |s| {
        s.contains("first person · seed 5") && s.contains("● armed") && rows_shown(0)(s)
    });
    // Only the header so far.
    assert_eq!(log_rows(&log).len(), 0);

    tmux.keys(&["Up"]);
    tmux.wait("the first row", 10, rows_shown(1));
    // Written and flushed while the session is still running.
    assert_eq!(log_rows(&log).len(), 1);
    // Pressed twice without the down arrow: no second row.
    tmux.keys(&["Up"]);
    tmux.wait("the ignored key", 10, |s| s.contains("ignored: ↓ first"));
    tmux.keys(&["Right"]);
    std::thread::sleep(Duration::from_millis(300));
    assert!(rows_shown(1)(&tmux.screen()));
    assert_eq!(log_rows(&log).len(), 1);

    tmux.keys(&["Down"]);
    tmux.wait("re-armed", 10, |s| s.contains("● armed"));
    tmux.keys(&["Left"]);
    tmux.wait("the second row", 10, rows_shown(2));
    tmux.keys(&["Down", "Right"]);
    tmux.wait("the third row", 10, rows_shown(3));
    tmux.keys(&["M"]);
    tmux.wait("the whole scene", 10, |s| {
        s.contains("whole scene · seed 5")
    });

    tmux.keys(&["q"]);
    assert_restored(&tmux, "after-collect rc=0");
    let screen = tmux.screen();
    assert!(screen.contains("3 rows by tester"), "{screen}");
    let rows = log_rows(&log);
    let actions: Vec<&str> = rows.iter().map(|r| r["action"].as_str()).collect();
    assert_eq!(actions, ["AHEAD", "LEFT", "RIGHT"]);
    let steps: Vec<&str> = rows.iter().map(|r| r["step"].as_str()).collect();
    assert_eq!(steps, ["0", "1", "2"]);
    assert!(rows
        .iter()
        .all(|r| r["seed"] == "5" && r.contains_key("laser_16")));
    // After each action the robot jumped to a new pose facing roughly towards the goal.
    for pair in rows.windows(2) {
        let at = |r: &std::collections::HashMap<String, String>, k: &str| -> f64 {
            r[k].parse().unwrap()
        };
        let moved =
            (at(&pair[0], "x") - at(&pair[1], "x")).hypot(at(&pair[0], "y") - at(&pair[1], "y"));
        assert!(moved > 5.0, "not re-posed: {pair:?}");
        let off = (at(&pair[1], "direction") + 180.0).rem_euclid(360.0) - 180.0;
        assert!(
            off.abs() < 45.0,
            "re-posed facing {off} degrees off the goal"
        );
    }
}
