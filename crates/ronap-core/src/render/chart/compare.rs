//! The comparison chart (`compare.png`): success rate with its 95% interval and the SPL of the
//! successful episodes, a panel each, one slot per policy.

use super::*;

pub(super) const COMPARE_W: i64 = 1000;
pub(super) const COMPARE_H: i64 = 450;

/// The two panels of [`compare_chart`]: success rate on the left, SPL on the right.
pub(super) fn compare_frames() -> (Frame, Frame) {
    let left = Frame {
        left: 76,
        top: 86,
        right: 478,
        bottom: COMPARE_H - 64,
    };
    let right = Frame {
        left: 590,
        top: 86,
        right: COMPARE_W - 20,
        bottom: COMPARE_H - 64,
    };
    (left, right)
}

/// The comparison chart, about 1000 x 450 px: a title line, then on the left each policy's
/// success rate as a bar with its 95% interval whiskers (y 0-100%), and on the right each
/// policy's SPL over its successful episodes as a box plot (median, quartiles, whiskers to the
/// furthest values within 1.5 IQR, dots beyond) with a diamond at the mean SPL over all episodes
/// (y 0-1). Under each bar and box: the policy's name and its success rate or mean SPL. Each
/// policy has its own colour (`policy_colour`), the same in both panels; when names had to be
/// cut or numbered to fit, a legend underneath gives them in full.
///
/// `title` is the line on top, e.g. "success = reached the goal within 10 px, 1000 seeds".
pub fn compare_chart(title: &str, policies: &[PolicyBars]) -> RgbImage {
    let (left, right) = compare_frames();
    let n = policies.len();
    let slot_px = left.slot(0, n).1.min(right.slot(0, n).1);
    let names = || policies.iter().map(|p| p.name.as_str());
    let (labels, naming) = slot_labels(names(), slot_px);
    let legend = policy_legend(names(), naming);
    let legend_width = COMPARE_W - 2 * 24;
    let (_, legend_rows) = legend_layout(legend_width, &legend);
    let height = COMPARE_H + legend_rows * LEGEND_ROW;
    let mut img = canvas(COMPARE_W, height);

    let title = fit(title, Font::Title.chars_in(COMPARE_W - 2 * 20));
    text(&mut img, (20, 14), &title, Font::Title, INK, Align::Left);

    // Panel headers, with the key of the SPL markers on the right.
    let header_y = 50;
    text(
        &mut img,
        (left.left, header_y),
        "Success rate, 95% interval",
        Font::Bold,
        INK,
        Align::Left,
    );
    text(
        &mut img,
        (right.left, header_y),
        "SPL of successful episodes",
        Font::Bold,
        INK,
        Align::Left,
    );
    let key = "mean, all episodes";
    let key_x = right.right - Font::Body.width(key);
    fill_diamond(&mut img, key_x - 12, header_y + 8, 5, INK);
    text(
        &mut img,
        (key_x, header_y),
        key,
        Font::Body,
        MUTED,
        Align::Left,
    );

    left.axes(&mut img, true, "success rate");
    right.axes(&mut img, false, "SPL");
    if n == 0 {
        left.note(&mut img, "no policies");
        right.note(&mut img, "no policies");
    }

    for (i, (p, label)) in policies.iter().zip(&labels).enumerate() {
        success_bar(&mut img, &left, (i, n), p, label);
        spl_box(&mut img, &right, (i, n), p, label);
    }
    draw_legend(&mut img, (24, COMPARE_H - 4), legend_width, &legend);
    img
}

/// Under slot `x..x + w` of `frame`: the policy's `label` and, greyed, its `value`.
pub(super) fn slot_caption(
    img: &mut RgbImage,
    frame: &Frame,
    (x, w): (i64, i64),
    label: &str,
    value: &str,
) {
    let (cx, y) = (x + w / 2, frame.bottom + 8);
    text(img, (cx, y), label, Font::Body, INK, Align::Centre);
    text(img, (cx, y + 18), value, Font::Body, MUTED, Align::Centre);
}

/// Policy `i` of `n`'s success-rate bar, whiskers and caption in the left panel of
/// [`compare_chart`].
pub(super) fn success_bar(
    img: &mut RgbImage,
    frame: &Frame,
    (i, n): (usize, usize),
    p: &PolicyBars,
    label: &str,
) {
    let (x, w) = frame.slot(i, n);
    let cx = x + w / 2;
    let bar = ((w as f64 * 0.55).round() as i64).clamp(3, 70);
    let rate = unit(p.success_rate);
    if let Some(rate) = rate {
        let x0 = cx - bar / 2;
        fill_rect(
            img,
            x0,
            frame.y(rate),
            x0 + bar,
            frame.bottom,
            policy_colour(i),
        );
    }
    whisker(img, frame, cx, p.success_ci95, (bar / 4).clamp(2, 10));
    let value = match rate {
        Some(r) => first_fitting(
            &[format!("{:.1}%", r * 100.0), format!("{:.0}", r * 100.0)],
            w,
        ),
        None => first_fitting(&["n/a".to_owned()], w),
    };
    slot_caption(img, frame, (x, w), label, &value);
}

/// Policy `i` of `n`'s SPL box over its successes, the diamond at its mean SPL over all episodes
/// and its caption in the right panel of [`compare_chart`].
pub(super) fn spl_box(
    img: &mut RgbImage,
    frame: &Frame,
    (i, n): (usize, usize),
    p: &PolicyBars,
    label: &str,
) {
    let colour = policy_colour(i);
    let (x, w) = frame.slot(i, n);
    let cx = x + w / 2;
    let all: Vec<f64> = p.spl.iter().copied().filter(|v| v.is_finite()).collect();
    let mut wins: Vec<f64> = all
        .iter()
        .filter(|&&v| v > 0.0)
        .map(|v| v.min(1.0))
        .collect();
    wins.sort_by(f64::total_cmp);
    if let Some(b) = box_stats(&wins) {
        let bw = ((w as f64 * 0.5).round() as i64).clamp(3, 64);
        let cap = (bw / 4).clamp(2, 10);
        let (y_low, y_q1, y_q3, y_high) = (
            frame.y(b.low),
            frame.y(b.q1),
            frame.y(b.q3),
            frame.y(b.high),
        );
        fill_rect(img, cx, y_high, cx + 1, y_q3, INK);
        fill_rect(img, cx, y_q1, cx + 1, y_low + 1, INK);
        fill_rect(img, cx - cap, y_high, cx + cap + 1, y_high + 1, INK);
        fill_rect(img, cx - cap, y_low, cx + cap + 1, y_low + 1, INK);
        let (bx0, bx1) = (cx - bw / 2, cx - bw / 2 + bw);
        fill_rect(img, bx0, y_q3, bx1, y_q1 + 1, tint(colour, 0.4));
        outline(img, (bx0, y_q3, bx1, y_q1 + 1), 2, colour);
        let y_med = frame.y(b.median);
        fill_rect(img, bx0, y_med - 1, bx1, y_med + 2, INK);
        for v in &b.outliers {
            fill_disc(img, cx, frame.y(*v), 2, colour);
        }
    }
    let mean = (!all.is_empty())
        .then(|| all.iter().sum::<f64>() / all.len() as f64)
        .and_then(unit);
    if let Some(mean) = mean {
        let y = frame.y(mean);
        fill_diamond(img, cx, y, 7, BACKGROUND);
        fill_diamond(img, cx, y, 5, INK);
    }
    let value = match mean {
        Some(m) => first_fitting(&[format!("mean {m:.2}"), format!("{m:.2}")], w),
        None => first_fitting(&["no episodes".to_owned(), "n/a".to_owned()], w),
    };
    slot_caption(img, frame, (x, w), label, &value);
}
