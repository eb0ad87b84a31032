//! Drawing an episode into a ratatui frame at terminal resolution, with the core's geometry: the
//! paper's first-person view (scene turned so the heading points up, [`HeadingUp`]) and the whole
//! scene with the path so far. Scenes are drawn in Braille dots on ratatui's Canvas: 2 x 4 dots a
//! cell, square dots on the usual terminal whose cells are twice as tall as wide.
//!
//! Colours, in the terminal's 16 named ones: walls white (grey beyond the laser's range), rays in
//! their classes green / yellow / red, the circle of range grey, the goal arrow magenta (the
//! paper's arrow is red, which here would read as a close ray), the robot cyan, the path light
//! blue, start red, goal green, moving obstacles light red (the pictures' orange), and the
//! distance to the goal in green digits at the upper right.

use ratatui::layout::{Alignment, Rect};
use ratatui::style::{Color, Modifier, Style};
use ratatui::symbols::Marker;
use ratatui::text::{Line, Span};
use ratatui::widgets::canvas::{Canvas, Painter, Shape};
use ratatui::widgets::{Block, Paragraph};
use ratatui::Frame;
use ronap_core::geometry::{unit, Point};
use ronap_core::render::{HeadingUp, FIRST_PERSON_HALF_SPAN};
use ronap_core::sim::{Body, Movers, RayClass};
use ronap_core::Episode;

/// Walls within the laser's range (first-person) and everywhere (whole scene).
pub const WALL: Color = Color::White;
/// Walls beyond the laser's range in the first-person view.
pub const WALL_FAR: Color = Color::DarkGray;
/// The circle of laser range.
pub const RANGE: Color = Color::Gray;
/// The arrow towards the goal.
pub const ARROW: Color = Color::Magenta;
/// The robot.
pub const ROBOT: Color = Color::Cyan;
/// The path so far.
pub const PATH: Color = Color::LightBlue;
/// The start.
pub const START: Color = Color::Red;
/// The goal.
pub const GOAL: Color = Color::Green;
/// The distance to the goal.
pub const DISTANCE: Color = Color::LightGreen;
/// Moving obstacles.
pub const MOVER: Color = Color::LightRed;

/// The colour of a laser ray of `class`.
pub fn ray_colour(class: RayClass) -> Color {
    match class {
        RayClass::Green => Color::Green,
        RayClass::Yellow => Color::Yellow,
        RayClass::Red => Color::Red,
    }
}

/// What the scene panel shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SceneMode {
    /// The paper's first-person view.
    FirstPerson,
    /// The whole scene with the path so far (the paper's `M` key).
    WholeScene,
}

impl SceneMode {
    /// The other mode.
    pub fn toggled(self) -> Self {
        match self {
            SceneMode::FirstPerson => SceneMode::WholeScene,
            SceneMode::WholeScene => SceneMode::FirstPerson,
        }
    }

    /// The panel's title.
    pub fn title(self) -> &'static str {
        match self {
            SceneMode::FirstPerson => "first person",
            SceneMode::WholeScene => "whole scene",
        }
    }
}

/// Where the parts of a screen go.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Areas {
    /// The scene panel, as square as the screen allows.
    pub scene: Rect,
    /// The side panel; `None` on a screen too narrow for it.
    pub side: Option<Rect>,
    /// The status line at the bottom.
    pub status: Rect,
}

/// Narrowest useful side panel, cells.
const SIDE_MIN: u16 = 30;
/// Widest side panel; more room goes to the scene.
const SIDE_MAX: u16 = 44;

/// Splits `area`: a status line at the bottom, above it the scene panel (a square of dots, so
/// twice as many columns as rows) and the side panel to its right.
pub fn layout(area: Rect) -> Areas {
    layout_with_status(area, 1)
}

/// [`layout`] with `status_rows` rows for the status line.
pub fn layout_with_status(area: Rect, status_rows: u16) -> Areas {
    let status_h = status_rows.min(area.height);
    let main_h = area.height - status_h;
    let status = Rect::new(area.x, area.y + main_h, area.width, status_h);
    let square = main_h.saturating_sub(2).saturating_mul(2).saturating_add(2);
    let (scene_w, side_w) = if area.width >= square + SIDE_MIN {
        let side = (area.width - square).min(SIDE_MAX);
        (area.width - side, side)
    } else if area.width >= 2 * SIDE_MIN {
        (area.width - SIDE_MIN, SIDE_MIN)
    } else {
        (area.width, 0)
    };
    let scene = Rect::new(area.x, area.y, scene_w, main_h);
    let side = (side_w > 0).then(|| Rect::new(area.x + scene_w, area.y, side_w, main_h));
    Areas {
        scene,
        side,
        status,
    }
}

/// A Braille dot grid over a canvas area: `px_per_dot` px a dot, dot `(i, j)` (from the top left)
/// covering `[left + i s, left + (i + 1) s) x (top - (j + 1) s, top - j s]`.
#[derive(Clone, Copy, Debug)]
struct DotGrid {
    cols: usize,
    rows: usize,
    px_per_dot: f64,
    left: f64,
    top: f64,
}

impl DotGrid {
    /// The grid showing at least `extent` px centred on `centre`, square dots.
    fn fit(area: Rect, centre: (f64, f64), extent: (f64, f64)) -> Self {
        let cols = usize::from(area.width) * 2;
        let rows = usize::from(area.height) * 4;
        let px_per_dot = (extent.0 / cols.max(1) as f64)
            .max(extent.1 / rows.max(1) as f64)
            .max(1e-9);
        Self {
            cols,
            rows,
            px_per_dot,
            left: centre.0 - cols as f64 * px_per_dot / 2.0,
            top: centre.1 + rows as f64 * px_per_dot / 2.0,
        }
    }

    /// The centre of dot `(i, j)`.
    fn centre(&self, i: usize, j: usize) -> (f64, f64) {
        (
            self.left + (i as f64 + 0.5) * self.px_per_dot,
            self.top - (j as f64 + 0.5) * self.px_per_dot,
        )
    }

    /// The dot holding `(x, y)`, if on the grid.
    fn dot(&self, x: f64, y: f64) -> Option<(usize, usize)> {
        let i = ((x - self.left) / self.px_per_dot).floor();
        let j = ((self.top - y) / self.px_per_dot).floor();
        (i >= 0.0 && j >= 0.0 && i < self.cols as f64 && j < self.rows as f64)
            .then_some((i as usize, j as usize))
    }

    /// Every dot with its centre, row by row.
    fn dots(&self) -> impl Iterator<Item = ((usize, usize), (f64, f64))> + '_ {
        (0..self.rows).flat_map(move |j| (0..self.cols).map(move |i| ((i, j), self.centre(i, j))))
    }
}

/// Dots to paint, in order: a dot painted later sets its cell's colour, and dots sharing a cell
/// merge into one Braille character.
struct Pen {
    grid: DotGrid,
    dots: Vec<(usize, usize, Color)>,
}

impl Pen {
    fn new(grid: DotGrid) -> Self {
        Self {
            grid,
            dots: Vec::new(),
        }
    }

    /// The dot at `(x, y)`, if on the grid.
    fn point(&mut self, x: f64, y: f64, colour: Color) {
        if let Some((i, j)) = self.grid.dot(x, y) {
            self.dots.push((i, j, colour));
        }
    }

    /// The segment `a`-`b`, sampled every half dot; the parts off the grid are left out.
    fn line(&mut self, a: (f64, f64), b: (f64, f64), colour: Color) {
        let n = ((b.0 - a.0).hypot(b.1 - a.1) / self.grid.px_per_dot * 2.0).ceil() as usize;
        for k in 0..=n.max(1) {
            let t = k as f64 / n.max(1) as f64;
            self.point(a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t, colour);
        }
    }

    /// A filled disc of `radius` around `c`: every dot whose centre lies inside, and at least the
    /// dot holding `c`.
    fn disc(&mut self, c: (f64, f64), radius: f64, colour: Color) {
        self.point(c.0, c.1, colour);
        let s = self.grid.px_per_dot;
        let reach = (radius / s).ceil() as i64 + 1;
        let Some((ci, cj)) = self.grid.dot(c.0, c.1) else {
            return;
        };
        for dj in -reach..=reach {
            for di in -reach..=reach {
                let (i, j) = (ci as i64 + di, cj as i64 + dj);
                if i < 0 || j < 0 || i >= self.grid.cols as i64 || j >= self.grid.rows as i64 {
                    continue;
                }
                let (x, y) = self.grid.centre(i as usize, j as usize);
                if (x - c.0).hypot(y - c.1) <= radius {
                    self.dots.push((i as usize, j as usize, colour));
                }
            }
        }
    }

    /// The circle of `radius` around `c`, sampled every half dot.
    fn circle(&mut self, c: (f64, f64), radius: f64, colour: Color) {
        let n = (std::f64::consts::TAU * radius / self.grid.px_per_dot * 2.0).ceil() as usize;
        for k in 0..n.max(8) {
            let a = std::f64::consts::TAU * k as f64 / n.max(8) as f64;
            self.point(c.0 + radius * a.cos(), c.1 + radius * a.sin(), colour);
        }
    }

    /// An arrow from `from` along `angle_deg`, `length` long, head included.
    fn arrow(&mut self, from: (f64, f64), angle_deg: f64, length: f64, colour: Color) {
        let d = unit(angle_deg);
        let tip = (from.0 + d.x * length, from.1 + d.y * length);
        self.line(from, tip, colour);
        for wing in [150.0, -150.0] {
            let w = unit(angle_deg + wing);
            self.line(
                tip,
                (tip.0 + w.x * length * 0.35, tip.1 + w.y * length * 0.35),
                colour,
            );
        }
    }

    /// A canvas painting the dots, filling `area`.
    fn render(self, frame: &mut Frame, area: Rect) {
        let canvas = Canvas::default()
            .marker(Marker::Braille)
            .x_bounds([0.0, 1.0])
            .y_bounds([0.0, 1.0])
            .paint(|ctx| ctx.draw(&self));
        frame.render_widget(canvas, area);
    }
}

impl Shape for Pen {
    fn draw(&self, painter: &mut Painter) {
        for &(i, j, colour) in &self.dots {
            painter.paint(i, j, colour);
        }
    }
}

/// A robot as the scene panel draws it.
pub struct Shown<'a> {
    /// Its episode.
    pub episode: &'a Episode,
    /// Its positions so far, start first.
    pub path: &'a [Point],
    /// Whether it is in the scene: a robot taken out has no body.
    pub present: bool,
    /// Whether its episode goes on: a team robot's goal ring shows only then.
    pub running: bool,
    /// Its path's colour and its body's.
    pub colours: (Color, Color),
}

impl<'a> Shown<'a> {
    /// A lone robot (a team of one), in [`Shown::colours`].
    pub fn lone(episode: &'a Episode, path: &'a [Point]) -> Self {
        Self {
            episode,
            path,
            present: true,
            running: !episode.status().is_done(),
            colours: Self::colours(0, 1),
        }
    }

    /// Robot `k`'s path and body colours among `n` robots: a lone robot's (path light blue, body
    /// cyan) for a team of one, else its own colour for both.
    pub fn colours(k: usize, n: usize) -> (Color, Color) {
        match n {
            1 => (PATH, ROBOT),
            _ => (robot_colour(k), robot_colour(k)),
        }
    }
}

/// What the scene panel shows: the robots, the one followed, the moving obstacles, the view and
/// the panel's title.
pub struct Panel<'a> {
    /// Every robot, in team order.
    pub robots: &'a [Shown<'a>],
    /// The robot followed: its rays, its first-person view and its distance to the goal.
    pub focus: usize,
    /// The moving obstacles.
    pub movers: Option<&'a Movers>,
    /// Whole scene or first person.
    pub mode: SceneMode,
    /// The panel's title.
    pub title: &'a str,
}

/// Draws the scene panel in `area`: a block titled with the panel's title holding its robots in
/// its mode, with the followed robot's distance to its goal in the upper right. One robot is
/// drawn as the paper's screen draws it (start and goal filled, [`whole_scene`]); a team's robots
/// each in their colours.
pub fn scene(frame: &mut Frame, area: Rect, panel: &Panel<'_>) {
    let block = Block::bordered().title(format!(" {} ", panel.title));
    let inner = block.inner(area);
    frame.render_widget(block, area);
    if inner.width < 2 || inner.height < 2 || panel.robots.is_empty() {
        return;
    }
    let focus = panel.focus.min(panel.robots.len() - 1);
    let followed = panel.robots[focus].episode;
    let pen = match panel.mode {
        SceneMode::FirstPerson => {
            let mut pen = first_person(inner, followed);
            let view = HeadingUp::new(followed.pose());
            if followed.movers().is_none() {
                movers(&mut pen, panel.movers, |p| view.to_view(p));
            }
            for (k, r) in panel.robots.iter().enumerate() {
                if k != focus && r.present {
                    let at = view.to_view(r.episode.pose().position());
                    pen.disc(at, r.episode.config().robot.radius_px, r.colours.1);
                }
            }
            pen
        }
        SceneMode::WholeScene => whole_scene(inner, panel.robots, focus, panel.movers),
    };
    pen.render(frame, inner);
    let distance = Paragraph::new(Span::styled(
        format!("{:.1} px", followed.distance_px()),
        Style::default().fg(DISTANCE).add_modifier(Modifier::BOLD),
    ))
    .alignment(Alignment::Right);
    frame.render_widget(distance, Rect::new(inner.x, inner.y, inner.width, 1));
}

/// The laser rays of `episode`, each as its end point in the coordinates `to` gives and its
/// colour.
fn rays(episode: &Episode, to: impl Fn(Point) -> (f64, f64)) -> Vec<((f64, f64), Color)> {
    let laser = episode.laser();
    let pose = episode.pose();
    episode
        .readings()
        .iter()
        .enumerate()
        .map(|(i, &d)| {
            let end = pose.position() + unit(laser.beam_angle_deg(i, pose.z_deg)) * d;
            (to(end), ray_colour(laser.class(d)))
        })
        .collect()
}

/// The present moving obstacles in the coordinates `to` gives: discs filled (at least a dot),
/// boxes outlined with their centre filled.
fn movers(pen: &mut Pen, movers: Option<&Movers>, to: impl Fn(Point) -> (f64, f64)) {
    let Some(movers) = movers else {
        return;
    };
    let least = pen.grid.px_per_dot * 0.5;
    for m in movers.items().filter(|m| m.present()) {
        let c = m.position();
        match m.body() {
            Body::Disc(r) => pen.disc(to(c), r.max(least), MOVER),
            Body::Box(h) => {
                let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
                    .map(|(sx, sy)| to(Point::new(c.x + sx * h.x, c.y + sy * h.y)));
                for k in 0..4 {
                    pen.line(corners[k], corners[(k + 1) % 4], MOVER);
                }
                pen.disc(to(c), h.x.min(h.y).max(least), MOVER);
            }
        }
    }
}

/// The paper's first-person view: heading up, walls within the laser's range brighter than those
/// beyond, the circle of range, the rays in their colour classes, the goal arrow at the paper's
/// angle `theta_a = 90 + (theta - z)`, and the robot in the middle.
fn first_person(area: Rect, episode: &Episode) -> Pen {
    let range = episode.laser().range_px();
    let span = 2.0 * FIRST_PERSON_HALF_SPAN * range;
    let mut pen = Pen::new(DotGrid::fit(area, (0.0, 0.0), (span, span)));
    let view = HeadingUp::new(episode.pose());
    let scene = episode.scene();
    let probe = pen.grid.px_per_dot * 0.5;
    let grid = pen.grid;
    for ((i, j), (u, v)) in grid.dots() {
        let p = view.to_scene(u, v);
        if scene.occupied(p) || !scene.disc_clear(p, probe) {
            let colour = if u.hypot(v) <= range { WALL } else { WALL_FAR };
            pen.dots.push((i, j, colour));
        }
    }
    movers(&mut pen, episode.movers(), |p| view.to_view(p));
    pen.circle((0.0, 0.0), range, RANGE);
    for (end, colour) in rays(episode, |p| view.to_view(p)) {
        pen.line((0.0, 0.0), end, colour);
    }
    let config = episode.config();
    pen.disc(
        view.to_view(episode.goal()),
        config.episode.goal_tolerance_px,
        GOAL,
    );
    pen.arrow(
        (0.0, 0.0),
        view.angle_deg(episode.bearing_deg()),
        range * 0.6,
        ARROW,
    );
    pen.disc((0.0, 0.0), config.robot.radius_px, ROBOT);
    pen
}

/// The robot's footprint at `pose`: its rectangle's outline, or a disc of `radius`.
fn body(
    pen: &mut Pen,
    pose: ronap_core::Pose,
    robot: &ronap_core::config::RobotConfig,
    radius: f64,
    colour: Color,
) {
    match ronap_core::sim::Robot::corners(robot, pose) {
        Some(c) => {
            for i in 0..c.len() {
                let (a, b) = (c[i], c[(i + 1) % c.len()]);
                pen.line((a.x, a.y), (b.x, b.y), colour);
            }
        }
        None => pen.disc((pose.x, pose.y), radius, colour),
    }
}

/// The whole scene: walls, each robot's path so far, the moving obstacles, the followed robot's
/// rays, then each robot: one robot's start and goal filled, a team robot's goal as a ring while
/// it runs, and each robot in the scene, the followed one with a tick along its heading.
fn whole_scene(area: Rect, robots: &[Shown<'_>], focus: usize, obstacles: Option<&Movers>) -> Pen {
    let followed = robots[focus].episode;
    let mut pen = scene_walls(area, followed);
    let s = pen.grid.px_per_dot;
    for r in robots {
        trail(&mut pen, r.path, r.episode.pose().position(), r.colours.0);
    }
    movers(&mut pen, obstacles, |p| (p.x, p.y));
    let pose = followed.pose();
    for (end, colour) in rays(followed, |p| (p.x, p.y)) {
        pen.line((pose.x, pose.y), end, colour);
    }
    let lone = robots.len() == 1;
    for (k, r) in robots.iter().enumerate() {
        let config = r.episode.config();
        let goal = r.episode.goal();
        if lone {
            let start = r.episode.start().position();
            pen.disc((start.x, start.y), config.robot.radius_px, START);
            pen.disc((goal.x, goal.y), config.episode.goal_tolerance_px, GOAL);
        } else if r.running {
            let ring = config.episode.goal_tolerance_px.max(s);
            pen.circle((goal.x, goal.y), ring, r.colours.1);
        }
        if r.present {
            let pose = r.episode.pose();
            let radius = config.robot.radius_px.max(s);
            body(&mut pen, pose, &config.robot, radius, r.colours.1);
            if k == focus {
                let tip = pose.position() + unit(pose.z_deg) * radius * 2.5;
                pen.line((pose.x, pose.y), (tip.x, tip.y), r.colours.1);
            }
        }
    }
    pen
}

/// The whole scene of `episode` fitted into `area`, its walls drawn.
fn scene_walls(area: Rect, episode: &Episode) -> Pen {
    let scene = episode.scene();
    let (w, h) = (scene.width(), scene.height());
    let mut pen = Pen::new(DotGrid::fit(area, (w / 2.0, h / 2.0), (w, h)));
    let grid = pen.grid;
    let s = grid.px_per_dot;
    let bounds = scene.bounds();
    // A dot is wall if an obstacle lies within its half diagonal, so thin walls never fall
    // between dot centres.
    for ((i, j), (x, y)) in grid.dots() {
        let p = Point::new(x, y);
        if bounds.contains(p) && (scene.occupied(p) || !scene.disc_clear(p, s * 0.71)) {
            pen.dots.push((i, j, WALL));
        }
    }
    pen
}

/// The path `path` then `now`, in `colour`; points closer than a dot draw nothing new.
fn trail(pen: &mut Pen, path: &[Point], now: Point, colour: Color) {
    let s = pen.grid.px_per_dot;
    let mut trail: Vec<(f64, f64)> = Vec::new();
    for p in path.iter().chain(std::iter::once(&now)) {
        match trail.last() {
            Some(&(x, y)) if (p.x - x).hypot(p.y - y) < s => {}
            _ => trail.push((p.x, p.y)),
        }
    }
    for pair in trail.windows(2) {
        pen.line(pair[0], pair[1], colour);
    }
}

/// Robot `k`'s colour in a team view (six colours, repeating).
pub fn robot_colour(k: usize) -> Color {
    const COLOURS: [Color; 6] = [
        Color::Cyan,
        Color::Yellow,
        Color::LightMagenta,
        Color::LightGreen,
        Color::LightBlue,
        Color::Blue,
    ];
    COLOURS[k % COLOURS.len()]
}

/// Where the goal is, relative to the heading: `ahead`, `35° left`, `170° right`, `behind`.
pub fn direction_text(direction_deg: f64) -> String {
    let d = direction_deg.round() as i64 % 360;
    match d {
        0 => "ahead".to_string(),
        180 => "behind".to_string(),
        d if d < 180 => format!("{d}° left"),
        d => format!("{}° right", 360 - d),
    }
}

/// The legend of the scene's colours, as lines for a side panel (with the moving obstacles'
/// when there are some).
pub fn legend(moving: bool) -> Vec<Line<'static>> {
    let mark = |text: &'static str, colour: Color| Span::styled(text, Style::default().fg(colour));
    let mut lines = vec![
        rays_legend(),
        Line::from(vec![
            mark("━▶ goal  ", ARROW),
            mark("● robot  ", ROBOT),
            mark("━ path", PATH),
        ]),
    ];
    if moving {
        lines.push(Line::from(mark("● moving obstacle", MOVER)));
    }
    lines
}

/// The legend of a team view: each robot, its path and the ring round its goal in the robot's
/// own colour (`robots` of them, the first six named).
pub fn team_legend(robots: usize, moving: bool) -> Vec<Line<'static>> {
    let mut marks = vec![Span::raw("robots ")];
    marks.extend(
        (0..robots.min(6))
            .map(|k| Span::styled(format!("● {k} "), Style::default().fg(robot_colour(k)))),
    );
    if robots > 6 {
        marks.push(Span::raw("…"));
    }
    let mut lines = vec![
        rays_legend(),
        Line::from(marks),
        Line::raw("━ path  ○ goal: its robot's colour"),
    ];
    if moving {
        lines.push(Line::from(Span::styled(
            "● moving obstacle",
            Style::default().fg(MOVER),
        )));
    }
    lines
}

/// The rays' colour classes.
fn rays_legend() -> Line<'static> {
    let mark = |text: &'static str, colour: Color| Span::styled(text, Style::default().fg(colour));
    Line::from(vec![
        Span::raw("rays  "),
        mark("━ far ", Color::Green),
        mark("━ near ", Color::Yellow),
        mark("━ close", Color::Red),
    ])
}

/// A side-panel line: a label in a fixed column, then `value`.
pub fn field(label: &str, value: impl Into<String>) -> Line<'static> {
    Line::from(vec![
        Span::styled(
            format!("{label:<11}"),
            Style::default().add_modifier(Modifier::DIM),
        ),
        Span::raw(value.into()),
    ])
}

/// A key and what it does, for a side panel.
pub fn key_help(keys: &str, what: &str) -> Line<'static> {
    Line::from(vec![
        Span::styled(format!("{keys:<8}"), Style::default().fg(Color::Cyan)),
        Span::raw(what.to_string()),
    ])
}

/// A side panel: `fields`, the colour legend (`moving`: with moving obstacles), then each key
/// with what it does.
pub fn side_panel(
    fields: Vec<Line<'static>>,
    moving: bool,
    keys: &[(&str, &str)],
) -> Vec<Line<'static>> {
    side_panel_with(fields, legend(moving), keys)
}

/// [`side_panel`] with its own `legend`.
pub fn side_panel_with(
    mut fields: Vec<Line<'static>>,
    legend: Vec<Line<'static>>,
    keys: &[(&str, &str)],
) -> Vec<Line<'static>> {
    fields.push(Line::raw(""));
    fields.extend(legend);
    fields.push(Line::raw(""));
    fields.extend(keys.iter().map(|(k, what)| key_help(k, what)));
    fields
}

/// A side panel that fits its height, its parts in the order they give way when it is short.
pub struct SidePanel<'a> {
    /// The figures, always shown (first).
    pub fields: Vec<Line<'static>>,
    /// The colour legend, the first to go.
    pub legend: Vec<Line<'static>>,
    /// Each key with what it does, shown last and kept.
    pub keys: &'a [(&'a str, &'a str)],
}

impl SidePanel<'_> {
    /// The panel's lines for `height` rows: [`side_panel_with`] when everything fits; else
    /// without the legend; else without the blank line before the keys.
    pub fn lines(self, height: usize) -> Vec<Line<'static>> {
        let (fields, keys) = (self.fields.len(), self.keys.len());
        if fields + 1 + self.legend.len() + 1 + keys <= height {
            return side_panel_with(self.fields, self.legend, self.keys);
        }
        let mut lines = self.fields;
        if fields + 1 + keys <= height {
            lines.push(Line::raw(""));
        }
        lines.extend(self.keys.iter().map(|(k, what)| key_help(k, what)));
        lines
    }
}

/// A status line in parts: ended, paused or running, then each of `figures`, then `message` in
/// its colour, separated by ` · `.
pub struct Status {
    /// Whether the episode is over.
    pub finished: bool,
    /// Whether stepping is paused.
    pub paused: bool,
    /// The figures, each a part.
    pub figures: Vec<String>,
    /// How the episode ended (or the message of the moment), in its colour.
    pub message: Option<(String, Color)>,
}

impl Status {
    /// The status on as many rows of `width` cells as it needs, broken between parts only (a
    /// part wider than a row is cut by the screen). On one row it reads as [`status_line`].
    pub fn rows(&self, width: u16) -> Vec<Line<'static>> {
        let (mark, mark_style) = state_mark(self.finished, self.paused);
        let mut parts = vec![Span::styled(mark, mark_style)];
        parts.extend(self.figures.iter().map(|f| Span::raw(f.clone())));
        if let Some((text, colour)) = &self.message {
            parts.push(Span::styled(
                text.clone(),
                Style::default().fg(*colour).add_modifier(Modifier::BOLD),
            ));
        }
        let mut rows: Vec<Line<'static>> = Vec::new();
        for part in parts {
            let gap = Span::raw(" · ");
            match rows.last_mut() {
                Some(row) if row.width() + gap.width() + part.width() <= usize::from(width) => {
                    row.spans.extend([gap, part]);
                }
                _ => rows.push(Line::from(vec![Span::raw(" "), part])),
            }
        }
        rows
    }
}

/// A whole screen fitted to the terminal: the status on the rows its width needs (at most a
/// third of the screen), the side panel titled `name` fitted to its height when there is room
/// for one, and the scene panel, which `draw_scene` draws into the area it is given, in the rest.
pub fn fitted_screen(
    frame: &mut Frame,
    name: &str,
    side: SidePanel<'_>,
    status: &Status,
    draw_scene: impl FnOnce(&mut Frame, Rect),
) {
    if too_small(frame) {
        return;
    }
    let area = frame.area();
    let mut rows = status.rows(area.width);
    rows.truncate(usize::from((area.height / 3).max(1)));
    let areas = layout_with_status(area, rows.len() as u16);
    draw_scene(frame, areas.scene);
    if let Some(panel) = areas.side {
        let lines = side.lines(usize::from(panel.height.saturating_sub(2)));
        frame.render_widget(
            Paragraph::new(lines).block(Block::bordered().title(format!(" {name} "))),
            panel,
        );
    }
    frame.render_widget(Paragraph::new(rows), areas.status);
}

/// A whole screen: the scene of the lone `robot` (titled with the mode and seed), the side
/// panel titled `name` when there is room, and the status line.
pub fn screen(
    frame: &mut Frame,
    robot: Shown<'_>,
    mode: SceneMode,
    name: &str,
    side: Vec<Line<'static>>,
    status: Line<'static>,
) {
    let title = format!("{} · seed {}", mode.title(), robot.episode.seed());
    let movers = robot.episode.movers();
    let robots = [robot];
    let panel = Panel {
        robots: &robots,
        focus: 0,
        movers,
        mode,
        title: &title,
    };
    screen_with(frame, name, side, status, |frame, area| {
        scene(frame, area, &panel)
    });
}

/// A whole screen whose scene panel `draw_scene` draws into the area it is given: the side panel
/// titled `name` when there is room, and the status line.
pub fn screen_with(
    frame: &mut Frame,
    name: &str,
    side: Vec<Line<'static>>,
    status: Line<'static>,
    draw_scene: impl FnOnce(&mut Frame, Rect),
) {
    if too_small(frame) {
        return;
    }
    let areas = layout(frame.area());
    draw_scene(frame, areas.scene);
    if let Some(area) = areas.side {
        frame.render_widget(
            Paragraph::new(side).block(Block::bordered().title(format!(" {name} "))),
            area,
        );
    }
    frame.render_widget(Paragraph::new(status), areas.status);
}

/// A status line: ended, paused or running, then `figures`, then `message` in its colour.
pub fn status_line(
    finished: bool,
    paused: bool,
    figures: String,
    message: Option<(String, Color)>,
) -> Line<'static> {
    let (mark, mark_style) = state_mark(finished, paused);
    let mut spans = vec![
        Span::raw(" "),
        Span::styled(mark, mark_style),
        Span::raw(figures),
    ];
    if let Some((text, colour)) = message {
        spans.push(Span::raw(" · "));
        spans.push(Span::styled(
            text,
            Style::default().fg(colour).add_modifier(Modifier::BOLD),
        ));
    }
    Line::from(spans)
}

/// Ended, paused or running, in its style.
fn state_mark(finished: bool, paused: bool) -> (&'static str, Style) {
    if finished {
        ("■ ended", Style::default().add_modifier(Modifier::BOLD))
    } else if paused {
        ("❚❚ paused", Style::default().fg(Color::Yellow))
    } else {
        ("▶ running", Style::default().fg(Color::Green))
    }
}

/// The message shown when the terminal is too small for anything useful.
pub fn too_small(frame: &mut Frame) -> bool {
    let area = frame.area();
    if area.width >= 40 && area.height >= 12 {
        return false;
    }
    frame.render_widget(
        Paragraph::new(format!(
            "terminal {}x{}: ronap needs at least 40x12 (80x24 or more is best)",
            area.width, area.height
        ))
        .wrap(ratatui::widgets::Wrap { trim: true }),
        area,
    );
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layout_at_80_by_24_is_a_square_scene_a_side_panel_and_a_status_line() {
        let a = layout(Rect::new(0, 0, 80, 24));
        assert_eq!(a.scene, Rect::new(0, 0, 44, 23));
        assert_eq!(a.side, Some(Rect::new(44, 0, 36, 23)));
        assert_eq!(a.status, Rect::new(0, 23, 80, 1));
        let wide = layout(Rect::new(0, 0, 200, 50));
        assert_eq!(wide.side.map(|s| s.width), Some(SIDE_MAX));
        assert_eq!(wide.scene.width, 200 - SIDE_MAX);
        let narrow = layout(Rect::new(0, 0, 50, 24));
        assert_eq!(narrow.side, None);
        assert_eq!(narrow.scene.width, 50);
    }

    #[test]
    fn a_status_too_long_for_one_row_breaks_between_its_parts() {
        let status = Status {
            finished: true,
            paused: false,
            figures: vec!["step 12".to_string(), "collisions: walls 0".to_string()],
            message: Some(("deadlock: no robot moved".to_string(), Color::Yellow)),
        };
        let text = |rows: Vec<Line<'static>>| -> Vec<String> {
            rows.iter().map(|l| l.to_string()).collect()
        };
        let one = " ■ ended · step 12 · collisions: walls 0 · deadlock: no robot moved";
        assert_eq!(text(status.rows(80)), [one]);
        let as_before = status_line(
            true,
            false,
            " · step 12 · collisions: walls 0".to_string(),
            status.message.clone(),
        );
        assert_eq!(as_before.to_string(), one);
        assert_eq!(
            text(status.rows(50)),
            [
                " ■ ended · step 12 · collisions: walls 0",
                " deadlock: no robot moved"
            ]
        );
        assert_eq!(
            text(status.rows(10)),
            [
                " ■ ended",
                " step 12",
                " collisions: walls 0",
                " deadlock: no robot moved"
            ]
        );
    }

    #[test]
    fn a_short_side_panel_gives_up_its_legend_then_its_blank_line_but_keeps_its_keys() {
        let panel = || SidePanel {
            fields: vec![field("a", "1"), field("b", "2")],
            legend: vec![Line::raw("legend 1"), Line::raw("legend 2")],
            keys: &[("q", "quit"), ("m", "map")],
        };
        let text = |height| -> Vec<String> {
            panel()
                .lines(height)
                .iter()
                .map(|l| l.to_string().trim_end().to_string())
                .collect()
        };
        let all = [
            "a          1",
            "b          2",
            "",
            "legend 1",
            "legend 2",
            "",
            "q       quit",
            "m       map",
        ];
        assert_eq!(text(8), all);
        assert_eq!(text(20), all);
        assert_eq!(
            text(7),
            [
                "a          1",
                "b          2",
                "",
                "q       quit",
                "m       map"
            ]
        );
        assert_eq!(
            text(4),
            [
                "a          1",
                "b          2",
                "q       quit",
                "m       map"
            ]
        );
    }

    #[test]
    fn directions_read_as_a_person_says_them() {
        assert_eq!(direction_text(0.2), "ahead");
        assert_eq!(direction_text(359.7), "ahead");
        assert_eq!(direction_text(35.0), "35° left");
        assert_eq!(direction_text(190.0), "170° right");
        assert_eq!(direction_text(180.0), "behind");
    }

    #[test]
    fn dot_grid_centres_lie_in_their_own_dots_and_cover_the_extent() {
        let g = DotGrid::fit(Rect::new(0, 0, 10, 5), (50.0, 50.0), (100.0, 100.0));
        assert_eq!((g.cols, g.rows), (20, 20));
        assert!((g.px_per_dot - 5.0).abs() < 1e-12);
        for (i, j) in [(0, 0), (7, 3), (19, 19)] {
            let (x, y) = g.centre(i, j);
            assert_eq!(g.dot(x, y), Some((i, j)));
        }
        assert_eq!(g.dot(0.1, 99.9), Some((0, 0)));
        assert_eq!(g.dot(99.9, 0.1), Some((19, 19)));
        assert_eq!(g.dot(100.1, 50.0), None);
        assert_eq!(g.dot(50.0, -0.1), None);
    }
}
