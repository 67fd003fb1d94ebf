//! The difference picture's legend: a colour bar from −τ_max to +τ_max
//! under the image, labelled with the 8x8 bitmap glyphs of `font8x8`
//! (public-domain glyphs, so the PNG needs no font file on the machine).

use crate::images::diverging;
use font8x8::{UnicodeFonts, BASIC_FONTS};

/// Glyph size, pixels.
const GLYPH: usize = 8;
/// Margin around the bar and between lines, pixels.
const MARGIN: usize = 6;
/// Height of the colour bar, pixels.
const BAR: usize = 12;
/// The caption under the labels.
const CAPTION: &str = "L_a/L_b - 1: blue darker, red brighter";
const WHITE: [u8; 3] = [255, 255, 255];
const BLACK: [u8; 3] = [0, 0, 0];

/// A picture being drawn: row-major RGB.
struct Canvas {
    width: usize,
    pixels: Vec<[u8; 3]>,
}

impl Canvas {
    /// Draws `text` with its top-left corner at `(x, y)`, clipped.
    fn text(&mut self, x: usize, y: usize, text: &str) {
        for (k, c) in text.chars().enumerate() {
            let Some(rows) = BASIC_FONTS.get(c) else { continue };
            for (dy, bits) in rows.iter().enumerate() {
                for dx in 0..GLYPH {
                    let (px, py) = (x + k * GLYPH + dx, y + dy);
                    if bits >> dx & 1 == 1 && px < self.width && py * self.width + px < self.pixels.len() {
                        self.pixels[py * self.width + px] = BLACK;
                    }
                }
            }
        }
    }
}

/// `τ` as a percentage with at most three decimals and no trailing zeros:
/// 0.1 → `10%`, 0.025 → `2.5%`.
pub fn percent(tau: f64) -> String {
    let text = format!("{:.3}", 100.0 * tau);
    format!("{}%", text.trim_end_matches('0').trim_end_matches('.'))
}

/// The picture with the legend below it: `(width, height, pixels)`. The
/// result is at least wide enough for the caption; the image keeps its
/// pixels at the top left, on white.
pub fn with_scale_bar(width: usize, height: usize, picture: &[[u8; 3]], tau_max: f64) -> (usize, usize, Vec<[u8; 3]>) {
    let out_width = width.max(CAPTION.len() * GLYPH + 2 * MARGIN);
    let bar_top = height + MARGIN;
    let labels_top = bar_top + BAR + 2;
    let caption_top = labels_top + GLYPH + 2;
    let out_height = caption_top + GLYPH + MARGIN;
    let mut canvas = Canvas { width: out_width, pixels: vec![WHITE; out_width * out_height] };
    for y in 0..height {
        canvas.pixels[y * out_width..y * out_width + width].copy_from_slice(&picture[y * width..(y + 1) * width]);
    }
    let (left, right) = (MARGIN, out_width - MARGIN);
    for x in left..right {
        let t = 2.0 * (x - left) as f64 / (right - 1 - left) as f64 - 1.0;
        for y in bar_top..bar_top + BAR {
            canvas.pixels[y * out_width + x] = diverging(t);
        }
    }
    let low = format!("-{}", percent(tau_max));
    let high = format!("+{}", percent(tau_max));
    canvas.text(left, labels_top, &low);
    canvas.text((left + right) / 2 - GLYPH / 2, labels_top, "0");
    canvas.text(right - high.len() * GLYPH, labels_top, &high);
    canvas.text(left, caption_top, CAPTION);
    (out_width, out_height, canvas.pixels)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_and_bar_ends() {
        assert_eq!(percent(0.1), "10%");
        assert_eq!(percent(0.025), "2.5%");
        assert_eq!(percent(0.07), "7%");
        let picture = vec![[9, 9, 9]; 4 * 2];
        let (w, h, pixels) = with_scale_bar(4, 2, &picture, 0.1);
        assert_eq!(w, CAPTION.len() * GLYPH + 2 * MARGIN);
        assert_eq!(pixels.len(), w * h);
        // The image sits at the top left; white beside it.
        assert_eq!((pixels[0], pixels[w + 3], pixels[4]), ([9, 9, 9], [9, 9, 9], WHITE));
        // The bar runs from full blue to full red through white.
        let bar = (2 + MARGIN + BAR / 2) * w;
        assert_eq!(pixels[bar + MARGIN], [0, 0, 255]);
        assert_eq!(pixels[bar + w - MARGIN - 1], [255, 0, 0]);
        // Some label ink below the bar.
        let labels = (2 + MARGIN + BAR + 2) * w;
        assert!(pixels[labels..labels + GLYPH * w].contains(&BLACK));
    }
}
