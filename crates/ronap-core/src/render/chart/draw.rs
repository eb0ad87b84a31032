//! What every chart draws with: the drawing primitives (rectangles, outlines, discs, tints),
//! text in the three chart fonts, and legends.

use super::{BACKGROUND, INK, MAX_SIDE};
use image::{Rgb, RgbImage};
use noto_sans_mono_bitmap::{get_raster, get_raster_width, FontWeight, RasterHeight};

// ---------------------------------------------------------------------------------------------
// Drawing primitives
// ---------------------------------------------------------------------------------------------

/// A white canvas of `w` x `h` pixels, each side clamped to 1..=[`MAX_SIDE`].
pub(super) fn canvas(w: i64, h: i64) -> RgbImage {
    let side = |v: i64| v.clamp(1, i64::from(MAX_SIDE)) as u32;
    RgbImage::from_pixel(side(w), side(h), BACKGROUND)
}

/// Fills the pixels `x0..x1` x `y0..y1` (either order), cut to the image.
pub(super) fn fill_rect(img: &mut RgbImage, x0: i64, y0: i64, x1: i64, y1: i64, colour: Rgb<u8>) {
    let (w, h) = (i64::from(img.width()), i64::from(img.height()));
    let (xa, xb) = (x0.min(x1).max(0), x0.max(x1).min(w));
    let (ya, yb) = (y0.min(y1).max(0), y0.max(y1).min(h));
    for y in ya..yb {
        for x in xa..xb {
            img.put_pixel(x as u32, y as u32, colour);
        }
    }
}

/// The outline, `t` pixels thick, of the rectangle `x0..x1` x `y0..y1`.
pub(super) fn outline(
    img: &mut RgbImage,
    (x0, y0, x1, y1): (i64, i64, i64, i64),
    t: i64,
    colour: Rgb<u8>,
) {
    fill_rect(img, x0, y0, x1, y0 + t, colour);
    fill_rect(img, x0, y1 - t, x1, y1, colour);
    fill_rect(img, x0, y0, x0 + t, y1, colour);
    fill_rect(img, x1 - t, y0, x1, y1, colour);
}

/// Mixes `colour` into the pixel at `(x, y)` with coverage `alpha` (255 = all `colour`).
fn blend(img: &mut RgbImage, x: i64, y: i64, colour: Rgb<u8>, alpha: u8) {
    if x < 0 || y < 0 || x >= i64::from(img.width()) || y >= i64::from(img.height()) {
        return;
    }
    let a = u32::from(alpha);
    let p = img.get_pixel_mut(x as u32, y as u32);
    for k in 0..3 {
        p.0[k] = ((u32::from(p.0[k]) * (255 - a) + u32::from(colour.0[k]) * a + 127) / 255) as u8;
    }
}

/// `colour` faded towards white: `amount` 0 is white, 1 is `colour`.
pub(super) fn tint(colour: Rgb<u8>, amount: f64) -> Rgb<u8> {
    let mix = |c: u8| (255.0 - (255.0 - f64::from(c)) * amount).round() as u8;
    Rgb([mix(colour.0[0]), mix(colour.0[1]), mix(colour.0[2])])
}

/// Fills the diamond of half-diagonal `r` around `(cx, cy)`.
pub(super) fn fill_diamond(img: &mut RgbImage, cx: i64, cy: i64, r: i64, colour: Rgb<u8>) {
    for dy in -r..=r {
        let half = r - dy.abs();
        fill_rect(img, cx - half, cy + dy, cx + half + 1, cy + dy + 1, colour);
    }
}

/// Fills the disc of radius `r` around `(cx, cy)`.
pub(super) fn fill_disc(img: &mut RgbImage, cx: i64, cy: i64, r: i64, colour: Rgb<u8>) {
    for dy in -r..=r {
        for dx in -r..=r {
            if dx * dx + dy * dy <= r * r + r {
                fill_rect(img, cx + dx, cy + dy, cx + dx + 1, cy + dy + 1, colour);
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Text
// ---------------------------------------------------------------------------------------------

/// The three text styles of the charts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Font {
    /// Labels and ticks: regular, 16 px line, 7 px per character.
    Body,
    /// Headers: bold, 16 px line.
    Bold,
    /// Titles: bold, 20 px line, 9 px per character.
    Title,
}

impl Font {
    fn style(self) -> (FontWeight, RasterHeight) {
        match self {
            Font::Body => (FontWeight::Regular, RasterHeight::Size16),
            Font::Bold => (FontWeight::Bold, RasterHeight::Size16),
            Font::Title => (FontWeight::Bold, RasterHeight::Size20),
        }
    }

    /// Pixels from one character to the next.
    pub(super) fn advance(self) -> i64 {
        let (weight, height) = self.style();
        get_raster_width(weight, height) as i64
    }

    /// Line height in pixels.
    pub(super) fn height(self) -> i64 {
        self.style().1.val() as i64
    }

    /// How many characters fit in `px` pixels.
    pub(super) fn chars_in(self, px: i64) -> usize {
        (px / self.advance()).max(0) as usize
    }

    /// Width of `s` in pixels.
    pub(super) fn width(self, s: &str) -> i64 {
        s.chars().count() as i64 * self.advance()
    }
}

/// `s` in printable ASCII (other characters as `?`, white space as a space), cut to at most
/// `max_chars` characters: a cut name ends in "..".
pub(super) fn fit(s: &str, max_chars: usize) -> String {
    let clean: Vec<char> = s
        .chars()
        .map(|c| {
            if c == ' ' || c.is_ascii_graphic() {
                c
            } else if c.is_whitespace() {
                ' '
            } else {
                '?'
            }
        })
        .collect();
    if clean.len() <= max_chars {
        clean.into_iter().collect()
    } else if max_chars >= 4 {
        clean[..max_chars - 2]
            .iter()
            .chain(['.', '.'].iter())
            .collect()
    } else {
        clean[..max_chars].iter().collect()
    }
}

/// Where the `x` of a text is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Align {
    Left,
    Centre,
    Right,
}

/// Writes `s` (already [`fit`]) with its line's top at `y`, aligned on `x`.
pub(super) fn text(
    img: &mut RgbImage,
    (x, y): (i64, i64),
    s: &str,
    font: Font,
    colour: Rgb<u8>,
    align: Align,
) {
    let x0 = match align {
        Align::Left => x,
        Align::Centre => x - font.width(s) / 2,
        Align::Right => x - font.width(s),
    };
    let (weight, height) = font.style();
    for (i, c) in s.chars().enumerate() {
        let Some(glyph) = get_raster(c, weight, height).or_else(|| get_raster('?', weight, height))
        else {
            continue;
        };
        let gx0 = x0 + i as i64 * font.advance();
        for (gy, row) in glyph.rows().enumerate() {
            for (gx, &alpha) in row.iter().enumerate() {
                if alpha > 0 {
                    blend(img, gx0 + gx as i64, y + gy as i64, colour, alpha);
                }
            }
        }
    }
}

/// Writes `s` turned a quarter anticlockwise (reading upwards), its line's top at column `x`,
/// centred on row `cy`.
pub(super) fn text_up(img: &mut RgbImage, x: i64, cy: i64, s: &str, font: Font, colour: Rgb<u8>) {
    let bottom = cy + font.width(s) / 2;
    let (weight, height) = font.style();
    for (i, c) in s.chars().enumerate() {
        let Some(glyph) = get_raster(c, weight, height).or_else(|| get_raster('?', weight, height))
        else {
            continue;
        };
        let along = i as i64 * font.advance();
        for (gy, row) in glyph.rows().enumerate() {
            for (gx, &alpha) in row.iter().enumerate() {
                if alpha > 0 {
                    blend(
                        img,
                        x + gy as i64,
                        bottom - along - gx as i64,
                        colour,
                        alpha,
                    );
                }
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Legend
// ---------------------------------------------------------------------------------------------

/// What a legend entry shows before its text.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Key {
    /// A filled square.
    Square(Rgb<u8>),
    /// A thin bar, as the disagreement row.
    Thin(Rgb<u8>),
}

pub(super) const LEGEND_ROW: i64 = 22;
const KEY_PX: i64 = 13;

/// Entries flowed left to right in rows `width` wide: each entry's `(dx, row)`, and the rows.
pub(super) fn legend_layout(width: i64, entries: &[(Key, String)]) -> (Vec<(i64, i64)>, i64) {
    let mut places = Vec::with_capacity(entries.len());
    let (mut dx, mut row) = (0, 0);
    for (_, label) in entries {
        let w = KEY_PX + 6 + Font::Body.width(label);
        if dx > 0 && dx + w > width {
            dx = 0;
            row += 1;
        }
        places.push((dx, row));
        dx += w + 20;
    }
    (places, if entries.is_empty() { 0 } else { row + 1 })
}

/// Draws a legend laid out by [`legend_layout`] with its top-left at `(x, y)`.
pub(super) fn draw_legend(
    img: &mut RgbImage,
    (x, y): (i64, i64),
    width: i64,
    entries: &[(Key, String)],
) {
    let (places, _) = legend_layout(width, entries);
    for ((key, label), (dx, row)) in entries.iter().zip(places) {
        let (ex, ey) = (x + dx, y + row * LEGEND_ROW);
        match *key {
            Key::Square(c) => fill_rect(img, ex, ey + 2, ex + KEY_PX, ey + 2 + KEY_PX, c),
            Key::Thin(c) => fill_rect(img, ex, ey + 6, ex + KEY_PX, ey + 10, c),
        }
        text(
            img,
            (ex + KEY_PX + 6, ey),
            label,
            Font::Body,
            INK,
            Align::Left,
        );
    }
}
