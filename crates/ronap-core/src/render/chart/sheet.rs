//! Contact sheets: episode pictures in a grid, a column per policy and a row per seed.

use super::*;

pub(super) const SHEET_MARGIN: i64 = 10;
pub(super) const SHEET_HEADER: i64 = 26;
pub(super) const SHEET_CAPTION: i64 = 22;
pub(super) const SHEET_ROW_GAP: i64 = 12;
pub(super) const SHEET_COL_GAP: i64 = 12;
/// The most pixels a contact sheet has: past it the cells shrink.
pub(super) const SHEET_MAX_PIXELS: i64 = 100_000_000;

/// Where everything of a contact sheet goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct SheetLayout {
    /// Side of a picture's square cell.
    cell: i64,
    /// Width of the label column.
    label_w: i64,
    /// Columns.
    cols: usize,
    /// Rows.
    rows: usize,
}

impl SheetLayout {
    pub(super) fn new(cell_px: u32, label_chars: usize, cols: usize, rows: usize) -> Self {
        let label_w = if label_chars == 0 {
            0
        } else {
            label_chars as i64 * Font::Body.advance() + 12
        };
        let mut layout = Self {
            cell: i64::from(cell_px).clamp(16, 4096),
            label_w,
            cols,
            rows,
        };
        while layout.cell > 16 && layout.width() * layout.height() > SHEET_MAX_PIXELS {
            layout.cell = (layout.cell * 3 / 4).max(16);
        }
        layout
    }

    pub(super) fn width(&self) -> i64 {
        let cols = self.cols as i64 * (self.cell + SHEET_COL_GAP);
        (2 * SHEET_MARGIN + self.label_w + cols).max(160)
    }

    pub(super) fn height(&self) -> i64 {
        let rows = self.rows as i64 * (self.cell + SHEET_CAPTION + SHEET_ROW_GAP);
        (2 * SHEET_MARGIN + SHEET_HEADER + rows).max(60)
    }

    /// Top-left of the cell of row `r`, column `c`.
    pub(super) fn cell_at(&self, r: usize, c: usize) -> (i64, i64) {
        (
            SHEET_MARGIN + self.label_w + c as i64 * (self.cell + SHEET_COL_GAP),
            SHEET_MARGIN + SHEET_HEADER + r as i64 * (self.cell + SHEET_CAPTION + SHEET_ROW_GAP),
        )
    }
}

/// `picture` scaled to fit a `cell` x `cell` square, keeping its aspect: smoothed (bilinear) when
/// shrunk, nearest-neighbour when enlarged so that scene pixels stay crisp. `None` for an empty
/// picture.
pub(super) fn fit_picture(picture: &RgbImage, cell: i64) -> Option<RgbImage> {
    let (w, h) = (i64::from(picture.width()), i64::from(picture.height()));
    if w == 0 || h == 0 {
        return None;
    }
    let scale = (cell as f64 / w as f64).min(cell as f64 / h as f64);
    let side = |v: i64| ((v as f64 * scale).round() as i64).clamp(1, cell) as u32;
    let (nw, nh) = (side(w), side(h));
    if (i64::from(nw), i64::from(nh)) == (w, h) {
        return Some(picture.clone());
    }
    let filter = if scale < 1.0 {
        FilterType::Triangle
    } else {
        FilterType::Nearest
    };
    Some(imageops::resize(picture, nw, nh, filter))
}

/// A contact sheet: a header with the `columns`' names (e.g. the policies), then one row per
/// entry of `rows`, its label on the left (e.g. "seed 17") and its pictures in the columns, each
/// scaled to fit a square of `cell_px` (keeping its aspect, centred, framed) with its caption
/// under it (e.g. "success, 212 steps").
///
/// There are as many columns as names or as pictures in the longest row, whichever is more.
/// `cell_px` is kept within 16-4096, and shrunk further if the sheet would pass 100 megapixels.
pub fn contact_sheet(columns: &[String], rows: &[SheetRow], cell_px: u32) -> RgbImage {
    let cols = rows
        .iter()
        .map(|r| r.cells.len())
        .chain([columns.len()])
        .max()
        .unwrap_or(0);
    let labels: Vec<String> = rows.iter().map(|r| fit(&r.label, 20)).collect();
    let label_chars = labels.iter().map(|l| l.len()).max().unwrap_or(0);
    let layout = SheetLayout::new(cell_px, label_chars, cols, rows.len());
    let mut img = canvas(layout.width(), layout.height());
    let cell = layout.cell;
    let room = Font::Body.chars_in(cell + SHEET_COL_GAP - 2);

    if cols == 0 || rows.is_empty() {
        let at = (SHEET_MARGIN, SHEET_MARGIN + SHEET_HEADER);
        text(&mut img, at, "no pictures", Font::Body, MUTED, Align::Left);
    }
    for (c, name) in columns.iter().enumerate() {
        let x = layout.cell_at(0, c).0 + cell / 2;
        let name = fit(name, room);
        let at = (x, SHEET_MARGIN);
        text(
            &mut img,
            at,
            &name,
            Font::Bold,
            policy_colour_dark(c),
            Align::Centre,
        );
    }
    for (r, (row, label)) in rows.iter().zip(&labels).enumerate() {
        let (_, y) = layout.cell_at(r, 0);
        let at = (SHEET_MARGIN, y + cell / 2 - Font::Body.height() / 2);
        text(&mut img, at, label, Font::Body, INK, Align::Left);
        for (c, (picture, caption)) in row.cells.iter().enumerate() {
            let (x, y) = layout.cell_at(r, c);
            if let Some(scaled) = fit_picture(picture, cell) {
                let (w, h) = (i64::from(scaled.width()), i64::from(scaled.height()));
                let (px, py) = (x + (cell - w) / 2, y + (cell - h) / 2);
                outline(&mut img, (px - 1, py - 1, px + w + 1, py + h + 1), 1, FRAME);
                imageops::replace(&mut img, &scaled, px, py);
            } else {
                outline(&mut img, (x, y, x + cell, y + cell), 1, GRID);
            }
            let caption = fit(caption, room);
            let at = (x + cell / 2, y + cell + 4);
            text(&mut img, at, &caption, Font::Body, INK, Align::Centre);
        }
    }
    img
}
