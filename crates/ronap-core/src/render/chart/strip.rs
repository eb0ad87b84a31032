//! The per-seed outcome strip: a cell per seed and policy in its outcome colour, the seeds where
//! the policies disagree marked.

use super::*;

pub(super) const STRIP_MARGIN: i64 = 12;
/// Seed columns a band holds at most, in pixels.
pub(super) const STRIP_BAND_PX: i64 = 1200;
pub(super) const STRIP_HEADER: i64 = 20;
pub(super) const STRIP_ROW: i64 = 16;
pub(super) const STRIP_ROW_GAP: i64 = 3;
/// The disagreement row's slot; its mark is the `4..12` px of it.
pub(super) const STRIP_DISAGREE: i64 = 16;
pub(super) const STRIP_BAND_GAP: i64 = 14;

/// Where everything of an outcome strip goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct StripLayout {
    /// Width of one seed's column: 4 px for up to 300 seeds, down to 1 px.
    cell_w: i64,
    /// Seed columns per band.
    per_band: usize,
    /// Bands of seeds, one under the other.
    bands: usize,
    /// Policy rows.
    rows: usize,
    /// Width of the name column.
    label_w: i64,
    /// Image width.
    width: i64,
}

impl StripLayout {
    pub(super) fn new(seeds: usize, rows: usize, label_chars: usize) -> Self {
        let cell_w = match seeds {
            0..=300 => 4,
            301..=400 => 3,
            401..=600 => 2,
            _ => 1,
        };
        let per_band = (STRIP_BAND_PX / cell_w) as usize;
        let bands = seeds.div_ceil(per_band);
        let label_w = label_chars as i64 * Font::Body.advance() + 12;
        let columns = seeds.min(per_band) as i64;
        let width = (2 * STRIP_MARGIN + label_w + columns * cell_w).max(560);
        Self {
            cell_w,
            per_band,
            bands,
            rows,
            label_w,
            width,
        }
    }

    pub(super) fn band_h(&self) -> i64 {
        STRIP_HEADER
            + self.rows as i64 * (STRIP_ROW + STRIP_ROW_GAP)
            + STRIP_DISAGREE
            + STRIP_BAND_GAP
    }

    pub(super) fn band_top(&self, band: usize) -> i64 {
        STRIP_MARGIN + band as i64 * self.band_h()
    }

    /// Left edge of seed column `s`, and the top of its band.
    pub(super) fn column(&self, s: usize) -> (i64, i64) {
        let (band, col) = (s / self.per_band, (s % self.per_band) as i64);
        (
            STRIP_MARGIN + self.label_w + col * self.cell_w,
            self.band_top(band),
        )
    }

    /// Top-left of the cell of policy `p` at seed `s`.
    pub(super) fn cell(&self, p: usize, s: usize) -> (i64, i64) {
        let (x, top) = self.column(s);
        (
            x,
            top + STRIP_HEADER + p as i64 * (STRIP_ROW + STRIP_ROW_GAP),
        )
    }

    /// Top of the disagreement row's slot at seed `s`.
    pub(super) fn disagree(&self, s: usize) -> (i64, i64) {
        let (x, top) = self.column(s);
        (
            x,
            top + STRIP_HEADER + self.rows as i64 * (STRIP_ROW + STRIP_ROW_GAP),
        )
    }

    /// Top of the legend.
    pub(super) fn legend_top(&self) -> i64 {
        STRIP_MARGIN + (self.bands.max(1) as i64) * self.band_h()
    }
}

/// Seed columns from one tick over the strip to the next: the first of 10, 20, 25, 50, ... that
/// puts the ticks at least 90 px apart.
pub(super) fn strip_tick_step(cell_w: i64) -> usize {
    [10, 20, 25, 50, 100, 200, 250, 500]
        .into_iter()
        .find(|&step| step as i64 * cell_w >= 90)
        .unwrap_or(1000)
}

/// Whether the policies with an outcome at seed `s` differ in success (at least one succeeded and
/// at least one failed).
pub(super) fn disagrees(outcomes: &[Vec<Outcome>], s: usize) -> bool {
    let mut seen = outcomes.iter().filter_map(|row| row.get(s));
    let Some(first) = seen.next() else {
        return false;
    };
    let won = *first == Outcome::Success;
    seen.any(|o| (*o == Outcome::Success) != won)
}

/// The per-seed outcome strip: one row per policy, its name on the left, and one column per seed
/// in the order given, coloured by outcome (`outcome_colour`; a missing outcome is light grey).
/// Columns are 4 px wide for up to 300 seeds, down to 1 px; past 1200 px the seeds wrap into
/// bands, one under the other, each headed by its first and last seed. Under each band's policy
/// rows a thin row is dark at the seeds where the policies disagree (some succeeded, some did
/// not). A legend of the outcomes closes the picture.
///
/// `outcomes[p][s]` is policy `p`'s outcome at `seeds[s]`; there is one row per name (or per
/// outcome list, if there are more of those) and one column per seed; outcomes past the last seed
/// are ignored.
pub fn outcome_strip(names: &[String], seeds: &[u64], outcomes: &[Vec<Outcome>]) -> RgbImage {
    let rows = names.len().max(outcomes.len());
    let row_names: Vec<String> = (0..rows)
        .map(|p| match names.get(p) {
            Some(name) => fit(name, 24),
            None => format!("policy {}", p + 1),
        })
        .collect();
    let label_chars = row_names
        .iter()
        .map(|n| n.len())
        .chain([8])
        .max()
        .unwrap_or(8);
    let layout = StripLayout::new(seeds.len(), rows, label_chars);
    // Infeasible tasks are keyed only where some are shown.
    let infeasible = outcomes.iter().flatten().any(|o| *o == Outcome::Infeasible);
    let mut legend: Vec<(Key, String)> = Outcome::ALL
        .iter()
        .filter(|&&o| o != Outcome::Infeasible || infeasible)
        .map(|&o| (Key::Square(outcome_colour(o)), o.name().to_owned()))
        .collect();
    legend.push((Key::Thin(DISAGREE), "policies disagree".to_owned()));
    let legend_width = layout.width - 2 * STRIP_MARGIN;
    let (_, legend_rows) = legend_layout(legend_width, &legend);
    let height = layout.legend_top() + legend_rows * LEGEND_ROW + STRIP_MARGIN;
    let mut img = canvas(layout.width, height);

    if seeds.is_empty() {
        let at = (STRIP_MARGIN, STRIP_MARGIN);
        text(&mut img, at, "no seeds", Font::Body, MUTED, Align::Left);
    }
    for band in 0..layout.bands {
        let first = band * layout.per_band;
        let last = (first + layout.per_band).min(seeds.len()) - 1;
        let (x0, top) = layout.column(first);
        let x1 = layout.column(last).0 + layout.cell_w;
        text(
            &mut img,
            (STRIP_MARGIN, top),
            "seeds",
            Font::Body,
            MUTED,
            Align::Left,
        );
        let (a, b) = (seeds[first].to_string(), seeds[last].to_string());
        if Font::Body.width(&a) + Font::Body.width(&b) + 14 <= x1 - x0 {
            text(&mut img, (x0, top), &a, Font::Body, MUTED, Align::Left);
            text(&mut img, (x1, top), &b, Font::Body, MUTED, Align::Right);
            // Ticks every few seeds, labelled with their seed where the label has room.
            let step = strip_tick_step(layout.cell_w);
            let free = (
                x0 + Font::Body.width(&a) + 12,
                x1 - Font::Body.width(&b) - 12,
            );
            for col in (0..=last - first).step_by(step).chain([last - first]) {
                let x = layout.column(first + col).0 + layout.cell_w / 2;
                fill_rect(&mut img, x, top + 16, x + 1, top + STRIP_HEADER - 1, MUTED);
                let label = seeds[first + col].to_string();
                let half = Font::Body.width(&label) / 2;
                if col > 0 && x - half >= free.0 && x + half <= free.1 {
                    text(&mut img, (x, top), &label, Font::Body, MUTED, Align::Centre);
                }
            }
        } else {
            let both = fit(&format!("{a}-{b}"), Font::Body.chars_in(x1 - x0).max(1));
            text(&mut img, (x0, top), &both, Font::Body, MUTED, Align::Left);
        }
        for (p, name) in row_names.iter().enumerate() {
            let y = layout.cell(p, first).1;
            text(
                &mut img,
                (STRIP_MARGIN, y),
                name,
                Font::Body,
                INK,
                Align::Left,
            );
        }
        let y = layout.disagree(first).1;
        text(
            &mut img,
            (STRIP_MARGIN, y),
            "disagree",
            Font::Body,
            MUTED,
            Align::Left,
        );
    }
    for s in 0..seeds.len() {
        for p in 0..rows {
            let colour = outcomes
                .get(p)
                .and_then(|row| row.get(s))
                .map_or(NO_DATA, |&o| outcome_colour(o));
            let (x, y) = layout.cell(p, s);
            fill_rect(&mut img, x, y, x + layout.cell_w, y + STRIP_ROW, colour);
        }
        let colour = if disagrees(outcomes, s) {
            DISAGREE
        } else {
            NO_DATA
        };
        let (x, y) = layout.disagree(s);
        fill_rect(&mut img, x, y + 4, x + layout.cell_w, y + 12, colour);
    }
    let at = (STRIP_MARGIN, layout.legend_top());
    draw_legend(&mut img, at, legend_width, &legend);
    img
}
