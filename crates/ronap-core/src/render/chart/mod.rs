//! Charts that compare policies: the success-rate and SPL panels of a comparison
//! ([`compare_chart`]), the per-seed outcome strip ([`outcome_strip`]), contact sheets of episode
//! pictures ([`contact_sheet`]) and success rates grouped by bin ([`grouped_bars`]).
//!
//! Every function is pure: plain figures in, an [`RgbImage`] out; no files, no printing. Odd input
//! never panics and still gives a readable picture: an empty list gives a small image that says
//! so, a figure that is not finite is left out (its label reads "n/a"), rates are clamped to 0-1,
//! and names are cut to fit (ending in ".."). A picture is at most [`MAX_SIDE`] pixels a side;
//! past that it is cut off.
//!
//! Text uses Noto Sans Mono glyphs that the `noto-sans-mono-bitmap` crate stores pre-rasterised,
//! so no system font is needed. Only printable ASCII is drawn: any other character shows as `?`.
//!
//! Policy `i` (its index in the slice passed in) has colour [`policy_colour`]`(i)` in every chart,
//! and each outcome has colour [`outcome_colour`].

mod compare;
mod draw;
mod grouped;
mod line;
mod plot;
mod sheet;
mod strip;

pub use compare::compare_chart;
pub use grouped::grouped_bars;
pub use line::{line_chart, Line, Panel};
pub use sheet::contact_sheet;
pub use strip::outcome_strip;

use crate::eval::Outcome;
use draw::{
    canvas, draw_legend, fill_diamond, fill_disc, fill_rect, fit, legend_layout, outline, text,
    text_up, tint, Align, Font, Key, LEGEND_ROW,
};
use image::imageops::{self, FilterType};
use image::{Rgb, RgbImage};
use plot::{
    box_stats, first_fitting, policy_colour_dark, policy_legend, slot_labels, unit, whisker, Frame,
};

/// The longest side of any chart, in pixels; drawing past it is cut off.
pub const MAX_SIDE: u32 = 30_000;

/// Background colour of every chart.
pub const BACKGROUND: Rgb<u8> = Rgb([255, 255, 255]);
/// Text and axis colour.
const INK: Rgb<u8> = Rgb([33, 33, 33]);
/// Secondary text: tick labels, values under bars, seed ranges.
const MUTED: Rgb<u8> = Rgb([100, 100, 100]);
/// Grid lines.
const GRID: Rgb<u8> = Rgb([225, 225, 225]);
/// Picture frames in contact sheets.
const FRAME: Rgb<u8> = Rgb([190, 190, 190]);
/// Strip cells without an outcome, and the disagreement row where the policies agree.
pub const NO_DATA: Rgb<u8> = Rgb([236, 236, 236]);
/// Disagreement row of the outcome strip where the policies disagree.
pub const DISAGREE: Rgb<u8> = Rgb([40, 40, 40]);

/// Policy colours: matplotlib's "tab10", ten hues that stay apart on screen and in print.
/// How many distinct colours [`policy_colour`] gives before repeating.
pub const POLICY_COUNT: usize = 10;

const POLICY_COLOURS: [Rgb<u8>; POLICY_COUNT] = [
    Rgb([31, 119, 180]),
    Rgb([255, 127, 14]),
    Rgb([44, 160, 44]),
    Rgb([214, 39, 40]),
    Rgb([148, 103, 189]),
    Rgb([140, 86, 75]),
    Rgb([227, 119, 194]),
    Rgb([127, 127, 127]),
    Rgb([188, 189, 34]),
    Rgb([23, 190, 207]),
];

/// The colour of the `index`-th policy of a chart (ten colours, then they repeat).
pub fn policy_colour(index: usize) -> Rgb<u8> {
    POLICY_COLOURS[index % POLICY_COLOURS.len()]
}

/// The colour of an outcome in the outcome strip: success green, timeout amber, stuck grey,
/// collision red, reward floor purple, deadlock brown, infeasible near black.
pub fn outcome_colour(outcome: Outcome) -> Rgb<u8> {
    match outcome {
        Outcome::Success => Rgb([46, 160, 67]),
        Outcome::Timeout => Rgb([242, 169, 0]),
        Outcome::Stuck => Rgb([150, 150, 150]),
        Outcome::Collision => Rgb([215, 48, 39]),
        Outcome::RewardMin => Rgb([128, 64, 176]),
        Outcome::Deadlock => Rgb([140, 86, 75]),
        Outcome::Infeasible => Rgb([40, 40, 40]),
    }
}

// ---------------------------------------------------------------------------------------------
// Input types
// ---------------------------------------------------------------------------------------------

/// One policy's figures for [`compare_chart`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PolicyBars {
    /// The policy's name, shown under its bar and box (cut to fit).
    pub name: String,
    /// Fraction of the episodes that reached the goal, 0-1 (not per cent).
    pub success_rate: f64,
    /// The 95% interval of the success rate, `[low, high]`, as fractions 0-1.
    pub success_ci95: [f64; 2],
    /// SPL of every episode, 0 for the failures. The box plot shows the entries above 0 (the
    /// successful episodes); the diamond marks the mean over all entries. Entries that are not
    /// finite are left out.
    pub spl: Vec<f64>,
}

/// One row of a [`contact_sheet`]: a label on the left and one captioned picture per column.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SheetRow {
    /// The row's label, e.g. "seed 17".
    pub label: String,
    /// One picture and its caption per column, in column order; a 0 x 0 picture leaves its cell
    /// empty (its caption is still written).
    pub cells: Vec<(RgbImage, String)>,
}

/// One policy's success rates per bin for [`grouped_bars`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Series {
    /// The policy's name, shown in the legend.
    pub name: String,
    /// Per bin, in the order of the bins: the success rate (0-1) and its 95% interval
    /// `[low, high]`. A missing or non-finite rate draws no bar.
    pub values: Vec<(f64, [f64; 2])>,
}

#[cfg(test)]
mod tests {
    use super::compare::*;
    use super::grouped::*;
    use super::plot::Naming;
    use super::sheet::*;
    use super::strip::*;
    use super::*;

    fn bars(name: &str, rate: f64, spl: Vec<f64>) -> PolicyBars {
        PolicyBars {
            name: name.to_owned(),
            success_rate: rate,
            success_ci95: [(rate - 0.05).max(0.0), (rate + 0.05).min(1.0)],
            spl,
        }
    }

    /// Rows of column `x` within `top..=bottom` that have `colour`.
    fn count_in_column(img: &RgbImage, x: i64, top: i64, bottom: i64, colour: Rgb<u8>) -> i64 {
        (top..=bottom)
            .filter(|&y| *img.get_pixel(x as u32, y as u32) == colour)
            .count() as i64
    }

    fn px(img: &RgbImage, (x, y): (i64, i64)) -> Rgb<u8> {
        *img.get_pixel(x as u32, y as u32)
    }

    #[test]
    fn fit_cuts_long_names_and_replaces_what_it_cannot_draw() {
        assert_eq!(fit("greedy", 10), "greedy");
        assert_eq!(fit("a very long policy name", 10), "a very l..");
        assert_eq!(fit("a very long policy name", 10).len(), 10);
        assert_eq!(fit("abcdef", 3), "abc");
        assert_eq!(fit("abc", 0), "");
        assert_eq!(fit("déjà\tvu", 20), "d?j? vu");
    }

    #[test]
    fn labels_are_names_cut_names_or_numbers() {
        let names = ["greedy", "a-rather-long-policy-name"];
        let (labels, naming) = slot_labels(names.iter().copied(), 300);
        assert_eq!(
            (labels, naming),
            (vec!["greedy".to_owned(), names[1].to_owned()], Naming::Full)
        );
        // 12 characters of room: the long name is cut, and a legend gives it.
        let (labels, naming) = slot_labels(names.iter().copied(), 12 * 7 + 4);
        assert_eq!(labels[1], "a-rather-l..");
        assert_eq!(naming, Naming::Cut);
        assert_eq!(policy_legend(names.iter().copied(), naming)[1].1, names[1]);
        // 5 characters: numbers.
        let (labels, naming) = slot_labels(names.iter().copied(), 5 * 7 + 4);
        assert_eq!(
            (labels, naming),
            (vec!["1".to_owned(), "2".to_owned()], Naming::Numbered)
        );
        assert_eq!(
            policy_legend(names.iter().copied(), naming)[0].1,
            "1 greedy"
        );
        assert!(policy_legend(names.iter().copied(), Naming::Full).is_empty());
    }

    #[test]
    fn a_full_success_bar_is_taller_than_a_fifth() {
        let img = compare_chart(
            "t",
            &[bars("full", 1.0, vec![1.0]), bars("fifth", 0.2, vec![])],
        );
        assert_eq!(img.dimensions(), (1000, 450));
        let (left, _) = compare_frames();
        let mut heights = Vec::new();
        for i in 0..2 {
            let (x, w) = left.slot(i, 2);
            // A quarter of the bar's width off its centre, clear of the whisker.
            let col = x + w / 2 + (w as f64 * 0.55 / 4.0) as i64;
            heights.push(count_in_column(
                &img,
                col,
                left.top,
                left.bottom,
                policy_colour(i),
            ));
        }
        let plot = left.bottom - left.top;
        assert!((heights[0] - plot).abs() <= 2, "{heights:?} of {plot}");
        assert!((heights[1] - plot / 5).abs() <= 2, "{heights:?} of {plot}");
        // Halfway up, the first bar is there and the second is not.
        let (x1, w1) = left.slot(1, 2);
        assert_eq!(px(&img, (x1 + w1 / 2 + 10, left.y(0.5) + 2)), BACKGROUND);
    }

    #[test]
    fn the_whisker_spans_the_interval() {
        let mut p = bars("p", 0.5, vec![]);
        p.success_ci95 = [0.3, 0.8];
        let img = compare_chart("t", &[p]);
        let (left, _) = compare_frames();
        let (x, w) = left.slot(0, 1);
        let cx = x + w / 2;
        // Above the bar the whisker is the only ink in the centre column: from 0.8 down to 0.5.
        let ink = count_in_column(&img, cx, left.top, left.y(0.5) - 1, INK);
        let expected = left.y(0.5) - left.y(0.8);
        assert!((ink - expected).abs() <= 2, "{ink} vs {expected}");
        assert_eq!(px(&img, (cx, left.y(0.9))), BACKGROUND);
    }

    #[test]
    fn the_spl_box_spans_the_quartiles_and_the_mean_is_marked() {
        // Successes 0.2, 0.4, 0.6, 0.8 (quartiles 0.35 and 0.65) and one failure: mean 0.4.
        let spl = vec![0.2, 0.4, 0.6, 0.8, 0.0];
        let stats = box_stats(&[0.2, 0.4, 0.6, 0.8]).expect("values");
        assert!((stats.q1 - 0.35).abs() < 1e-12 && (stats.q3 - 0.65).abs() < 1e-12);
        assert!((stats.median - 0.5).abs() < 1e-12);
        assert_eq!((stats.low, stats.high), (0.2, 0.8));
        let img = compare_chart("t", &[bars("p", 0.8, spl)]);
        let (_, right) = compare_frames();
        let (x, w) = right.slot(0, 1);
        let cx = x + w / 2;
        let fill = tint(policy_colour(0), 0.4);
        // Box fill between the quartiles (off the centre column and the median line), none
        // outside them.
        let col = cx + 8;
        let inside = count_in_column(&img, col, right.top, right.bottom, fill);
        let box_h = right.y(0.35) - right.y(0.65);
        assert!(
            inside > box_h - 10 && inside <= box_h,
            "{inside} vs {box_h}"
        );
        assert_eq!(px(&img, (col, right.y(0.7))), BACKGROUND);
        // The mean diamond at 0.4, the median line at 0.5.
        assert_eq!(px(&img, (cx, right.y(0.4))), INK);
        assert_eq!(px(&img, (col, right.y(0.5))), INK);
        // The same policy colour as the bar on the left.
        let outline_px = count_in_column(&img, cx, right.top, right.bottom, policy_colour(0));
        assert!(outline_px >= 2, "{outline_px}");
    }

    #[test]
    fn box_stats_set_apart_outliers() {
        let mut v = vec![0.5, 0.52, 0.54, 0.56, 0.58, 0.6, 0.05];
        v.sort_by(f64::total_cmp);
        let s = box_stats(&v).expect("values");
        assert_eq!(s.outliers, vec![0.05]);
        assert_eq!(s.low, 0.5);
        assert_eq!(box_stats(&[]), None);
        let one = box_stats(&[0.7]).expect("one");
        assert_eq!(
            (one.low, one.q1, one.median, one.q3, one.high),
            (0.7, 0.7, 0.7, 0.7, 0.7)
        );
    }

    #[test]
    fn odd_figures_do_not_panic_and_many_long_names_get_a_legend() {
        let odd = PolicyBars {
            name: String::new(),
            success_rate: f64::NAN,
            success_ci95: [f64::NAN, f64::INFINITY],
            spl: vec![f64::NAN, f64::NEG_INFINITY, -3.0, 7.0],
        };
        let img = compare_chart(
            "",
            &[odd.clone(), bars("x", 2.0, vec![]), bars("y", -1.0, vec![])],
        );
        assert_eq!(img.dimensions(), (1000, 450));
        let many: Vec<PolicyBars> = (0..10)
            .map(|i| {
                bars(
                    &format!("policy number {i} with a very long name indeed"),
                    0.1 * i as f64,
                    vec![0.5; 3],
                )
            })
            .collect();
        let img = compare_chart(&"a very long title ".repeat(20), &many);
        assert_eq!(img.width(), 1000);
        assert!(img.height() > 450, "a legend row or more: {}", img.height());
        let one = compare_chart("one", &many[..1]);
        assert_eq!(one.dimensions(), (1000, 450));
        let empty = compare_chart("nothing", &[]);
        assert_eq!(empty.dimensions(), (1000, 450));
    }

    #[test]
    fn text_is_drawn_in_ink() {
        let img = compare_chart("TITLE", &[]);
        let inked = (14..34)
            .flat_map(|y| (20..70).map(move |x| (x, y)))
            .filter(|&(x, y)| img.get_pixel(x, y).0[0] < 128)
            .count();
        assert!(inked > 40, "{inked} dark pixels in the title");
    }

    fn pattern(p: usize, s: usize) -> Outcome {
        match (p, s % 7) {
            (_, 0) => Outcome::Success,
            (0, _) if s % 3 == 0 => Outcome::Success,
            (1, 1 | 2) => Outcome::Success,
            (_, 1) => Outcome::Collision,
            (_, 2) => Outcome::Stuck,
            (_, 3) => Outcome::RewardMin,
            _ => Outcome::Timeout,
        }
    }

    #[test]
    fn strip_size_follows_seeds_and_policies() {
        let names = |n: usize| (0..n).map(|i| format!("p{i}")).collect::<Vec<_>>();
        let strip = |policies: usize, seeds: usize| {
            let seeds_v: Vec<u64> = (1..=seeds as u64).collect();
            let outcomes = vec![vec![Outcome::Success; seeds]; policies];
            outcome_strip(&names(policies), &seeds_v, &outcomes)
        };
        let label_w = 8 * Font::Body.advance() + 12;
        for (seeds, cell_w, columns) in [
            (250, 4, 250),
            (300, 4, 300),
            (350, 3, 350),
            (600, 2, 600),
            (1000, 1, 1000),
            (1200, 1, 1200),
            (3000, 1, 1200),
        ] {
            let img = strip(2, seeds);
            let want = (2 * STRIP_MARGIN + label_w + columns * cell_w).max(560);
            assert_eq!(i64::from(img.width()), want, "{seeds} seeds");
        }
        // Each policy adds one row to every band; each band of 1200 seeds adds a band.
        let band_row = STRIP_ROW + STRIP_ROW_GAP;
        let h = |p, s| i64::from(strip(p, s).height());
        assert_eq!(h(3, 100) - h(1, 100), 2 * band_row);
        assert_eq!(h(3, 2500) - h(1, 2500), 3 * 2 * band_row);
        let band_h = STRIP_HEADER + 2 * band_row + STRIP_DISAGREE + STRIP_BAND_GAP;
        assert_eq!(h(2, 2400) - h(2, 1200), band_h);
        assert_eq!(h(2, 2401) - h(2, 1200), 2 * band_h);
    }

    #[test]
    fn strip_cells_have_their_outcome_and_disagreement_is_marked_exactly() {
        for seeds in [40, 2500] {
            let names: Vec<String> = ["a", "b", "c"].iter().map(|s| s.to_string()).collect();
            let seed_ids: Vec<u64> = (0..seeds as u64).map(|s| 1000 + s).collect();
            let outcomes: Vec<Vec<Outcome>> = (0..3)
                .map(|p| (0..seeds).map(|s| pattern(p, s)).collect())
                .collect();
            let img = outcome_strip(&names, &seed_ids, &outcomes);
            let layout = StripLayout::new(seeds, 3, 8);
            let mut marked = 0;
            for s in 0..seeds {
                for (p, row) in outcomes.iter().enumerate() {
                    let (x, y) = layout.cell(p, s);
                    assert_eq!(px(&img, (x, y + 8)), outcome_colour(row[s]), "p {p} s {s}");
                }
                let won: Vec<bool> = outcomes.iter().map(|r| r[s] == Outcome::Success).collect();
                let differ = won.iter().any(|&w| w != won[0]);
                let (x, y) = layout.disagree(s);
                let want = if differ { DISAGREE } else { NO_DATA };
                assert_eq!(px(&img, (x, y + 8)), want, "seeds {seeds}: seed {s}");
                marked += usize::from(differ);
            }
            assert!(marked > seeds / 4 && marked < seeds, "{marked} of {seeds}");
        }
    }

    #[test]
    fn strip_copes_with_ragged_and_missing_outcomes() {
        let names = vec!["only".to_owned()];
        let seeds: Vec<u64> = (0..10).collect();
        // Two outcome rows for one name, the first too short, the second too long.
        let outcomes = vec![vec![Outcome::Success; 4], vec![Outcome::Collision; 30]];
        let img = outcome_strip(&names, &seeds, &outcomes);
        let layout = StripLayout::new(10, 2, 8);
        assert_eq!(
            px(&img, layout.cell(0, 3)),
            outcome_colour(Outcome::Success)
        );
        assert_eq!(px(&img, layout.cell(0, 4)), NO_DATA);
        assert_eq!(
            px(&img, layout.cell(1, 9)),
            outcome_colour(Outcome::Collision)
        );
        let (x, y) = layout.disagree(3);
        assert_eq!(px(&img, (x, y + 8)), DISAGREE);
        let (x, y) = layout.disagree(4);
        assert_eq!(
            px(&img, (x, y + 8)),
            NO_DATA,
            "one policy alone never disagrees"
        );
        // One policy: never a disagreement.
        let img = outcome_strip(&names, &seeds, &outcomes[..1]);
        let layout = StripLayout::new(10, 1, 8);
        for s in 0..10 {
            let (x, y) = layout.disagree(s);
            assert_eq!(px(&img, (x, y + 8)), NO_DATA);
        }
    }

    fn solid(w: u32, h: u32, colour: [u8; 3]) -> RgbImage {
        RgbImage::from_pixel(w, h, Rgb(colour))
    }

    #[test]
    fn contact_sheet_is_header_plus_rows_of_cells() {
        let columns = vec!["greedy".to_owned(), "mlp".to_owned()];
        let rows: Vec<SheetRow> = (0..3)
            .map(|r| SheetRow {
                label: format!("seed {r}"),
                cells: vec![
                    (
                        solid(200, 100, [255, 0, 0]),
                        "success, 212 steps".to_owned(),
                    ),
                    (solid(30, 60, [0, 0, 255]), "timeout".to_owned()),
                ],
            })
            .collect();
        let img = contact_sheet(&columns, &rows, 100);
        let label_w = 6 * Font::Body.advance() + 12;
        let width = 2 * SHEET_MARGIN + label_w + 2 * (100 + SHEET_COL_GAP);
        let height = 2 * SHEET_MARGIN + SHEET_HEADER + 3 * (100 + SHEET_CAPTION + SHEET_ROW_GAP);
        assert_eq!(
            (i64::from(img.width()), i64::from(img.height())),
            (width, height)
        );
        let layout = SheetLayout::new(100, 6, 2, 3);
        // 200 x 100 shrinks to 100 x 50, centred: rows 25..75 of the cell.
        let (x, y) = layout.cell_at(2, 0);
        assert_eq!(px(&img, (x + 50, y + 50)), Rgb([255, 0, 0]));
        assert_eq!(px(&img, (x, y + 25)), Rgb([255, 0, 0]));
        assert_eq!(px(&img, (x + 99, y + 74)), Rgb([255, 0, 0]));
        assert_eq!(px(&img, (x + 50, y + 10)), BACKGROUND);
        assert_eq!(px(&img, (x + 50, y + 90)), BACKGROUND);
        // 30 x 60 grows to 50 x 100: columns 25..75.
        let (x, y) = layout.cell_at(1, 1);
        assert_eq!(px(&img, (x + 25, y)), Rgb([0, 0, 255]));
        assert_eq!(px(&img, (x + 74, y + 99)), Rgb([0, 0, 255]));
        assert_eq!(px(&img, (x + 10, y + 50)), BACKGROUND);
    }

    #[test]
    fn contact_sheet_copes_with_odd_cells() {
        let rows = vec![
            SheetRow {
                label: "x".repeat(200),
                cells: vec![(RgbImage::new(0, 0), String::new())],
            },
            SheetRow {
                label: String::new(),
                cells: vec![
                    (solid(1, 1, [0, 0, 0]), "c".repeat(100)),
                    (solid(3000, 2, [0, 0, 0]), "wide".to_owned()),
                    (solid(1, 1, [0, 0, 0]), "third, no column name".to_owned()),
                ],
            },
        ];
        let img = contact_sheet(&["one".to_owned()], &rows, 0);
        let layout = SheetLayout::new(16, 20, 3, 2);
        assert_eq!(
            (i64::from(img.width()), i64::from(img.height())),
            (layout.width(), layout.height())
        );
    }

    #[test]
    fn grouped_bar_heights_follow_the_rates() {
        let bins: Vec<String> = ["ratio 1.0-1.3", "ratio 1.3-1.6", "ratio 1.6+"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        let series = vec![
            Series {
                name: "greedy".to_owned(),
                values: vec![(0.9, [0.85, 0.95]), (0.5, [0.4, 0.6]), (0.1, [0.05, 0.2])],
            },
            Series {
                name: "mlp".to_owned(),
                values: vec![(0.6, [0.5, 0.7]), (f64::NAN, [f64::NAN, 0.5])],
            },
        ];
        let img = grouped_bars("by difficulty", &bins, &series);
        let frame = grouped_frame(3, 2, 13);
        assert_eq!(i64::from(img.width()), frame.right + GROUPED_RIGHT_MARGIN);
        let plot = frame.bottom - frame.top;
        for (b, want) in [(0, [0.9, 0.6]), (1, [0.5, 0.0]), (2, [0.1, 0.0])] {
            let (x, w) = frame.slot(b, 3);
            let gap = (w / 5).clamp(2, 28);
            let bar = ((w - gap) / 2).clamp(1, 30);
            let group_x = x + (w - bar * 2) / 2;
            for (i, rate) in want.iter().enumerate() {
                let col = group_x + i as i64 * bar + 2;
                let h = count_in_column(&img, col, frame.top, frame.bottom, policy_colour(i));
                let expected = (rate * plot as f64).round() as i64;
                assert!(
                    (h - expected).abs() <= 1,
                    "bin {b} series {i}: {h} vs {expected}"
                );
            }
        }
    }

    /// A rising, slightly noisy return over 2 M steps and a success rate climbing to 0.8.
    fn training_panels() -> Vec<Panel> {
        let steps = |i: usize| i as f64 * 50_000.0;
        vec![
            Panel {
                y_label: "mean return".to_owned(),
                y_range: None,
                lines: vec![Line {
                    name: "dqn".to_owned(),
                    points: (0..=40)
                        .map(|i| {
                            let t = i as f64 / 40.0;
                            (steps(i), -180.0 + 420.0 * t + 25.0 * (i as f64 * 1.7).sin())
                        })
                        .collect(),
                }],
            },
            Panel {
                y_label: "success rate".to_owned(),
                y_range: Some((0.0, 1.0)),
                lines: vec![Line {
                    name: "validation".to_owned(),
                    points: (0..=40)
                        .map(|i| (steps(i), 0.8 * (1.0 - (-(i as f64) / 12.0).exp())))
                        .collect(),
                }],
            },
        ]
    }

    #[test]
    fn line_charts_are_900_wide_and_grow_by_a_panel_each() {
        let panels = training_panels();
        let one = line_chart("DQN", "steps", &panels[..1]);
        let two = line_chart("DQN", "steps", &panels);
        // Title 44, then per panel a legend row 22, the plot 200 and a gap 16, then the x axis 46.
        assert_eq!(one.dimensions(), (900, 44 + 238 + 46));
        assert_eq!(two.dimensions(), (900, 44 + 2 * 238 + 46));
    }

    #[test]
    fn line_charts_without_data_say_so() {
        let nan = Line {
            name: "nan".to_owned(),
            points: vec![(f64::NAN, 1.0), (1.0, f64::NAN), (f64::INFINITY, 0.5)],
        };
        for lines in [vec![], vec![nan]] {
            for y_range in [None, Some((0.0, 1.0))] {
                let panel = Panel {
                    y_label: "nothing".to_owned(),
                    y_range,
                    lines: lines.clone(),
                };
                let img = line_chart("empty", "steps", &[panel]);
                // "no data" is written in the middle of the plot, 100 px below its top.
                let rows = lines.len() as i64 * LEGEND_ROW;
                let (cx, cy) = (96 + (900 - 96 - 30) / 2, 44 + rows + 100);
                let inked = (cy - 8..cy + 8)
                    .flat_map(|y| (cx - 30..cx + 30).map(move |x| (x, y)))
                    .filter(|&p| px(&img, p).0[0] < 200)
                    .count();
                assert!(inked > 20, "{inked} dark pixels where the note goes");
            }
        }
        // A lone point, equal values and huge values draw something in the line's colour.
        for points in [
            vec![(5.0, 3.0)],
            vec![(0.0, 2.0), (1.0, 2.0), (2.0, 2.0)],
            vec![(0.0, -1e300), (1e300, 1e300)],
        ] {
            let panel = Panel {
                y_label: "odd".to_owned(),
                y_range: None,
                lines: vec![Line {
                    name: "odd".to_owned(),
                    points,
                }],
            };
            let img = line_chart("odd", "x", &[panel]);
            let drawn = img
                .enumerate_pixels()
                .filter(|(_, y, p)| i64::from(*y) > 44 + LEGEND_ROW && **p == policy_colour(0))
                .count();
            assert!(drawn >= 4, "{drawn} pixels of the line");
        }
        let none = line_chart("", "", &[]);
        assert_eq!(none.width(), 900);
    }

    /// Writes the example picture to `/tmp/line_chart_example.png` for a look by eye:
    /// `cargo test -p ronap-core --release render::chart -- --ignored`.
    #[test]
    #[ignore = "writes a file for a look by eye"]
    fn line_chart_example_png() {
        let img = line_chart("DQN on corridors", "steps", &training_panels());
        img.save("/tmp/line_chart_example.png").expect("saved");
    }

    #[test]
    fn empty_inputs_give_small_valid_images() {
        for img in [
            compare_chart("", &[]),
            outcome_strip(&[], &[], &[]),
            outcome_strip(&["a".to_owned()], &[], &[vec![Outcome::Success]]),
            contact_sheet(&[], &[], 128),
            grouped_bars("", &[], &[]),
            grouped_bars("", &["a".to_owned()], &[]),
        ] {
            let (w, h) = img.dimensions();
            assert!(w >= 100 && h >= 50 && w <= 1400 && h <= 600, "{w} x {h}");
        }
    }
}
