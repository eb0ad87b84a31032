//! Grouped bars: success rates by bin (difficulty), a bar per policy in each group.

use super::*;

pub(super) const GROUPED_LEFT: i64 = 76;
pub(super) const GROUPED_TOP: i64 = 62;
pub(super) const GROUPED_PLOT_H: i64 = 300;
pub(super) const GROUPED_RIGHT_MARGIN: i64 = 24;
/// Widest plot area of [`grouped_bars`]; past it bars and groups get narrower.
pub(super) const GROUPED_MAX_PLOT_W: i64 = 1300;

/// The plot frame of [`grouped_bars`] for `bins` bins of `series` series.
pub(super) fn grouped_frame(bins: usize, series: usize, label_chars: usize) -> Frame {
    let want_group = (series.max(1) as i64 * 26 + 28).max(label_chars as i64 * 7 + 14);
    let plot_w = (bins.max(1) as i64)
        .saturating_mul(want_group)
        .clamp(520, GROUPED_MAX_PLOT_W);
    Frame {
        left: GROUPED_LEFT,
        top: GROUPED_TOP,
        right: GROUPED_LEFT + plot_w,
        bottom: GROUPED_TOP + GROUPED_PLOT_H,
    }
}

/// Grouped bars: along x one group per bin (labelled with the bin's name, e.g. "ratio 1.0-1.3"),
/// in each group one bar per series (policy) for its success rate with 95% interval whiskers;
/// y 0-100%. A legend under the plot names the series in their colours (`policy_colour`).
/// `title` is the line on top.
///
/// There is a group per bin name, or per value in the longest series if more; a series without a
/// value (or with a non-finite one) in a bin has no bar there.
pub fn grouped_bars(title: &str, bins: &[String], series: &[Series]) -> RgbImage {
    let n_bins = series
        .iter()
        .map(|s| s.values.len())
        .chain([bins.len()])
        .max()
        .unwrap_or(0);
    let n_series = series.len();
    let label_chars = bins
        .iter()
        .map(|b| b.chars().count())
        .max()
        .unwrap_or(0)
        .min(18);
    let frame = grouped_frame(n_bins, n_series, label_chars);
    let width = frame.right + GROUPED_RIGHT_MARGIN;
    let legend: Vec<(Key, String)> = series
        .iter()
        .enumerate()
        .map(|(i, s)| (Key::Square(policy_colour(i)), fit(&s.name, 40)))
        .collect();
    let legend_width = width - frame.left;
    let (_, legend_rows) = legend_layout(legend_width, &legend);
    let legend_top = frame.bottom + 34;
    let height = legend_top + legend_rows * LEGEND_ROW + 10;
    let mut img = canvas(width, height);

    let title = fit(title, Font::Title.chars_in(width - 40));
    text(&mut img, (20, 14), &title, Font::Title, INK, Align::Left);
    frame.axes(&mut img, true, "success rate");
    if n_bins == 0 || n_series == 0 {
        frame.note(&mut img, "no data");
    }
    for b in 0..n_bins {
        let (x, w) = frame.slot(b, n_bins);
        let gap = (w / 5).clamp(2, 28);
        let bar = ((w - gap) / n_series.max(1) as i64).clamp(1, 30);
        let group_x = x + (w - bar * n_series as i64) / 2;
        for (i, s) in series.iter().enumerate() {
            let Some(&(rate, ci)) = s.values.get(b) else {
                continue;
            };
            let bx = group_x + i as i64 * bar;
            if let Some(rate) = unit(rate) {
                let inset = i64::from(bar >= 6);
                let y = frame.y(rate);
                fill_rect(
                    &mut img,
                    bx + inset,
                    y,
                    bx + bar - inset,
                    frame.bottom,
                    policy_colour(i),
                );
                whisker(&mut img, &frame, bx + bar / 2, ci, (bar / 4).clamp(1, 6));
            }
        }
        let label = bins
            .get(b)
            .map_or(String::new(), |l| fit(l, Font::Body.chars_in(w - 2)));
        text(
            &mut img,
            (x + w / 2, frame.bottom + 8),
            &label,
            Font::Body,
            INK,
            Align::Centre,
        );
    }
    draw_legend(&mut img, (frame.left, legend_top), legend_width, &legend);
    img
}
