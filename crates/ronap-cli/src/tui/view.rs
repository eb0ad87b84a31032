//! `ronap view`: one episode run live in the terminal, as the paper's Start screen showed it: the
//! first-person view (`M` for the whole scene with the path so far), a side panel of figures and
//! keys, and a status line with the step, the collisions, and the paper's "TaskComplete" and
//! "CollisionWarning" messages.
//!
//! [`ViewState`] is the episode on screen and [`draw`] a pure function of it and the keys'
//! [`Controls`]; [`ViewApp`] holds the controls and steps the policy at the chosen speed between
//! keys, in the loop of [`crate::tui::app`], for the lone view and the team view alike.

use crate::tui::app::App;
use crate::tui::draw::{self, SceneMode};
use crate::tui::terminal;
use anyhow::Result;
use ratatui::crossterm::event::{KeyCode, KeyEvent};
use ratatui::style::Color;
use ratatui::text::Line;
use ratatui::Frame;
use ronap_core::eval::Evaluator;
use ronap_core::geometry::Point;
use ronap_core::policy::Policy;
use ronap_core::run::{Rollout, RunError};
use ronap_core::{Episode, Status};
use std::process::ExitCode;
use std::time::{Duration, Instant};

/// The speeds `+` and `-` step through, steps per second.
const SPEEDS: [u32; 10] = [1, 2, 5, 10, 20, 50, 100, 200, 500, 1000];

/// Longest wait for a key before the loop looks at signals and the clock again.
const POLL: Duration = Duration::from_millis(50);

/// How an episode stopped other than by its own status.
#[derive(Clone, Debug, PartialEq)]
pub enum Ending {
    /// The policy gave up (trapped, oscillating, no path), with its reason.
    GaveUp(String),
    /// The policy or the episode failed, with the error.
    Failed(String),
}

/// The episode `ronap view` shows (the keys' settings are [`ViewApp`]'s).
pub struct ViewState {
    /// The episode and the policy's say in it.
    pub rollout: Rollout,
    /// Positions so far, start first (the whole-scene view draws them).
    pub path: Vec<Point>,
    /// The policy's name as given.
    pub policy: String,
    /// The step of the latest collision.
    pub last_collision: Option<u32>,
    /// Why the episode stopped, when its status does not say.
    pub ending: Option<Ending>,
}

impl ViewState {
    /// The view of `rollout`, just started, under `policy`.
    pub fn new(rollout: Rollout, policy: &str) -> Self {
        Self {
            path: vec![rollout.episode().pose().position()],
            rollout,
            policy: policy.to_string(),
            last_collision: None,
            ending: None,
        }
    }

    /// The episode.
    pub fn episode(&self) -> &Episode {
        self.rollout.episode()
    }

    /// Whether the episode is over.
    pub fn finished(&self) -> bool {
        self.rollout.finished() || self.ending.is_some()
    }

    /// Asks `policy` for the next action and takes it, keeping the path and the collision record.
    pub fn advance(&mut self, policy: &mut dyn Policy) {
        match self.rollout.advance(policy) {
            Ok(Some(s)) if s.collided => self.last_collision = Some(s.step),
            Ok(Some(s)) => self.path.push(s.pose.position()),
            Ok(None) => {
                if let Some(why) = self.rollout.gave_up() {
                    self.ending = Some(Ending::GaveUp(why.to_string()));
                }
            }
            Err(RunError::InvalidAction { step, action, .. }) => {
                self.ending = Some(Ending::Failed(format!(
                    "step {step}: the policy returned an invalid action {action:?}"
                )))
            }
            Err(RunError::Policy { step, source, .. }) => {
                self.ending = Some(Ending::Failed(format!(
                    "step {step}: policy failed: {source}"
                )))
            }
            Err(e) => self.ending = Some(Ending::Failed(e.to_string())),
        }
    }

    /// Whether to show "CollisionWarning": the latest step collided, or one within the last
    /// half second at `speed` steps a second, so a warning stays long enough to read.
    pub fn warning(&self, speed: u32) -> bool {
        let linger = (speed / 2).max(1);
        self.last_collision
            .is_some_and(|k| self.episode().steps().saturating_sub(k) < linger)
    }
}

/// What a key asks of the loop.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum KeyAction {
    /// Nothing beyond what the key changed in the state.
    None,
    /// Take one step (paused).
    Step,
    /// Start the episode again.
    Restart,
    /// Go on to the next seed.
    Next,
    /// Follow the next robot (team view).
    NextRobot,
    /// Quit.
    Quit,
    /// Quit as interrupted (Ctrl-C).
    Interrupt,
}

/// What the keys set, in the lone and the team view alike.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Controls {
    /// First person or whole scene.
    pub mode: SceneMode,
    /// Whether stepping is paused.
    pub paused: bool,
    /// Steps per second.
    pub speed: u32,
}

impl Controls {
    /// Running at `speed` steps per second in `mode`.
    pub fn new(mode: SceneMode, speed: u32) -> Self {
        Self {
            mode,
            paused: false,
            speed,
        }
    }

    /// The next speed up (`faster`) or down.
    fn change_speed(&mut self, faster: bool) {
        self.speed = if faster {
            SPEEDS.into_iter().find(|&s| s > self.speed).unwrap_or(1000)
        } else {
            SPEEDS
                .into_iter()
                .rev()
                .find(|&s| s < self.speed)
                .unwrap_or(1)
        };
    }

    /// Applies `key`; what is left for the loop to do comes back.
    pub fn handle_key(&mut self, key: &KeyEvent) -> KeyAction {
        if terminal::is_ctrl_c(key) {
            return KeyAction::Interrupt;
        }
        match key.code {
            KeyCode::Char('q') | KeyCode::Char('Q') | KeyCode::Esc => KeyAction::Quit,
            KeyCode::Char(' ') => {
                self.paused = !self.paused;
                KeyAction::None
            }
            KeyCode::Char('+') | KeyCode::Char('=') => {
                self.change_speed(true);
                KeyAction::None
            }
            KeyCode::Char('-') | KeyCode::Char('_') => {
                self.change_speed(false);
                KeyAction::None
            }
            KeyCode::Char('m') | KeyCode::Char('M') => {
                self.mode = self.mode.toggled();
                KeyAction::None
            }
            KeyCode::Char('s') | KeyCode::Char('.') if self.paused => KeyAction::Step,
            KeyCode::Char('r') | KeyCode::Char('R') => KeyAction::Restart,
            KeyCode::Char('n') | KeyCode::Char('N') => KeyAction::Next,
            KeyCode::Tab => KeyAction::NextRobot,
            _ => KeyAction::None,
        }
    }
}

/// The status line: state, step, collisions, speed and the latest message.
pub fn status_line(state: &ViewState, controls: &Controls) -> Line<'static> {
    let e = state.episode();
    draw::status_line(
        state.finished(),
        controls.paused,
        format!(
            " · step {} · collisions {} · {} steps/s",
            e.steps(),
            e.collisions(),
            controls.speed
        ),
        message(state, controls.speed),
    )
}

/// The message of the moment, in its colour: the paper's "TaskComplete" and "CollisionWarning",
/// or why the episode ended (a warning lingers half a second at `speed` steps a second).
fn message(state: &ViewState, speed: u32) -> Option<(String, Color)> {
    let e = state.episode();
    let ended = match e.status() {
        Status::Success => Some(("TaskComplete".to_string(), Color::Green)),
        Status::TimeOut => Some((format!("time-out after {} steps", e.steps()), Color::Yellow)),
        Status::RewardMin => Some(("summed reward fell to R_min".to_string(), Color::Yellow)),
        Status::Deadlock => Some(("deadlock: no robot moved".to_string(), Color::Yellow)),
        Status::Collision => Some(("CollisionWarning: episode over".to_string(), Color::Red)),
        Status::Running => match &state.ending {
            Some(Ending::GaveUp(why)) => Some((format!("stuck: {why}"), Color::Yellow)),
            Some(Ending::Failed(why)) => Some((why.clone(), Color::Red)),
            None => None,
        },
    };
    ended.or_else(|| {
        state
            .warning(speed)
            .then(|| ("CollisionWarning".to_string(), Color::Red))
    })
}

/// The keys of the view and what they do (the team view adds its own to these).
pub(crate) const KEYS: [(&str, &str); 6] = [
    ("space", "pause / resume"),
    ("+ -", "faster / slower"),
    ("m", "whole scene / first person"),
    ("s", "one step, when paused"),
    ("r n", "restart / next seed"),
    ("q", "quit"),
];

/// The side panel's lines.
fn side_lines(state: &ViewState, controls: &Controls) -> Vec<Line<'static>> {
    let e = state.episode();
    let lines = vec![
        draw::field("seed", e.seed().to_string()),
        draw::field("policy", state.policy.clone()),
        draw::field(
            "step",
            format!("{} / {}", e.steps(), e.config().episode.max_steps),
        ),
        draw::field("distance", format!("{:.1} px", e.distance_px())),
        draw::field("goal", draw::direction_text(e.direction_deg())),
        draw::field("heading", format!("{:.1}°", e.pose().z_deg)),
        draw::field("collisions", e.collisions().to_string()),
        draw::field("path", format!("{:.1} px", e.path_length_px())),
        draw::field("speed", format!("{} steps/s", controls.speed)),
    ];
    draw::side_panel(lines, e.movers().is_some(), &KEYS)
}

/// Draws the whole screen for `state` as `controls` set it.
pub fn draw(frame: &mut Frame, state: &ViewState, controls: &Controls) {
    draw::screen(
        frame,
        draw::Shown::lone(state.episode(), &state.path),
        controls.mode,
        "ronap view",
        side_lines(state, controls),
        status_line(state, controls),
    );
}

/// The rollout of `seed` with `policy` reset for it.
pub fn start_episode(
    evaluator: &Evaluator,
    policy: &mut dyn Policy,
    seed: u64,
) -> Result<Rollout, String> {
    Rollout::start(evaluator.world(seed), seed, policy).map_err(|e| match e {
        RunError::Episode { source, .. } => format!("cannot start seed {seed}: {source}"),
        RunError::Policy { source, .. } => format!("seed {seed}: policy failed: {source}"),
        other => other.to_string(),
    })
}

/// What a view steps and draws: one robot's episode ([`Lone`]) or a team's
/// ([`crate::tui::team_view::TeamWatch`]); the keys' settings are [`ViewApp`]'s.
pub trait Watched {
    /// The scene view it starts in.
    const MODE: SceneMode;
    /// Whether the episode is over (or failed).
    fn finished(&self) -> bool;
    /// One step of the policies.
    fn advance(&mut self);
    /// The episode's seed.
    fn seed(&self) -> u64;
    /// Starts the episode of `seed` in place (a failure is shown).
    fn restart(&mut self, seed: u64);
    /// Follows the next robot, if there are several.
    fn next_robot(&mut self) {}
    /// Draws the whole screen as `controls` set it.
    fn draw(&self, frame: &mut Frame, controls: &Controls);
}

/// One robot's episode under its policy, for [`ViewApp`].
pub struct Lone<'a> {
    /// What is on screen.
    pub state: ViewState,
    evaluator: &'a Evaluator,
    policy: &'a mut dyn Policy,
}

impl<'a> Lone<'a> {
    /// `state` stepped by `policy`, new seeds from `evaluator`.
    pub fn new(state: ViewState, evaluator: &'a Evaluator, policy: &'a mut dyn Policy) -> Self {
        Self {
            state,
            evaluator,
            policy,
        }
    }
}

impl Watched for Lone<'_> {
    const MODE: SceneMode = SceneMode::FirstPerson;

    fn finished(&self) -> bool {
        self.state.finished()
    }

    fn advance(&mut self) {
        self.state.advance(self.policy);
    }

    fn seed(&self) -> u64 {
        self.state.episode().seed()
    }

    fn restart(&mut self, seed: u64) {
        let state = &mut self.state;
        match start_episode(self.evaluator, self.policy, seed) {
            Ok(rollout) => *state = ViewState::new(rollout, &state.policy),
            Err(why) => state.ending = Some(Ending::Failed(why)),
        }
    }

    fn draw(&self, frame: &mut Frame, controls: &Controls) {
        draw(frame, &self.state, controls)
    }
}

/// A view as an [`App`]: the policies step at the chosen speed between keys.
pub struct ViewApp<W> {
    /// What is on screen.
    pub watched: W,
    /// The view, pause and speed the keys set (kept across restarts).
    pub controls: Controls,
    owed: f64,
    last_tick: Instant,
}

impl<W: Watched> ViewApp<W> {
    /// The app over `watched`, running at `speed` steps a second in the view it starts in.
    pub fn new(watched: W, speed: u32) -> Self {
        Self {
            watched,
            controls: Controls::new(W::MODE, speed),
            owed: 0.0,
            last_tick: Instant::now(),
        }
    }

    /// Whether the loop should be stepping.
    fn running(&self) -> bool {
        !self.controls.paused && !self.watched.finished()
    }
}

impl<W: Watched> App for ViewApp<W> {
    fn draw(&self, frame: &mut Frame) {
        self.watched.draw(frame, &self.controls)
    }

    fn wait(&self) -> Duration {
        if self.running() {
            let speed = f64::from(self.controls.speed);
            let next = ((1.0 - self.owed).max(0.0) / speed).min(POLL.as_secs_f64());
            Duration::from_secs_f64(next)
        } else {
            POLL
        }
    }

    fn key(&mut self, key: &KeyEvent) -> Result<Option<ExitCode>> {
        let w = &mut self.watched;
        let next_seed = match self.controls.handle_key(key) {
            KeyAction::None => None,
            KeyAction::Quit => return Ok(Some(ExitCode::SUCCESS)),
            KeyAction::Interrupt => return Ok(Some(ExitCode::from(130))),
            KeyAction::Step => {
                if !w.finished() {
                    w.advance();
                }
                None
            }
            KeyAction::NextRobot => {
                w.next_robot();
                None
            }
            KeyAction::Restart => Some(w.seed()),
            KeyAction::Next => Some(w.seed().wrapping_add(1)),
        };
        if let Some(seed) = next_seed {
            w.restart(seed);
            self.owed = 0.0;
        }
        Ok(None)
    }

    fn tick(&mut self) -> Result<bool> {
        let now = Instant::now();
        let mut changed = false;
        if self.running() {
            // Never more than a quarter second of catching up after a slow frame.
            let speed = f64::from(self.controls.speed);
            self.owed =
                (self.owed + (now - self.last_tick).as_secs_f64() * speed).min(speed / 4.0 + 1.0);
            while self.owed >= 1.0 && self.running() {
                self.watched.advance();
                self.owed -= 1.0;
                changed = true;
            }
        } else {
            self.owed = 0.0;
        }
        self.last_tick = now;
        Ok(changed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ratatui::backend::TestBackend;
    use ratatui::buffer::Buffer;
    use ratatui::crossterm::event::KeyModifiers;
    use ratatui::Terminal;
    use ronap_core::policy::{Builtin, PolicyFactory};
    use ronap_core::ValidConfig;

    /// Seed 7 under `policy`, stepped until `stop` says so (or the episode ends).
    fn state_of(policy: Builtin, stop: impl Fn(&ViewState) -> bool) -> ViewState {
        let evaluator =
            Evaluator::new(ValidConfig::default(), ronap_core::sim::Scenes::MazePerSeed);
        let mut p = policy.make().unwrap();
        let rollout = start_episode(&evaluator, p.as_mut(), 7).unwrap();
        let mut state = ViewState::new(rollout, policy.name());
        while !state.finished() && !stop(&state) {
            state.advance(p.as_mut());
        }
        state
    }

    /// The controls `ronap view` starts with at 20 steps a second.
    fn first_person() -> Controls {
        Controls::new(SceneMode::FirstPerson, 20)
    }

    fn render(state: &ViewState, w: u16, h: u16) -> Buffer {
        render_as(state, &first_person(), w, h)
    }

    fn render_as(state: &ViewState, controls: &Controls, w: u16, h: u16) -> Buffer {
        let mut terminal = Terminal::new(TestBackend::new(w, h)).unwrap();
        terminal.draw(|f| draw(f, state, controls)).unwrap();
        terminal.backend().buffer().clone()
    }

    fn row(buf: &Buffer, y: u16) -> String {
        (0..buf.area.width)
            .map(|x| buf[(x, y)].symbol())
            .collect::<String>()
    }

    /// Cells inside `area` drawn in `colour` with a Braille dot.
    fn dots(buf: &Buffer, area: ratatui::layout::Rect, colour: Color) -> Vec<(u16, u16)> {
        let mut cells = vec![];
        for y in area.top()..area.bottom() {
            for x in area.left()..area.right() {
                let c = &buf[(x, y)];
                let braille = c
                    .symbol()
                    .chars()
                    .next()
                    .is_some_and(|ch| ('\u{2801}'..='\u{28ff}').contains(&ch));
                if braille && c.fg == colour {
                    cells.push((x, y));
                }
            }
        }
        cells
    }

    /// A map of the scene panel's colours, one letter a cell: what a snapshot of text misses.
    fn colour_map(buf: &Buffer, area: ratatui::layout::Rect) -> String {
        let mut out = String::new();
        for y in area.top()..area.bottom() {
            for x in area.left()..area.right() {
                let c = &buf[(x, y)];
                out.push(if c.symbol() == " " || c.symbol() == "\u{2800}" {
                    '.'
                } else {
                    match c.fg {
                        Color::Green => 'g',
                        Color::Yellow => 'y',
                        Color::Red => 'r',
                        Color::Magenta => 'M',
                        Color::Cyan => 'C',
                        Color::LightBlue => 'b',
                        Color::White => 'W',
                        Color::DarkGray => 'd',
                        Color::Gray => 'o',
                        Color::LightGreen => 'D',
                        _ => '#',
                    }
                });
            }
            out.push('\n');
        }
        out
    }

    fn inner(area: ratatui::layout::Rect) -> ratatui::layout::Rect {
        ratatui::widgets::Block::bordered().inner(area)
    }

    #[test]
    fn first_person_frame_shows_rays_arrow_distance_and_status() {
        // Seed 7 under APF, at the first state with a near (yellow) ray.
        let near = |s: &ViewState| {
            let range = s.episode().laser().range_px();
            s.episode().readings().iter().any(|&d| d <= 0.6 * range)
        };
        let state = state_of(Builtin::Apf, near);
        assert!(!state.finished(), "APF on seed 7 never came near a wall");
        let buf = render(&state, 80, 24);
        let areas = draw::layout(buf.area);
        let scene = inner(areas.scene);
        for colour in [Color::Green, Color::Yellow] {
            assert!(
                !dots(&buf, scene, colour).is_empty(),
                "no {colour:?} rays:\n{}",
                colour_map(&buf, scene)
            );
        }
        // APF keeps 20 px from walls; the random walk does not: its first close (red) ray.
        let close = state_of(Builtin::Random, |s| {
            let range = s.episode().laser().range_px();
            s.episode().readings().iter().any(|&d| d <= 0.3 * range)
        });
        assert!(!close.finished());
        let close_buf = render(&close, 80, 24);
        assert!(!dots(&close_buf, scene, Color::Red).is_empty());
        // The arrow points at the goal: its cells lie on the side the paper's theta_a says.
        let arrow = dots(&buf, scene, draw::ARROW);
        assert!(arrow.len() >= 3, "{}", colour_map(&buf, scene));
        let centre = (
            f64::from(scene.x) + f64::from(scene.width) / 2.0,
            f64::from(scene.y) + f64::from(scene.height) / 2.0,
        );
        let (mut dx, mut dy) = (0.0, 0.0);
        for &(x, y) in &arrow {
            dx += f64::from(x) + 0.5 - centre.0;
            // Cells are twice as tall as wide; screen y grows downwards.
            dy -= (f64::from(y) + 0.5 - centre.1) * 2.0;
        }
        let seen = dy.atan2(dx).to_degrees();
        let theta_a = 90.0 + state.episode().direction_deg();
        let off = ronap_core::geometry::wrap_deg(seen - theta_a);
        assert!(
            off.min(360.0 - off) < 30.0,
            "arrow at {seen}, theta_a {theta_a}"
        );
        // The distance, green, in the upper right of the scene.
        let distance = format!("{:.1} px", state.episode().distance_px());
        let top: String = (scene.left()..scene.right())
            .map(|x| buf[(x, scene.y)].symbol())
            .collect();
        assert!(top.ends_with(&distance), "{top}");
        let x = scene.right() - 1;
        assert_eq!(buf[(x, scene.y)].fg, draw::DISTANCE);
        // The status line.
        let status = row(&buf, 23);
        assert!(
            status.contains(&format!("step {}", state.episode().steps())),
            "{status}"
        );
        assert!(status.contains("collisions 0"), "{status}");
        insta::assert_snapshot!("view_first_person_seed_7", TestBackendView(&buf));
        insta::assert_snapshot!("view_first_person_seed_7_colours", colour_map(&buf, scene));
    }

    /// The text of a buffer, as `TestBackend` prints it.
    struct TestBackendView<'a>(&'a Buffer);

    impl std::fmt::Display for TestBackendView<'_> {
        fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            for y in 0..self.0.area.height {
                writeln!(f, "{}", row(self.0, y))?;
            }
            Ok(())
        }
    }

    #[test]
    fn m_shows_the_whole_scene_with_the_path_in_blue() {
        let state = state_of(Builtin::Geodesic, |s| s.episode().steps() >= 60);
        let m = KeyEvent::new(KeyCode::Char('m'), KeyModifiers::NONE);
        let mut controls = first_person();
        assert_eq!(controls.handle_key(&m), KeyAction::None);
        assert_eq!(controls.mode, SceneMode::WholeScene);
        let buf = render_as(&state, &controls, 80, 24);
        let scene = inner(draw::layout(buf.area).scene);
        assert!(row(&buf, 0).contains("whole scene · seed 7"));
        assert!(dots(&buf, scene, draw::PATH).len() >= 5);
        assert!(!dots(&buf, scene, draw::ROBOT).is_empty());
        assert!(!dots(&buf, scene, draw::GOAL).is_empty());
        assert!(dots(&buf, scene, draw::WALL).len() > 200);
        insta::assert_snapshot!("view_whole_scene_seed_7", TestBackendView(&buf));
        controls.handle_key(&m);
        assert_eq!(controls.mode, SceneMode::FirstPerson);
    }

    #[test]
    fn moving_obstacles_are_drawn_and_in_the_legend() {
        let sim = ronap_core::SimConfig {
            moving: vec![ronap_core::config::MovingConfig {
                count: 30,
                ..Default::default()
            }],
            ..Default::default()
        };
        let evaluator = Evaluator::new(
            sim.validate().unwrap(),
            ronap_core::sim::Scenes::MazePerSeed,
        );
        let mut p = Builtin::Geodesic.make().unwrap();
        let rollout = start_episode(&evaluator, p.as_mut(), 7).unwrap();
        let mut state = ViewState::new(rollout, "geodesic");
        let buf = render(&state, 80, 24);
        let scene = inner(draw::layout(buf.area).scene);
        // 30 discs of radius 8 px: some dots in the first-person view are not needed, but the
        // legend says what the colour means.
        assert!((0..24).any(|y| row(&buf, y).contains("moving obstacle")));
        let m = KeyEvent::new(KeyCode::Char('m'), KeyModifiers::NONE);
        let mut controls = first_person();
        controls.handle_key(&m);
        let before = dots(&render_as(&state, &controls, 80, 24), scene, draw::MOVER);
        assert!(before.len() >= 15, "{} moving-obstacle cells", before.len());
        for _ in 0..20 {
            state.advance(p.as_mut());
        }
        let after = dots(&render_as(&state, &controls, 80, 24), scene, draw::MOVER);
        assert_ne!(before, after, "the obstacles moved");
    }

    #[test]
    fn collisions_and_success_get_the_papers_messages() {
        /// Always straight on.
        struct Ahead;
        impl Policy for Ahead {
            fn reset(
                &mut self,
                _: &ronap_core::World,
                _: &Episode,
            ) -> Result<(), ronap_core::policy::PolicyError> {
                Ok(())
            }
            fn act(
                &mut self,
                _: &Episode,
            ) -> Result<ronap_core::policy::Decision, ronap_core::policy::PolicyError> {
                Ok(ronap_core::policy::Decision::Act(
                    ronap_core::DiscreteAction::Ahead.into(),
                ))
            }
        }
        let mut state = state_of(Builtin::Geodesic, |_| true);
        // Drive straight on until a wall stops the robot.
        for _ in 0..400 {
            state.advance(&mut Ahead);
            if state.last_collision.is_some() {
                break;
            }
        }
        assert!(state.last_collision.is_some());
        let status = row(&render(&state, 80, 24), 23);
        assert!(status.contains("CollisionWarning"), "{status}");
        let collisions = state.episode().collisions();
        assert!(status.contains(&format!("collisions {collisions}")));

        let done = state_of(Builtin::Geodesic, |_| false);
        assert_eq!(done.episode().status(), Status::Success);
        let status = row(&render(&done, 80, 24), 23);
        assert!(status.contains("TaskComplete"), "{status}");
        assert!(status.contains("■ ended"), "{status}");
    }

    #[test]
    fn keys_pause_change_speed_and_quit() {
        let state = state_of(Builtin::Random, |s| s.episode().steps() >= 1);
        let key = |c| KeyEvent::new(KeyCode::Char(c), KeyModifiers::NONE);
        let mut controls = first_person();
        controls.handle_key(&key(' '));
        assert!(controls.paused && !state.finished());
        assert!(row(&render_as(&state, &controls, 80, 24), 23).contains("paused"));
        assert_eq!(controls.handle_key(&key('s')), KeyAction::Step);
        controls.handle_key(&key(' '));
        assert!(!controls.paused && !state.finished());
        assert_eq!(controls.handle_key(&key('s')), KeyAction::None);
        controls.handle_key(&key('+'));
        assert_eq!(controls.speed, 50);
        controls.handle_key(&key('-'));
        controls.handle_key(&key('-'));
        assert_eq!(controls.speed, 10);
        for _ in 0..20 {
            controls.handle_key(&key('-'));
        }
        assert_eq!(controls.speed, 1);
        assert_eq!(controls.handle_key(&key('q')), KeyAction::Quit);
        let ctrl_c = KeyEvent::new(KeyCode::Char('c'), KeyModifiers::CONTROL);
        assert_eq!(controls.handle_key(&ctrl_c), KeyAction::Interrupt);
        assert_eq!(controls.handle_key(&key('n')), KeyAction::Next);
    }

    #[test]
    fn every_size_from_small_to_large_draws_without_panicking() {
        let state = state_of(Builtin::Apf, |s| s.episode().steps() >= 3);
        for (w, h) in [
            (20, 5),
            (40, 12),
            (60, 20),
            (80, 24),
            (81, 25),
            (120, 40),
            (300, 90),
        ] {
            let buf = render(&state, w, h);
            let text: String = (0..h).map(|y| row(&buf, y)).collect();
            if w >= 40 && h >= 12 {
                assert!(text.contains("step 3"), "{w}x{h}");
            } else {
                assert!(text.contains("needs at least 40x12"), "{w}x{h}");
            }
        }
    }
}
