//! Plot frames and axes: value-to-pixel frames with their grids and ticks, interval whiskers,
//! box-plot statistics, and the x-axis labels and legends that name the policies.

use super::{fill_rect, fit, policy_colour, text, text_up, Align, Font, Key, GRID, INK, MUTED};
use image::{Rgb, RgbImage};

/// A plot area in image pixels, values 0-1 from `bottom` up to `top`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Frame {
    pub(super) left: i64,
    pub(super) top: i64,
    pub(super) right: i64,
    pub(super) bottom: i64,
}

impl Frame {
    /// The row of value `v` (clamped to 0-1).
    pub(super) fn y(&self, v: f64) -> i64 {
        self.bottom - (v.clamp(0.0, 1.0) * (self.bottom - self.top) as f64).round() as i64
    }

    /// Left edge and width of slot `i` of `n` equal slots across the frame.
    pub(super) fn slot(&self, i: usize, n: usize) -> (i64, i64) {
        let (w, n, i) = (self.right - self.left, n.max(1) as i64, i as i64);
        let (a, b) = (self.left + w * i / n, self.left + w * (i + 1) / n);
        (a, b - a)
    }

    /// Grid lines and labelled ticks every 0.2, the axis lines, and `label` up the left side.
    pub(super) fn axes(&self, img: &mut RgbImage, percent: bool, label: &str) {
        let mut widest = 0;
        for k in 0..=5 {
            let v = f64::from(k) / 5.0;
            let y = self.y(v);
            if k > 0 {
                fill_rect(img, self.left + 1, y, self.right, y + 1, GRID);
            }
            fill_rect(img, self.left - 4, y, self.left, y + 1, INK);
            let tick = if percent {
                format!("{}%", k * 20)
            } else {
                format!("{v:.1}")
            };
            widest = widest.max(Font::Body.width(&tick));
            let at = (self.left - 7, y - Font::Body.height() / 2);
            text(img, at, &tick, Font::Body, MUTED, Align::Right);
        }
        fill_rect(
            img,
            self.left,
            self.top,
            self.left + 1,
            self.bottom + 1,
            INK,
        );
        fill_rect(
            img,
            self.left,
            self.bottom,
            self.right,
            self.bottom + 1,
            INK,
        );
        let x = self.left - 7 - widest - 6 - Font::Body.height();
        let label = fit(label, Font::Body.chars_in(self.bottom - self.top));
        text_up(
            img,
            x,
            (self.top + self.bottom) / 2,
            &label,
            Font::Body,
            INK,
        );
    }

    /// "no policies" (or another note) in the middle of the frame.
    pub(super) fn note(&self, img: &mut RgbImage, note: &str) {
        let mid = (
            (self.left + self.right) / 2,
            (self.top + self.bottom) / 2 - 8,
        );
        let note = fit(note, Font::Body.chars_in(self.right - self.left));
        text(img, mid, &note, Font::Body, MUTED, Align::Centre);
    }
}

/// `v` if finite, clamped to 0-1.
pub(super) fn unit(v: f64) -> Option<f64> {
    v.is_finite().then(|| v.clamp(0.0, 1.0))
}

/// A 2 px interval whisker at column `cx` from `ci[0]` to `ci[1]`, with caps `cap` px either side.
pub(super) fn whisker(img: &mut RgbImage, frame: &Frame, cx: i64, ci: [f64; 2], cap: i64) {
    let (Some(a), Some(b)) = (unit(ci[0]), unit(ci[1])) else {
        return;
    };
    let (ya, yb) = (frame.y(a.min(b)), frame.y(a.max(b)));
    fill_rect(img, cx - 1, yb, cx + 1, ya + 1, INK);
    for y in [ya, yb] {
        fill_rect(img, cx - cap, y - 1, cx + cap + 1, y + 1, INK);
    }
}

/// Quartiles and Tukey whiskers of sorted values.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct BoxStats {
    pub(super) low: f64,
    pub(super) q1: f64,
    pub(super) median: f64,
    pub(super) q3: f64,
    pub(super) high: f64,
    pub(super) outliers: Vec<f64>,
}

/// The value at quantile `q` of `sorted` (non-empty), interpolated linearly between ranks.
fn quantile(sorted: &[f64], q: f64) -> f64 {
    let pos = q * (sorted.len() - 1) as f64;
    let (i, frac) = (pos.floor() as usize, pos - pos.floor());
    match sorted.get(i + 1) {
        Some(next) => sorted[i] + (next - sorted[i]) * frac,
        None => sorted[i],
    }
}

/// Median, quartiles, whiskers at the furthest values within 1.5 IQR of the box, and the values
/// beyond them; `None` for no values.
pub(super) fn box_stats(sorted: &[f64]) -> Option<BoxStats> {
    if sorted.is_empty() {
        return None;
    }
    let (q1, median, q3) = (
        quantile(sorted, 0.25),
        quantile(sorted, 0.5),
        quantile(sorted, 0.75),
    );
    let reach = 1.5 * (q3 - q1);
    let inside = |v: &&f64| **v >= q1 - reach && **v <= q3 + reach;
    let low = sorted.iter().find(inside).copied().unwrap_or(q1);
    let high = sorted.iter().rev().find(inside).copied().unwrap_or(q3);
    let outliers = sorted.iter().filter(|v| !inside(v)).copied().collect();
    Some(BoxStats {
        low,
        q1,
        median,
        q3,
        high,
        outliers,
    })
}

/// How the x-axis labels of [`slot_labels`] name the policies.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Naming {
    /// Every name in full: no legend needed.
    Full,
    /// Some names cut to fit: a legend gives them in full.
    Cut,
    /// Too narrow for names: the labels are 1, 2, ... and a legend says which is which.
    Numbered,
}

/// The x-axis labels of `names` for slots `slot_px` wide: the names, cut to fit if need be; or,
/// when names would be cut to fewer than 8 characters (too short to tell apart), the numbers
/// 1, 2, ...
pub(super) fn slot_labels<'a>(
    names: impl Iterator<Item = &'a str>,
    slot_px: i64,
) -> (Vec<String>, Naming) {
    let names: Vec<&str> = names.collect();
    let room = Font::Body.chars_in(slot_px - 4);
    let fitted: Vec<String> = names.iter().map(|n| fit(n, room)).collect();
    let cut = fitted.iter().zip(&names).any(|(f, n)| f != n);
    if cut && room < 8 {
        let numbers = (1..=names.len())
            .map(|i| fit(&i.to_string(), room))
            .collect();
        return (numbers, Naming::Numbered);
    }
    (fitted, if cut { Naming::Cut } else { Naming::Full })
}

/// The first of `choices` that fits in `px` pixels, or the last one cut to fit.
pub(super) fn first_fitting(choices: &[String], px: i64) -> String {
    let room = Font::Body.chars_in(px);
    choices
        .iter()
        .find(|c| c.len() <= room)
        .or(choices.last())
        .map_or(String::new(), |c| fit(c, room))
}

/// Legend entries naming each policy in its colour (empty when the labels name them in full).
pub(super) fn policy_legend<'a>(
    names: impl Iterator<Item = &'a str>,
    naming: Naming,
) -> Vec<(Key, String)> {
    if naming == Naming::Full {
        return Vec::new();
    }
    names
        .enumerate()
        .map(|(i, name)| {
            let label = match naming {
                Naming::Numbered => format!("{} {}", i + 1, fit(name, 40)),
                _ => fit(name, 40),
            };
            (Key::Square(policy_colour(i)), label)
        })
        .collect()
}

/// A policy's colour darkened for text on white.
pub(super) fn policy_colour_dark(index: usize) -> Rgb<u8> {
    let c = policy_colour(index);
    Rgb(c.0.map(|v| (f64::from(v) * 0.7).round() as u8))
}
