//! The HTML episode player: one self-contained page (no network, no external script: the
//! player's script and style, the scene picture and the episode's numbers all inline) that
//! plays one or several recorded episodes ([`Trace`]) on a canvas, with a shared timeline.
//!
//! The numbers are packed small: positions, distances and laser readings quantised to a power of
//! two of a px (1/64 px in a scene up to 333 px across, 1/16 px in a 1000 px one), angles to 0.01 degree, each series stored as differences from the frame
//! before (most are small), bytes split into planes (all low bytes, then all high bytes),
//! deflated (zlib) and base64-encoded; the browser inflates them with its own
//! `DecompressionStream`. The still scene is one PNG picture; everything that moves is drawn
//! from the numbers.

mod trace;

pub use trace::{Acted, Recorder, Trace};

use trace::Move;

use crate::geometry::Point;
use crate::sim::Body;
use base64::Engine as _;
use std::fmt::Write as _;

/// The player's script.
const SCRIPT: &str = include_str!("player.js");
/// The player's style.
const STYLE: &str = include_str!("player.css");

/// Largest side of the scene picture, pixels (the canvas scales it to the window).
const BACKGROUND_SIDE_PX: f64 = 1200.0;

/// A page of players.
#[derive(Clone, Debug)]
pub struct PlayerPage<'a> {
    /// The page's title.
    pub title: String,
    /// The episodes, played side by side on one timeline (usually one).
    pub traces: &'a [Trace],
    /// A line under the title (what the episodes are, where they come from), if any.
    pub note: Option<String>,
}

/// A page that could not be made.
#[derive(Debug, thiserror::Error)]
pub enum PlayerError {
    /// The scene picture could not be encoded.
    #[error("cannot encode the scene picture: {0}")]
    Picture(#[from] image::ImageError),
    /// No episode to play.
    #[error("no episode to play")]
    Empty,
}

/// The HTML of `page`.
pub fn player_page(page: &PlayerPage<'_>) -> Result<String, PlayerError> {
    if page.traces.is_empty() {
        return Err(PlayerError::Empty);
    }
    let mut h = String::with_capacity(1 << 16);
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <title>{}</title>\n<style>\n{STYLE}</style>\n</head>\n<body>\n<header>\n<h1>{}</h1>\n",
        escape(&page.title),
        escape(&page.title)
    );
    if let Some(note) = &page.note {
        let _ = writeln!(h, "<p class=\"note\">{}</p>", escape(note));
    }
    h.push_str("</header>\n");
    h.push_str(CONTROLS);
    h.push_str("<div class=\"players\">\n");
    for trace in page.traces {
        section(&mut h, trace)?;
    }
    let _ = write!(h, "</div>\n<script>\n{SCRIPT}</script>\n</body>\n</html>\n");
    Ok(h)
}

/// The controls every player of a page shares.
const CONTROLS: &str = "<div class=\"controls\" id=\"controls\">\n\
<div class=\"row\">\
<button id=\"back\" title=\"step back (left arrow)\">&#9664;&#9646;</button>\
<button id=\"play\" title=\"play or pause (space)\">&#9654;</button>\
<button id=\"forward\" title=\"step forward (right arrow)\">&#9646;&#9654;</button>\
<input id=\"scrub\" type=\"range\" min=\"0\" max=\"0\" value=\"0\" aria-label=\"step\">\
<span id=\"frame\" class=\"frame\">step 0</span>\
</div>\n<div class=\"row\">\
<label>speed <select id=\"speed\"><option value=\"5\">5</option><option value=\"10\">10</option>\
<option value=\"20\" selected>20</option><option value=\"50\">50</option>\
<option value=\"100\">100</option><option value=\"250\">250</option></select> steps/s</label>\
<label>robot <select id=\"robot\"></select></label>\
<label><input id=\"follow\" type=\"checkbox\"> follow (f: next)</label>\
<label><input id=\"laser\" type=\"checkbox\" checked> laser rays</label>\
<label><input id=\"tracks\" type=\"checkbox\" checked> obstacles' tracks</label>\
<label><input id=\"paths\" type=\"checkbox\" checked> robots' paths</label>\
<label><input id=\"goals\" type=\"checkbox\" checked> goals</label>\
<span class=\"absent\" title=\"the step logs do not record the policies' plans\">planned paths: not logged</span>\
</div>\n</div>\n";

/// Appends the section of one player: its title, headline, canvas, panel and data.
fn section(h: &mut String, trace: &Trace) -> Result<(), PlayerError> {
    let b64 = base64::engine::general_purpose::STANDARD;
    let _ = writeln!(
        h,
        "<section class=\"player\">\n<h2>{}</h2>\n<dl class=\"headline\">",
        escape(&trace.title)
    );
    for (key, value) in &trace.headline {
        let _ = write!(
            h,
            "<div><dt>{}</dt><dd>{}</dd></div>",
            escape(key),
            escape(value)
        );
    }
    let (header, blob) = encode(trace);
    let background = background_png(trace)?;
    let _ = write!(
        h,
        "</dl>\n<div class=\"view\"><canvas></canvas><aside class=\"panel\"></aside></div>\n\
         <script type=\"application/json\" class=\"ronap-trace\">{}</script>\n\
         <script type=\"text/plain\" class=\"ronap-blob\">{}</script>\n\
         <script type=\"text/plain\" class=\"ronap-scene\">{}</script>\n</section>\n",
        header.to_string().replace("</", "<\\/"),
        b64.encode(blob),
        b64.encode(background)
    );
    Ok(())
}

/// The still scene as a PNG picture, at most [`BACKGROUND_SIDE_PX`] along its longer side.
fn background_png(trace: &Trace) -> Result<Vec<u8>, image::ImageError> {
    let scene = &trace.scene;
    let side = scene.width().max(scene.height()).max(1.0);
    let scale = (BACKGROUND_SIDE_PX / side).min(4.0);
    crate::render::png_bytes(&crate::render::Canvas::new(scene, scale).into_image())
}

/// The quantum of positions, distances and readings in a scene whose longer side is `side_px`:
/// the finest power of two (at most 1/64 px) that keeps one and a half sides within an i16.
fn position_quantum(side_px: f64) -> f64 {
    let mut q = 1.0 / 64.0;
    while side_px * 1.5 / q > 32_000.0 {
        q *= 2.0;
    }
    q
}

/// A column of the packed numbers: its name, bytes per value and values.
struct Column {
    name: &'static str,
    width: usize,
    bytes: Vec<u8>,
}

impl Column {
    fn new(name: &'static str, width: usize) -> Self {
        Self {
            name,
            width,
            bytes: Vec::new(),
        }
    }

    /// Appends `values` (one series, frame after frame) quantised by `quantum`, each as its
    /// difference from the one before (u16, wrapping).
    fn series(&mut self, values: impl Iterator<Item = f64>, quantum: f64) {
        let mut before: i16 = 0;
        for v in values {
            let q = (v / quantum)
                .round()
                .clamp(f64::from(i16::MIN), f64::from(i16::MAX)) as i16;
            self.bytes
                .extend_from_slice(&q.wrapping_sub(before).to_le_bytes());
            before = q;
        }
    }

    /// Appends `values` of angles, degrees, as [`Column::series`] at 0.01 degree (wrapped to
    /// -180..180 first).
    fn angles(&mut self, values: impl Iterator<Item = f64>) {
        self.series(
            values.map(|d| {
                let w = crate::geometry::wrap_deg(d);
                if w > 180.0 {
                    w - 360.0
                } else {
                    w
                }
            }),
            0.01,
        );
    }

    /// The bytes split into planes: every value's first byte, then every second byte...
    fn planes(&self) -> Vec<u8> {
        let n = self.bytes.len() / self.width;
        (0..self.width)
            .flat_map(|b| (0..n).map(move |i| self.bytes[i * self.width + b]))
            .collect()
    }
}

/// The page data of `trace`: its JSON header and its deflated columns.
fn encode(trace: &Trace) -> (serde_json::Value, Vec<u8>) {
    let scene = &trace.scene;
    // Readings reach as far as the laser does, which may be past the scene's side.
    let reach = trace
        .robots
        .iter()
        .map(|r| r.range_px)
        .fold(scene.width().max(scene.height()), f64::max);
    let q = position_quantum(reach);
    let names = [
        "x",
        "y",
        "z",
        "bearing",
        "distance",
        "direction",
        "readings",
    ];
    let mut cols: Vec<Column> = names.iter().map(|n| Column::new(n, 2)).collect();
    let (mut goal, mut flags) = (Column::new("goal", 1), Column::new("flags", 1));
    let (mut action, mut reward) = (Column::new("action", 2), Column::new("reward", 4));
    let (mut speed, mut turn) = (Column::new("speed", 4), Column::new("turn", 4));
    for r in &trace.robots {
        cols[0].series(r.x.iter().copied(), q);
        cols[1].series(r.y.iter().copied(), q);
        cols[2].angles(r.z_deg.iter().copied());
        cols[3].angles(r.bearing_deg.iter().copied());
        cols[4].series(r.distance_px.iter().copied(), q);
        cols[5].angles(r.direction_deg.iter().copied());
        let beams = r.beam_offsets_deg.len();
        for b in 0..beams {
            cols[6].series(r.readings.iter().skip(b).step_by(beams).copied(), q);
        }
        goal.bytes
            .extend(r.goals_reached.iter().map(|&g| g.min(255) as u8));
        flags.bytes.extend_from_slice(&r.flags);
        for a in &r.action {
            let (code, v, w) = match a {
                None => (u16::MAX, 0.0, 0.0),
                Some(Move::Named(i)) => (*i, 0.0, 0.0),
                Some(Move::Speeds(v, w)) => (u16::MAX - 1, *v, *w),
                Some(Move::Steer(v, steer)) => (u16::MAX - 2, *v, *steer),
            };
            action.bytes.extend_from_slice(&code.to_le_bytes());
            speed.bytes.extend_from_slice(&v.to_le_bytes());
            turn.bytes.extend_from_slice(&w.to_le_bytes());
        }
        for v in &r.reward {
            reward.bytes.extend_from_slice(&v.to_le_bytes());
        }
    }
    cols.extend([goal, flags, action, reward, speed, turn]);
    let (mut mx, mut my, mut mflags) = (
        Column::new("mover_x", 2),
        Column::new("mover_y", 2),
        Column::new("mover_flags", 1),
    );
    let (mut gx, mut gy) = (
        Column::new("mover_goal_x", 2),
        Column::new("mover_goal_y", 2),
    );
    let has_goals = trace
        .movers
        .iter()
        .any(|m| m.goal.iter().any(Option::is_some));
    for m in &trace.movers {
        mx.series(m.x.iter().copied(), q);
        my.series(m.y.iter().copied(), q);
        mflags.bytes.extend(
            m.present
                .iter()
                .zip(&m.goal)
                .map(|(&p, g)| u8::from(p) | (u8::from(g.is_some()) << 1)),
        );
        if has_goals {
            let at = |pick: fn(&Point) -> f64| {
                let mut last = 0.0;
                m.goal
                    .iter()
                    .map(|g| {
                        if let Some(p) = g {
                            last = pick(p);
                        }
                        last
                    })
                    .collect::<Vec<f64>>()
            };
            gx.series(at(|p| p.x).into_iter(), q);
            gy.series(at(|p| p.y).into_iter(), q);
        }
    }
    cols.extend([mx, my, mflags, gx, gy]);
    let mut raw = Vec::new();
    let mut listed = Vec::new();
    for c in &cols {
        raw.extend(c.planes());
        listed.push(serde_json::json!([
            c.name,
            c.width,
            c.bytes.len() / c.width
        ]));
    }
    let round = |v: f64| (v * 1000.0).round() / 1000.0;
    let robots: Vec<serde_json::Value> = trace
        .robots
        .iter()
        .map(|r| {
            let [red, green, blue] = r.colour;
            let mut robot = serde_json::json!({
                "colour": format!("#{red:02x}{green:02x}{blue:02x}"),
                "radius": round(r.radius_px),
                "tolerance": round(r.goal_tolerance_px),
                "goals": r.goals.iter().map(|g| [round(g.x), round(g.y)]).collect::<Vec<_>>(),
                "beams": r.beam_offsets_deg.iter().map(|&d| round(d)).collect::<Vec<_>>(),
                "range": round(r.range_px),
            });
            // A footprint other than a disc: its corners, ahead and left of the robot.
            if !r.outline.is_empty() {
                robot["outline"] = serde_json::json!(r
                    .outline
                    .iter()
                    .map(|&[x, y]| [round(x), round(y)])
                    .collect::<Vec<_>>());
            }
            robot
        })
        .collect();
    let movers: Vec<serde_json::Value> = trace
        .movers
        .iter()
        .map(|m| match m.body {
            Body::Disc(r) => serde_json::json!({ "disc": round(r) }),
            Body::Box(h) => serde_json::json!({ "box": [round(h.x), round(h.y)] }),
        })
        .collect();
    let header = serde_json::json!({
        "title": trace.title,
        "team": trace.team,
        "frames": trace.frames,
        "scene": [round(scene.width()), round(scene.height())],
        "quantum": q,
        "robots": robots,
        "movers": movers,
        "mover_goals": has_goals,
        "actions": trace.actions,
        "columns": listed,
    });
    let packed = miniz_oxide::deflate::compress_to_vec_zlib(&raw, 9);
    (header, packed)
}

/// `s` with the characters HTML gives a meaning escaped.
fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn series_round_trip_through_wrapping_differences() {
        let mut c = Column::new("x", 2);
        let values = [0.0, 12.5, -3.25, 499.984375, 499.984375, 0.015625];
        c.series(values.iter().copied(), 1.0 / 64.0);
        let mut acc: u16 = 0;
        for (i, v) in values.iter().enumerate() {
            let d = u16::from_le_bytes([c.bytes[2 * i], c.bytes[2 * i + 1]]);
            acc = acc.wrapping_add(d);
            assert_eq!(f64::from(acc as i16) / 64.0, *v);
        }
        let planes = c.planes();
        assert_eq!(planes[0], c.bytes[0]);
        assert_eq!(planes[values.len()], c.bytes[1]);
    }

    #[test]
    fn the_quantum_keeps_a_scene_within_sixteen_bits() {
        assert_eq!(position_quantum(300.0), 1.0 / 64.0);
        assert_eq!(position_quantum(1000.0), 1.0 / 16.0);
        for side in [10.0, 700.0, 3000.0, 100_000.0] {
            assert!(side * 1.5 / position_quantum(side) <= 32_000.0);
        }
    }
}
