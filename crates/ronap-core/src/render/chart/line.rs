//! Line charts of training curves: panels stacked top to bottom over one x axis, each line in its
//! policy colour, with readable tick values.

use super::{
    canvas, draw_legend, fill_rect, fit, legend_layout, policy_colour, text, text_up, Align, Font,
    Key, GRID, INK, LEGEND_ROW, MUTED,
};
use image::{Rgb, RgbImage};

/// One line of a [`line_chart`] panel: a name for the legend and its `(x, y)` points in x order.
/// Points with a value that is not finite are skipped, leaving a gap.
#[derive(Clone, Debug, PartialEq)]
pub struct Line {
    /// The legend's name.
    pub name: String,
    /// The points, in x order.
    pub points: Vec<(f64, f64)>,
}

/// One panel of a [`line_chart`].
#[derive(Clone, Debug, PartialEq)]
pub struct Panel {
    /// The y axis label.
    pub y_label: String,
    /// A fixed y range (`(0, 1)` draws percentages); `None` fits the data.
    pub y_range: Option<(f64, f64)>,
    /// The lines, each in [`policy_colour`] of its index.
    pub lines: Vec<Line>,
}

const WIDTH: i64 = 900;
const LEFT: i64 = 96;
const RIGHT_MARGIN: i64 = 30;
const PLOT_H: i64 = 200;
const TITLE_H: i64 = 44;
const X_AXIS_H: i64 = 46;

/// `panels` stacked top to bottom over one x axis labelled `x_label`, under `title`.
///
/// The x axis spans the finite x values of every panel. A panel with `y_range: None` spans its
/// finite y values with a margin of 5% each side; ticks fall on round values inside the range.
/// No panels, or a panel without a finite point, draws an empty plot that says "no data".
pub fn line_chart(title: &str, x_label: &str, panels: &[Panel]) -> RgbImage {
    let nothing = [Panel {
        y_label: String::new(),
        y_range: None,
        lines: Vec::new(),
    }];
    let panels = if panels.is_empty() { &nothing } else { panels };
    let finite = |p: &&(f64, f64)| p.0.is_finite() && p.1.is_finite();
    let xs: Vec<f64> = panels
        .iter()
        .flat_map(|p| &p.lines)
        .flat_map(|l| l.points.iter().filter(finite))
        .map(|p| p.0)
        .collect();
    let (x_lo, x_hi) = span(&xs).unwrap_or((0.0, 1.0));
    let x_ticks = ticks(x_lo, x_hi, 6);
    let plot_w = WIDTH - LEFT - RIGHT_MARGIN;
    let legends: Vec<Vec<(Key, String)>> = panels
        .iter()
        .map(|p| {
            p.lines
                .iter()
                .enumerate()
                .map(|(i, l)| (Key::Square(policy_colour(i)), fit(&l.name, 40)))
                .collect()
        })
        .collect();
    let legend_rows: Vec<i64> = legends.iter().map(|l| legend_layout(plot_w, l).1).collect();
    let height = TITLE_H
        + legend_rows
            .iter()
            .map(|r| r * LEGEND_ROW + PLOT_H + 16)
            .sum::<i64>()
        + X_AXIS_H;
    let mut img = canvas(WIDTH, height);
    let title = fit(title, Font::Title.chars_in(WIDTH - 40));
    text(&mut img, (20, 12), &title, Font::Title, INK, Align::Left);
    let x_px = |x: f64| LEFT + (along(x, x_lo, x_hi) * plot_w as f64).round() as i64;
    let mut top = TITLE_H;
    for ((panel, legend), rows) in panels.iter().zip(&legends).zip(&legend_rows) {
        draw_legend(&mut img, (LEFT, top), plot_w, legend);
        top += rows * LEGEND_ROW;
        let bottom = top + PLOT_H;
        let ys: Vec<f64> = panel
            .lines
            .iter()
            .flat_map(|l| l.points.iter().filter(finite))
            .map(|p| p.1)
            .collect();
        let percent = panel.y_range == Some((0.0, 1.0));
        let (y_lo, y_hi) = match panel.y_range {
            Some((a, b)) if a.is_finite() && b.is_finite() && b > a => (a, b),
            _ => span(&ys).map_or((0.0, 1.0), |(lo, hi)| {
                let pad = (hi / 2.0 - lo / 2.0) * 0.1;
                ((lo - pad).max(f64::MIN), (hi + pad).min(f64::MAX))
            }),
        };
        let y_ticks = ticks(y_lo, y_hi, if percent { 4 } else { 5 });
        let y_px = |y: f64| bottom - (along(y, y_lo, y_hi) * PLOT_H as f64).round() as i64;
        // Grid, ticks and axes.
        let mut widest = 0;
        for &t in &y_ticks {
            let y = y_px(t);
            fill_rect(&mut img, LEFT + 1, y, LEFT + plot_w, y + 1, GRID);
            fill_rect(&mut img, LEFT - 4, y, LEFT, y + 1, INK);
            let label = if percent {
                format!("{}%", round_sig(t * 100.0))
            } else {
                fit(&tick_label(t), TICK_CHARS)
            };
            widest = widest.max(Font::Body.width(&label));
            let at = (LEFT - 7, y - Font::Body.height() / 2);
            text(&mut img, at, &label, Font::Body, MUTED, Align::Right);
        }
        for &t in &x_ticks {
            let x = x_px(t);
            fill_rect(&mut img, x, top, x + 1, bottom, GRID);
        }
        fill_rect(&mut img, LEFT, top, LEFT + 1, bottom + 1, INK);
        fill_rect(&mut img, LEFT, bottom, LEFT + plot_w, bottom + 1, INK);
        let label = fit(&panel.y_label, Font::Body.chars_in(PLOT_H));
        let x = (LEFT - 7 - widest - 6 - Font::Body.height()).max(2);
        text_up(&mut img, x, (top + bottom) / 2, &label, Font::Body, INK);
        if ys.is_empty() {
            let mid = (LEFT + plot_w / 2, (top + bottom) / 2 - 8);
            text(&mut img, mid, "no data", Font::Body, MUTED, Align::Centre);
        }
        // The lines, the first drawn last (on top).
        for (i, line) in panel.lines.iter().enumerate().rev() {
            let colour = policy_colour(i);
            let mut last: Option<(i64, i64)> = None;
            for &(x, y) in &line.points {
                if !(x.is_finite() && y.is_finite()) {
                    last = None;
                    continue;
                }
                let p = (x_px(x), y_px(y.clamp(y_lo, y_hi)));
                match last {
                    Some(a) => segment(&mut img, a, p, colour),
                    None => segment(&mut img, p, p, colour),
                }
                last = Some(p);
            }
        }
        top = bottom + 16;
    }
    // The shared x axis.
    let bottom = top - 16;
    for &t in &x_ticks {
        let x = x_px(t);
        fill_rect(&mut img, x, bottom, x + 1, bottom + 5, INK);
        text(
            &mut img,
            (x, bottom + 8),
            &fit(&tick_label(t), TICK_CHARS),
            Font::Body,
            MUTED,
            Align::Centre,
        );
    }
    let label = fit(x_label, Font::Body.chars_in(plot_w));
    text(
        &mut img,
        (LEFT + plot_w / 2, bottom + 26),
        &label,
        Font::Body,
        INK,
        Align::Centre,
    );
    img
}

/// The most characters of a tick label (longer ones are cut, ending in "..").
const TICK_CHARS: usize = 9;

/// Where `v` is from `lo` (0) to `hi` (1), without overflow however far apart they are.
fn along(v: f64, lo: f64, hi: f64) -> f64 {
    let width = hi / 2.0 - lo / 2.0;
    if width > 0.0 {
        (v / 2.0 - lo / 2.0) / width
    } else {
        0.5
    }
}

/// The least and greatest of `values`, apart when they are equal; `None` for none.
fn span(values: &[f64]) -> Option<(f64, f64)> {
    let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if !(lo.is_finite() && hi.is_finite()) {
        return None;
    }
    if hi - lo < 1e-12 * lo.abs().max(1.0) {
        let pad = (lo.abs() * 0.1).max(1.0);
        return Some(((lo - pad).max(f64::MIN), (hi + pad).min(f64::MAX)));
    }
    Some((lo, hi))
}

/// Round tick values (1, 2, 2.5 or 5 times a power of ten apart) inside `lo..=hi`, about `n`
/// steps apart.
fn ticks(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    let raw = (hi / 2.0 - lo / 2.0) / n.max(1) as f64 * 2.0;
    if !(raw.is_finite() && raw > 0.0) {
        return Vec::new();
    }
    let power = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 2.5, 5.0, 10.0]
        .iter()
        .map(|m| m * power)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * power);
    // A tick a hair outside the range (from rounding) still counts.
    let first = (lo / step - 1e-9).ceil() as i64;
    let last = (hi / step + 1e-9).floor() as i64;
    (first..=last.min(first.saturating_add(50)))
        .map(|k| k as f64 * step)
        .filter(|t| t.is_finite())
        .collect()
}

/// `v` to 9 significant digits, so a tick of `3 * 0.1` reads 0.3.
fn round_sig(v: f64) -> f64 {
    let r = format!("{v:.8e}").parse().unwrap_or(v);
    // No "-0".
    if r == 0.0 {
        0.0
    } else {
        r
    }
}

/// A tick value as people write it: 40, 2.5, 0.025, 250k, 1.5M, and past a billion or under a
/// thousandth 2.5e9, 1e-4.
fn tick_label(v: f64) -> String {
    let v = round_sig(v);
    let a = v.abs();
    if a >= 1e9 || (a > 0.0 && a < 1e-3) {
        format!("{v:e}")
    } else if a >= 1e6 {
        format!("{}M", round_sig(v / 1e6))
    } else if a >= 1e4 {
        format!("{}k", round_sig(v / 1e3))
    } else {
        format!("{v}")
    }
}

/// A 2 px line from `a` to `b`.
fn segment(img: &mut RgbImage, a: (i64, i64), b: (i64, i64), colour: Rgb<u8>) {
    let steps = (b.0 - a.0).abs().max((b.1 - a.1).abs()).max(1);
    for s in 0..=steps {
        let x = a.0 + (b.0 - a.0) * s / steps;
        let y = a.1 + (b.1 - a.1) * s / steps;
        fill_rect(img, x, y, x + 2, y + 2, colour);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rising() -> Panel {
        Panel {
            y_label: "mean return".into(),
            y_range: None,
            lines: vec![Line {
                name: "mean return".into(),
                points: (0..50)
                    .map(|i| (i as f64 * 40_000.0, i as f64 * 3.0 + (i as f64).sin()))
                    .collect(),
            }],
        }
    }

    #[test]
    fn tick_labels_read_as_people_write_them() {
        assert_eq!(tick_label(250_000.0), "250k");
        assert_eq!(tick_label(1_500_000.0), "1.5M");
        assert_eq!(tick_label(2_000_000.0), "2M");
        assert_eq!(tick_label(40.0), "40");
        assert_eq!(tick_label(2.5), "2.5");
        assert_eq!(tick_label(0.025), "0.025");
        assert_eq!(tick_label(3.0 * 0.1), "0.3");
        assert_eq!(tick_label(-1e-4), "-1e-4");
        assert_eq!(tick_label(2.5e13), "2.5e13");
        assert_eq!(tick_label(-0.0), "0");
        assert_eq!(
            ticks(-201.0, 266.0, 5),
            vec![-200.0, -100.0, 0.0, 100.0, 200.0]
        );
        assert_eq!(ticks(0.0, f64::MAX, 6), vec![0.0, 5e307, 1e308, 1.5e308]);
        assert_eq!(
            ticks(0.0, 2_000_000.0, 6),
            vec![0.0, 500_000.0, 1e6, 1.5e6, 2e6]
        );
    }

    #[test]
    fn a_rising_line_ends_higher_than_it_starts() {
        let img = line_chart("t", "steps", &[rising()]);
        assert_eq!(img.width(), WIDTH as u32);
        let colour = policy_colour(0);
        let rows_in = |x0: u32, x1: u32| {
            let mut ys = Vec::new();
            for x in x0..x1 {
                for y in 0..img.height() {
                    // Legend squares sit above the plot.
                    if *img.get_pixel(x, y) == colour && i64::from(y) > TITLE_H + LEGEND_ROW {
                        ys.push(y);
                    }
                }
            }
            ys.iter().sum::<u32>() as f64 / ys.len().max(1) as f64
        };
        let left = rows_in(LEFT as u32 + 2, LEFT as u32 + 20);
        let right = rows_in(
            (WIDTH - RIGHT_MARGIN - 20) as u32,
            (WIDTH - RIGHT_MARGIN) as u32,
        );
        assert!(right < left - 50.0, "{left} {right}");
    }

    #[test]
    fn panels_stack_and_odd_data_still_draws() {
        let one = line_chart("t", "steps", &[rising()]);
        let rate = Panel {
            y_label: "success".into(),
            y_range: Some((0.0, 1.0)),
            lines: vec![Line {
                name: "success".into(),
                points: vec![
                    (0.0, f64::NAN),
                    (1.0, 0.5),
                    (2.0, f64::INFINITY),
                    (3.0, 2.0),
                ],
            }],
        };
        let two = line_chart("t", "steps", &[rising(), rate]);
        assert_eq!(two.width(), one.width());
        assert!(two.height() > one.height() + PLOT_H as u32);
        for panels in [
            vec![],
            vec![Panel {
                y_label: "nothing".into(),
                y_range: None,
                lines: vec![Line {
                    name: "nan".into(),
                    points: vec![(f64::NAN, 1.0), (1.0, f64::NAN)],
                }],
            }],
            vec![Panel {
                y_label: "flat".into(),
                y_range: None,
                lines: vec![Line {
                    name: "one point".into(),
                    points: vec![(5.0, 1e300)],
                }],
            }],
        ] {
            let img = line_chart("odd", "x", &panels);
            assert!(img.width() > 0 && img.height() > 0);
        }
        // Points as far apart as floats go still draw a line, not a dot in the corner.
        let far = Panel {
            y_label: "far".into(),
            y_range: None,
            lines: vec![Line {
                name: "far".into(),
                points: vec![(0.0, -1e300), (1e300, 1e300), (f64::MAX, f64::MAX)],
            }],
        };
        let img = line_chart("far", "x", &[far]);
        let top = (TITLE_H + LEGEND_ROW) as u32;
        let drawn = img
            .enumerate_pixels()
            .filter(|(_, y, p)| *y > top && **p == policy_colour(0))
            .count();
        assert!(drawn > 400, "{drawn} pixels of the line");
        // No panels at all: one empty plot that says so, under the title.
        let none = line_chart("none", "x", &[]);
        let empty = Panel {
            y_label: String::new(),
            y_range: None,
            lines: vec![],
        };
        assert_eq!(none, line_chart("none", "x", &[empty]));
        assert_eq!(none.height() as i64, TITLE_H + PLOT_H + 16 + X_AXIS_H);
    }
}
