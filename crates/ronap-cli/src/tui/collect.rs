//! `ronap collect --human`: the paper's Collect Data screen in the terminal. The first-person view
//! (`M` for the whole scene), the left / up / right arrows for LEFT / AHEAD / RIGHT, the down
//! arrow to re-arm them after each action (anti-mispress), the robot re-posed after every
//! recorded action ([`ronap_core::collect::HumanCollector`]).
//!
//! Every row goes to the data log (the core's [`DataLogWriter`], the format `--expert` writes)
//! and is flushed as it is taken, so quitting, Ctrl-C or a crash loses no row already taken.

use crate::tui::app::{self, App};
use crate::tui::draw::{self, SceneMode};
use crate::tui::terminal::{self, Session};
use anyhow::{Context, Result};
use ratatui::crossterm::event::{KeyCode, KeyEvent};
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::Frame;
use ronap_core::collect::HumanCollector;
use ronap_core::eval::Evaluator;
use ronap_core::io::DataLogWriter;
use ronap_core::DiscreteAction;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

/// What a human session needs from `ronap collect`'s flags.
pub struct Setting {
    /// The scenes and configuration.
    pub evaluator: Evaluator,
    /// The first seed.
    pub seed_start: u64,
    /// Rows per seed before the next.
    pub per_episode: u64,
    /// Rows before the session ends by itself.
    pub samples: u64,
    /// Who is collecting (shown, and in the default file name).
    pub user: String,
    /// The data log to create.
    pub out: PathBuf,
}

/// The user name for the default file name: `$USER` (as a file-name-safe word) or `user`.
pub fn default_user() -> String {
    let name: String = std::env::var("USER")
        .unwrap_or_default()
        .chars()
        .filter(|c| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.'))
        .collect();
    if name.is_empty() || name.starts_with('.') {
        "user".to_string()
    } else {
        name
    }
}

/// Everything the Collect Data screen shows.
pub struct HumanView<'a> {
    /// The session.
    pub collector: HumanCollector<'a>,
    /// First person or whole scene.
    pub mode: SceneMode,
    /// Who is collecting.
    pub user: String,
    /// The data log's name.
    pub file: String,
    /// Rows before the session ends.
    pub samples: u64,
    /// An action key was pressed while disarmed (cleared by the next accepted key).
    pub ignored: bool,
}

/// What a key asks of the loop.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum KeyAction {
    /// Nothing beyond what the key changed on screen.
    None,
    /// Record this action (when armed).
    Act(DiscreteAction),
    /// Quit.
    Quit,
    /// Quit as interrupted (Ctrl-C).
    Interrupt,
}

/// Applies `key` to `view`; an action to take or a quit comes back to the loop.
pub fn handle_key(view: &mut HumanView, key: &KeyEvent) -> KeyAction {
    if terminal::is_ctrl_c(key) {
        return KeyAction::Interrupt;
    }
    let act = |view: &mut HumanView, a| {
        if view.collector.armed() {
            view.ignored = false;
            KeyAction::Act(a)
        } else {
            view.ignored = true;
            KeyAction::None
        }
    };
    match key.code {
        KeyCode::Left => act(view, DiscreteAction::Left),
        KeyCode::Up => act(view, DiscreteAction::Ahead),
        KeyCode::Right => act(view, DiscreteAction::Right),
        KeyCode::Down => {
            view.collector.rearm();
            view.ignored = false;
            KeyAction::None
        }
        KeyCode::Char('m') | KeyCode::Char('M') => {
            view.mode = view.mode.toggled();
            KeyAction::None
        }
        KeyCode::Char('q') | KeyCode::Char('Q') | KeyCode::Esc => KeyAction::Quit,
        _ => KeyAction::None,
    }
}

/// The status line: armed or not, rows, seed, the latest action and the paper's messages.
pub fn status_line(view: &HumanView) -> Line<'static> {
    let c = &view.collector;
    let mut spans = vec![Span::raw(" ")];
    if c.armed() {
        spans.push(Span::styled(
            "● armed: ← ↑ → act",
            Style::default().fg(Color::Green),
        ));
    } else {
        spans.push(Span::styled(
            "○ press ↓ to re-arm",
            Style::default().fg(Color::Yellow),
        ));
    }
    spans.push(Span::raw(format!(
        " · row {} · seed {}",
        c.rows(),
        c.episode().seed()
    )));
    if let Some(last) = c.last() {
        spans.push(Span::raw(format!(" · last {}", last.action.name())));
        let message = if last.reached_goal {
            Some(("TaskComplete", Color::Green))
        } else if last.collided {
            Some(("CollisionWarning", Color::Red))
        } else {
            None
        };
        if let Some((text, colour)) = message {
            spans.push(Span::raw(" · "));
            spans.push(Span::styled(
                text,
                Style::default().fg(colour).add_modifier(Modifier::BOLD),
            ));
        }
    }
    if view.ignored {
        spans.push(Span::styled(
            " · ignored: ↓ first",
            Style::default().fg(Color::Yellow),
        ));
    }
    Line::from(spans)
}

/// `text` in at most `max` characters, the middle replaced by `…` when it is longer.
fn shorten(text: &str, max: usize) -> String {
    let chars: Vec<char> = text.chars().collect();
    if chars.len() <= max || max < 3 {
        return text.to_string();
    }
    let head = (max - 1) / 2;
    let tail = max - 1 - head;
    let mut out: String = chars[..head].iter().collect();
    out.push('…');
    out.extend(&chars[chars.len() - tail..]);
    out
}

/// The side panel's lines.
fn side_lines(view: &HumanView) -> Vec<Line<'static>> {
    let c = &view.collector;
    let e = c.episode();
    let lines = vec![
        draw::field("user", view.user.clone()),
        draw::field("file", shorten(&view.file, 22)),
        draw::field("rows", format!("{} of {}", c.rows(), view.samples)),
        draw::field(
            "this seed",
            format!("{} / {}", c.episode_rows(), c.per_episode()),
        ),
        draw::field("seed", e.seed().to_string()),
        draw::field("distance", format!("{:.1} px", e.distance_px())),
        draw::field("goal", draw::direction_text(e.direction_deg())),
    ];
    draw::side_panel(
        lines,
        e.movers().is_some(),
        &[
            ("← ↑ →", "LEFT / AHEAD / RIGHT"),
            ("↓", "re-arm after each action"),
            ("m", "whole scene / first person"),
            ("q", "quit (every row is saved)"),
        ],
    )
}

/// Draws the whole Collect Data screen for `view`.
pub fn draw(frame: &mut Frame, view: &HumanView) {
    let episode = view.collector.episode();
    // Re-posing makes a path meaningless: the whole scene shows the robot and the goal.
    let here = [episode.pose().position()];
    draw::screen(
        frame,
        draw::Shown::lone(episode, &here),
        view.mode,
        "ronap collect",
        side_lines(view),
        status_line(view),
    );
}

/// Runs a human collection session.
pub fn run(setting: Setting) -> Result<ExitCode> {
    terminal::require_terminal("collect --human")?;
    let collector =
        HumanCollector::new(&setting.evaluator, setting.seed_start, setting.per_episode)
            .with_context(|| "cannot start collecting")?;
    let beams = setting.evaluator.config().laser.beams as usize;
    // A new file only: a typo in --out must not overwrite an earlier session's rows.
    let file = std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&setting.out)
        .with_context(|| {
            format!(
                "cannot create the data log {} (an existing file is never overwritten)",
                setting.out.display()
            )
        })?;
    let mut log = DataLogWriter::new(file, beams)
        .with_context(|| format!("cannot write {}", setting.out.display()))?;
    let mut view = HumanView {
        collector,
        mode: SceneMode::FirstPerson,
        user: setting.user.clone(),
        file: setting.out.file_name().map_or_else(
            || setting.out.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        ),
        samples: setting.samples,
        ignored: false,
    };
    let mut session = Session::start("collect --human")?;
    let outcome = app::run(
        &mut session,
        &mut CollectApp {
            view: &mut view,
            log: &mut log,
            setting: &setting,
        },
    );
    drop(session);
    let rows = view.collector.rows();
    let mut stdout = std::io::stdout().lock();
    if rows == 0 {
        // Nothing collected: no empty log left behind.
        let _ = std::fs::remove_file(&setting.out);
        writeln!(stdout, "ronap collect: no rows recorded; nothing written")?;
    } else {
        writeln!(
            stdout,
            "ronap collect: {rows} rows by {} from {} seeds ({}..), wrote {}",
            setting.user,
            view.collector.seeds(),
            setting.seed_start,
            setting.out.display()
        )?;
    }
    outcome
}

/// The Collect Data screen as an [`App`]: each armed arrow records a row, flushed at once.
struct CollectApp<'a, 'e> {
    view: &'a mut HumanView<'e>,
    log: &'a mut DataLogWriter<std::fs::File>,
    setting: &'a Setting,
}

impl App for CollectApp<'_, '_> {
    fn draw(&self, frame: &mut Frame) {
        draw(frame, self.view)
    }

    fn wait(&self) -> Duration {
        Duration::from_millis(100)
    }

    /// Records a row for an armed arrow; ends when the user quits or `samples` rows are in.
    fn key(&mut self, key: &KeyEvent) -> Result<Option<ExitCode>> {
        match handle_key(self.view, key) {
            KeyAction::None => Ok(None),
            KeyAction::Quit => Ok(Some(ExitCode::SUCCESS)),
            KeyAction::Interrupt => Ok(Some(ExitCode::from(130))),
            KeyAction::Act(action) => {
                if let Some(sample) = self.view.collector.act(action)? {
                    self.log
                        .write(&sample)
                        .with_context(|| format!("cannot write {}", self.setting.out.display()))?;
                }
                Ok((self.view.collector.rows() >= self.setting.samples)
                    .then_some(ExitCode::SUCCESS))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ratatui::backend::TestBackend;
    use ratatui::crossterm::event::KeyModifiers;
    use ratatui::Terminal;
    use ronap_core::sim::Scenes;
    use ronap_core::ValidConfig;

    fn screen(view: &HumanView) -> String {
        let mut terminal = Terminal::new(TestBackend::new(80, 24)).unwrap();
        terminal.draw(|f| draw(f, view)).unwrap();
        let buf = terminal.backend().buffer();
        (0..24)
            .map(|y| {
                let row: String = (0..80).map(|x| buf[(x, y)].symbol()).collect();
                row + "\n"
            })
            .collect()
    }

    #[test]
    fn long_file_names_keep_both_ends() {
        assert_eq!(
            shorten("tester_20261121120000.csv", 22),
            "tester_202…1120000.csv"
        );
        assert_eq!(shorten("short.csv", 22), "short.csv");
    }

    #[test]
    fn arrows_act_once_until_down_rearms_them() {
        let evaluator = Evaluator::new(ValidConfig::default(), Scenes::MazePerSeed);
        let mut view = HumanView {
            collector: HumanCollector::new(&evaluator, 5, 100).unwrap(),
            mode: SceneMode::FirstPerson,
            user: "tester".into(),
            file: "tester_20261121120000.csv".into(),
            samples: 10_000,
            ignored: false,
        };
        let key = |code| KeyEvent::new(code, KeyModifiers::NONE);
        let before = screen(&view);
        assert!(
            before.contains("● armed: ← ↑ → act · row 0 · seed 5"),
            "{before}"
        );
        insta::assert_snapshot!("collect_human_armed_seed_5", before);

        let up = handle_key(&mut view, &key(KeyCode::Up));
        assert_eq!(up, KeyAction::Act(DiscreteAction::Ahead));
        assert!(view.collector.act(DiscreteAction::Ahead).unwrap().is_some());
        // Pressed again without the down arrow: nothing to record.
        for code in [KeyCode::Up, KeyCode::Left, KeyCode::Right] {
            assert_eq!(handle_key(&mut view, &key(code)), KeyAction::None);
        }
        let after = screen(&view);
        assert!(
            after.contains("○ press ↓ to re-arm · row 1 · seed 5 · last AHEAD"),
            "{after}"
        );
        assert!(after.contains("ignored: ↓ first"), "{after}");
        assert!(after.contains("rows       1 of 10000"), "{after}");
        assert_ne!(before, after, "the robot was re-posed");

        assert_eq!(handle_key(&mut view, &key(KeyCode::Down)), KeyAction::None);
        assert!(view.collector.armed());
        assert_eq!(
            handle_key(&mut view, &key(KeyCode::Left)),
            KeyAction::Act(DiscreteAction::Left)
        );
        assert_eq!(
            handle_key(&mut view, &key(KeyCode::Char('m'))),
            KeyAction::None
        );
        assert!(screen(&view).contains("whole scene · seed 5"));
        assert_eq!(
            handle_key(&mut view, &key(KeyCode::Char('q'))),
            KeyAction::Quit
        );
    }
}
