//! `ronap view` of a scenario with `[[robots]]`: the whole team live in the terminal, each robot
//! with its path and goal in its own colour, one robot followed (Tab for the next) whose rays are
//! drawn and whose first-person view `M` shows; a side panel of team figures and keys and a
//! status line with the step, the robots at their goals, the collisions (with walls and with
//! each other, as robots.csv counts them) and how the episode ended, fitted to the terminal so
//! that at 80x24 the keys and the whole status line are on screen.
//!
//! [`TeamViewState`] is the team episode on screen and [`draw`] a pure function of it and the
//! keys' [`Controls`]; [`TeamWatch`] steps the policies for [`crate::tui::view::ViewApp`], the
//! loop (and the controls) the lone view has too.

use crate::args::TeamPolicies;
use crate::tui::draw::{self, SceneMode};
use crate::tui::view::{self, Controls, Ending, Watched};
use anyhow::Result;
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::Frame;
use ronap_core::eval::Evaluator;
use ronap_core::geometry::Point;
use ronap_core::policy::TeamPolicy;
use ronap_core::run::{RunError, TeamRollout};
use ronap_core::sim::Team;
use ronap_core::{Episode, Status};

/// The team episode the view shows (the keys' settings are [`crate::tui::view::ViewApp`]'s).
pub struct TeamViewState {
    /// The team episode.
    pub rollout: TeamRollout,
    /// The episode's seed.
    pub seed: u64,
    /// Each robot's positions so far, start first.
    pub paths: Vec<Vec<Point>>,
    /// Each robot's policy name.
    pub names: Vec<String>,
    /// The robot whose rays and first-person view are shown.
    pub focus: usize,
    /// Why the episode stopped, when the robots' statuses do not say.
    pub ending: Option<Ending>,
}

impl TeamViewState {
    /// The view of `rollout` (seed `seed`), just started, with robot `k` under `names[k]`.
    pub fn new(rollout: TeamRollout, seed: u64, names: Vec<String>) -> Self {
        let team = rollout.team();
        let paths = (0..team.robots().len())
            .map(|k| vec![team.robot(k).pose().position()])
            .collect();
        Self {
            rollout,
            seed,
            paths,
            names,
            focus: 0,
            ending: None,
        }
    }

    /// The team.
    pub fn team(&self) -> &Team {
        self.rollout.team()
    }

    /// Whether the episode is over.
    pub fn finished(&self) -> bool {
        self.rollout.finished() || self.ending.is_some()
    }

    /// One step of the team's policy, keeping the paths.
    pub fn advance(&mut self, policy: &mut dyn TeamPolicy) {
        match self.rollout.advance(policy) {
            Ok(true) => {
                let team = self.rollout.team();
                for (k, path) in self.paths.iter_mut().enumerate() {
                    if team.present(k) {
                        path.push(team.robot(k).pose().position());
                    }
                }
            }
            Ok(false) => {}
            Err(RunError::Policy { step, source, .. }) => {
                self.ending = Some(Ending::Failed(format!(
                    "step {step}: policy failed: {source}"
                )))
            }
            Err(e) => self.ending = Some(Ending::Failed(e.to_string())),
        }
    }

    /// Robots at their (last) goal.
    fn arrived(&self) -> usize {
        let team = self.team();
        (0..team.robots().len())
            .filter(|&k| team.robot(k).status() == Status::Success)
            .count()
    }
}

/// Walls and other robots that blocked `robots`' steps, as `walls W, robots R` (the
/// `collisions` and `robot_collisions` of robots.csv, summed).
fn collisions<'a>(robots: impl IntoIterator<Item = &'a Episode>) -> String {
    let (walls, others) = robots.into_iter().fold((0u64, 0u64), |(w, o), r| {
        (
            w + u64::from(r.collisions()),
            o + u64::from(r.robot_collisions()),
        )
    });
    format!("walls {walls}, robots {others}")
}

/// The status line: state, step, robots at their goals, collisions with walls and with each
/// other, speed and how it ended, in as many parts as the screen's width needs rows.
pub fn status(state: &TeamViewState, controls: &Controls) -> draw::Status {
    let team = state.team();
    draw::Status {
        finished: state.finished(),
        paused: controls.paused,
        figures: vec![
            format!("step {}", team.steps()),
            format!("at goal {}/{}", state.arrived(), team.robots().len()),
            format!("collisions: {}", collisions(team.robots())),
            format!("{} steps/s", controls.speed),
        ],
        message: message(state),
    }
}

/// How the episode ended, in its colour (nothing while it runs).
fn message(state: &TeamViewState) -> Option<(String, Color)> {
    if let Some(Ending::Failed(why)) = &state.ending {
        return Some((why.clone(), Color::Red));
    }
    if !state.rollout.finished() {
        return None;
    }
    let team = state.team();
    let n = team.robots().len();
    Some(if let Some(why) = state.rollout.infeasible() {
        (format!("infeasible: {why}"), Color::Red)
    } else if team.deadlocked() {
        ("deadlock: no robot moved".to_string(), Color::Yellow)
    } else if state.arrived() == n {
        (
            "TaskComplete: every robot at its goal".to_string(),
            Color::Green,
        )
    } else {
        (
            format!(
                "ended with {} of {n} robots at their goals",
                state.arrived()
            ),
            Color::Yellow,
        )
    })
}

/// The keys of the team view and what they do: the view's, and Tab after the speed keys.
const KEYS: [(&str, &str); 7] = {
    let [pause, speed, map, one, restart, quit] = view::KEYS;
    [
        pause,
        speed,
        ("tab", "follow the next robot"),
        map,
        one,
        restart,
        quit,
    ]
};

/// The side panel: the team, then the followed robot, the legend and the keys.
fn side_panel(state: &TeamViewState, controls: &Controls) -> draw::SidePanel<'static> {
    let team = state.team();
    let k = state.focus;
    let r = team.robot(k);
    let fields = vec![
        draw::field("seed", state.seed.to_string()),
        draw::field(
            "step",
            format!("{} / {}", team.steps(), r.config().episode.max_steps),
        ),
        draw::field(
            "at goal",
            format!("{} / {}", state.arrived(), team.robots().len()),
        ),
        draw::field("collisions", collisions(team.robots())),
        draw::field("speed", format!("{} steps/s", controls.speed)),
        Line::raw(""),
        Line::from(vec![
            Span::styled(
                format!("robot {k}"),
                Style::default()
                    .fg(draw::robot_colour(k))
                    .add_modifier(Modifier::BOLD),
            ),
            Span::raw(format!(
                " · {}",
                state.names.get(k).map_or("", String::as_str)
            )),
        ]),
        draw::field(
            "status",
            if state.rollout.infeasible().is_some() {
                "infeasible".to_string()
            } else {
                status_word(team, k)
            },
        ),
        draw::field(
            "goals",
            format!("{} / {}", r.goals_reached(), team.goals(k).len().max(1)),
        ),
        draw::field("distance", format!("{:.1} px", r.distance_px())),
        draw::field("collisions", collisions([r])),
        draw::field("path", format!("{:.1} px", r.path_length_px())),
    ];
    draw::SidePanel {
        fields,
        legend: draw::team_legend(team.robots().len(), team.movers().is_some()),
        keys: &KEYS,
    }
}

/// Robot `k`'s state in a word.
fn status_word(team: &Team, k: usize) -> String {
    if team.retired(k) {
        return "gave up".to_string();
    }
    match team.robot(k).status() {
        Status::Running => "running",
        Status::Success => "at goal",
        Status::TimeOut => "time-out",
        Status::RewardMin => "R_min",
        Status::Deadlock => "deadlock",
        Status::Collision => "collision",
    }
    .to_string()
}

/// Draws the whole screen for `state` as `controls` set it.
pub fn draw(frame: &mut Frame, state: &TeamViewState, controls: &Controls) {
    let mode = controls.mode;
    let title = match mode {
        SceneMode::WholeScene => format!("{} · seed {}", mode.title(), state.seed),
        SceneMode::FirstPerson => format!(
            "{} of robot {} · seed {}",
            mode.title(),
            state.focus,
            state.seed
        ),
    };
    draw::fitted_screen(
        frame,
        "ronap view",
        side_panel(state, controls),
        &status(state, controls),
        |frame, area| {
            let team = state.team();
            let robots: Vec<draw::Shown<'_>> = (0..team.robots().len())
                .map(|k| draw::Shown {
                    episode: team.robot(k),
                    path: state.paths.get(k).map_or(&[][..], Vec::as_slice),
                    present: team.present(k),
                    running: team.running(k),
                    colours: draw::Shown::colours(k, team.robots().len()),
                })
                .collect();
            let panel = draw::Panel {
                robots: &robots,
                focus: state.focus,
                movers: team.movers(),
                mode,
                title: &title,
            };
            draw::scene(frame, area, &panel)
        },
    );
}

/// A team episode under its policies, for [`crate::tui::view::ViewApp`].
pub struct TeamWatch<'a> {
    /// What is on screen.
    pub state: TeamViewState,
    evaluator: &'a Evaluator,
    policies: Box<dyn TeamPolicy>,
}

/// The team episode of `seed` with `policy` reset for it.
fn start_team(
    evaluator: &Evaluator,
    policy: &mut dyn TeamPolicy,
    seed: u64,
) -> Result<TeamRollout, String> {
    TeamRollout::start(
        evaluator.config(),
        evaluator.worlds().team(seed),
        seed,
        policy,
    )
    .map_err(|e| match e {
        RunError::Episode { source, .. } => format!("cannot start seed {seed}: {source}"),
        RunError::Policy { source, .. } => format!("seed {seed}: policy failed: {source}"),
        other => other.to_string(),
    })
}

impl<'a> TeamWatch<'a> {
    /// The team episode of `seed` from `evaluator` under `policies`.
    pub fn start(evaluator: &'a Evaluator, policies: &TeamPolicies, seed: u64) -> Result<Self> {
        let mut made = policies.start()?;
        let rollout = start_team(evaluator, made.as_mut(), seed).map_err(anyhow::Error::msg)?;
        Ok(Self {
            state: TeamViewState::new(rollout, seed, policies.names.clone()),
            evaluator,
            policies: made,
        })
    }
}

impl Watched for TeamWatch<'_> {
    const MODE: SceneMode = SceneMode::WholeScene;

    fn finished(&self) -> bool {
        self.state.finished()
    }

    fn advance(&mut self) {
        self.state.advance(self.policies.as_mut());
    }

    fn seed(&self) -> u64 {
        self.state.seed
    }

    fn restart(&mut self, seed: u64) {
        match start_team(self.evaluator, self.policies.as_mut(), seed) {
            Ok(rollout) => {
                let focus = self.state.focus;
                let names = std::mem::take(&mut self.state.names);
                self.state = TeamViewState::new(rollout, seed, names);
                self.state.focus = focus.min(self.state.team().robots().len() - 1);
            }
            Err(why) => self.state.ending = Some(Ending::Failed(why)),
        }
    }

    fn next_robot(&mut self) {
        let n = self.state.team().robots().len().max(1);
        self.state.focus = (self.state.focus + 1) % n;
    }

    fn draw(&self, frame: &mut Frame, controls: &Controls) {
        draw(frame, &self.state, controls)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tui::app::App;
    use crate::tui::view::{KeyAction, ViewApp};
    use ratatui::backend::TestBackend;
    use ratatui::buffer::Buffer;
    use ratatui::crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
    use ratatui::Terminal;

    /// The evaluator `ronap view --scenario scenarios/NAME` runs.
    fn evaluator(scenario: &str) -> Evaluator {
        let mut args = crate::args::EpisodeArgs::default();
        args.sim.scenario =
            Some(format!("{}/../../scenarios/{scenario}", env!("CARGO_MANIFEST_DIR")).into());
        let (config, scenes, _) = args.resolve().unwrap();
        Evaluator::new(config, scenes)
    }

    /// The controls the team view starts with at 20 steps a second.
    fn whole_scene() -> Controls {
        Controls::new(SceneMode::WholeScene, 20)
    }

    fn render(state: &TeamViewState, controls: &Controls, w: u16, h: u16) -> Buffer {
        let mut terminal = Terminal::new(TestBackend::new(w, h)).unwrap();
        terminal.draw(|f| draw(f, state, controls)).unwrap();
        terminal.backend().buffer().clone()
    }

    fn text(buf: &Buffer) -> String {
        (0..buf.area.height)
            .map(|y| {
                (0..buf.area.width)
                    .map(|x| buf[(x, y)].symbol())
                    .collect::<String>()
                    + "\n"
            })
            .collect()
    }

    /// Cells of the scene panel drawn in `colour`.
    fn cells_in(buf: &Buffer, colour: Color) -> usize {
        let scene = draw::layout(buf.area).scene;
        (scene.y + 1..scene.y + scene.height - 1)
            .flat_map(|y| (scene.x + 1..scene.x + scene.width - 1).map(move |x| (x, y)))
            .filter(|&(x, y)| buf[(x, y)].fg == colour && buf[(x, y)].symbol() != " ")
            .count()
    }

    #[test]
    fn every_robot_is_drawn_in_its_colour_with_its_path_and_tab_follows_the_next() {
        let evaluator = evaluator("warehouse-team.toml");
        let policies = TeamPolicies::new(evaluator.config(), "geodesic").unwrap();
        let mut app = ViewApp::new(TeamWatch::start(&evaluator, &policies, 3).unwrap(), 20);
        let n = app.watched.state.team().robots().len();
        assert!(n >= 2);
        for _ in 0..40 {
            app.watched.advance();
        }
        let state = &app.watched.state;
        assert!(state.paths.iter().all(|p| p.len() > 1));
        let buf = render(state, &app.controls, 120, 40);
        let screen = text(&buf);
        assert!(screen.contains("whole scene · seed 3"), "{screen}");
        assert!(screen.contains("step 40"), "{screen}");
        assert!(screen.contains(&format!("at goal 0/{n}")) || screen.contains("at goal"));
        assert!(screen.contains("robot 0"), "{screen}");
        for k in 0..n.min(6) {
            assert!(
                cells_in(&buf, draw::robot_colour(k)) > 0,
                "robot {k} not drawn"
            );
        }
        // Tab follows robot 1; M shows its first-person view.
        let key = |c| KeyEvent::new(c, KeyModifiers::NONE);
        assert_eq!(
            app.controls.handle_key(&key(KeyCode::Tab)),
            KeyAction::NextRobot
        );
        app.watched.next_robot();
        assert_eq!(app.watched.state.focus, 1);
        app.controls.handle_key(&key(KeyCode::Char('m')));
        let screen = text(&render(&app.watched.state, &app.controls, 120, 40));
        assert!(screen.contains("first person of robot 1"), "{screen}");
        assert!(screen.contains("robot 1"), "{screen}");
    }

    #[test]
    fn the_corridor_swap_ends_in_a_deadlock_the_status_line_names() {
        let evaluator = evaluator("corridor-swap.toml");
        let policies = TeamPolicies::new(evaluator.config(), "geodesic").unwrap();
        let mut watch = TeamWatch::start(&evaluator, &policies, 0).unwrap();
        let mut steps = 0;
        while !watch.finished() && steps < 100_000 {
            watch.advance();
            steps += 1;
        }
        assert!(watch.finished());
        let status = text(&render(&watch.state, &whole_scene(), 100, 30));
        assert!(
            status.contains("deadlock") || status.contains("TaskComplete"),
            "{status}"
        );
        assert!(status.contains("■ ended"), "{status}");
        // R starts the seed again and keeps the controls.
        let mut app = ViewApp::new(watch, 100);
        app.controls
            .handle_key(&KeyEvent::new(KeyCode::Char(' '), KeyModifiers::NONE));
        let restart = KeyEvent::new(KeyCode::Char('r'), KeyModifiers::NONE);
        assert!(app.key(&restart).unwrap().is_none());
        assert_eq!(app.watched.state.team().steps(), 0);
        assert!(!app.watched.finished());
        let kept = Controls {
            paused: true,
            speed: 100,
            ..whole_scene()
        };
        assert_eq!(app.controls, kept);
    }

    #[test]
    fn robot_collisions_are_shown_as_the_run_records_them_with_every_key_at_80_by_24() {
        let evaluator = evaluator("corridor-swap.toml");
        let policies = TeamPolicies::new(evaluator.config(), "geodesic").unwrap();
        let mut watch = TeamWatch::start(&evaluator, &policies, 1).unwrap();
        while !watch.finished() && watch.state.team().steps() < 100_000 {
            watch.advance();
        }
        let mut policy = policies.start().unwrap();
        let record = evaluator
            .run_team_episode(
                policy.as_mut(),
                &policies.names,
                1,
                ronap_core::eval::Recording::default(),
            )
            .unwrap();
        assert!(record.robot_collisions > 0, "{record:?}");
        let team = format!(
            "walls {}, robots {}",
            record.collisions, record.robot_collisions
        );
        for (w, h) in [(80, 24), (120, 40)] {
            let screen = text(&render(&watch.state, &whole_scene(), w, h));
            let lines: Vec<&str> = screen.lines().collect();
            let first = lines
                .iter()
                .position(|l| l.starts_with(" ■ ended"))
                .unwrap();
            let status = lines[first..].join(" ");
            assert!(status.contains(&format!("collisions: {team}")), "{screen}");
            assert!(status.contains("deadlock: no robot moved"), "{screen}");
            assert!(screen.contains(&format!("collisions {team}")), "{screen}");
            let own = &record.robots[0];
            let own = format!(
                "collisions walls {}, robots {}",
                own.collisions,
                own.team
                    .as_ref()
                    .expect("a robot of a team")
                    .robot_collisions
            );
            assert!(screen.contains(&own), "{screen}");
            for (key, what) in KEYS {
                assert!(screen.contains(&format!("{key:<8}{what}")), "{screen}");
            }
            // The legend when there is room for it.
            assert_eq!(screen.contains("rays  ━ far"), h >= 40, "{screen}");
        }
    }

    #[test]
    fn every_size_draws_without_panicking() {
        let evaluator = evaluator("warehouse-team.toml");
        let policies = TeamPolicies::new(evaluator.config(), "apf").unwrap();
        let mut watch = TeamWatch::start(&evaluator, &policies, 0).unwrap();
        watch.advance();
        for mode in [SceneMode::WholeScene, SceneMode::FirstPerson] {
            let controls = Controls::new(mode, 20);
            for (w, h) in [(20, 5), (40, 12), (80, 24), (200, 60)] {
                let screen = text(&render(&watch.state, &controls, w, h));
                if w >= 40 && h >= 12 {
                    assert!(screen.contains("step 1"), "{w}x{h}");
                }
            }
        }
    }
}
