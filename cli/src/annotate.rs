//! Labels on the `inspect --png` pictures, so that they read without the README: the x | y | z
//! panels of a residual image named, each with a grey scale bar in model units; the atlas and the
//! segmentation with a legend of cluster colours.
//!
//! Text is drawn with the public-domain 8×8 bitmap font of the `font8x8` crate (ASCII, no
//! dependencies, no font file to find at run time): a few labels do not need a font rasteriser.

use image::{GrayImage, Rgb, RgbImage};
use mcgv_video::inspect::FrameRanges;

const WHITE: Rgb<u8> = Rgb([255, 255, 255]);
const INK: Rgb<u8> = Rgb([0, 0, 0]);
const ZERO_MARK: Rgb<u8> = Rgb([220, 30, 30]);
/// Height of a line of text, 8-pixel glyphs and 2 pixels of leading.
const LINE: u32 = 10;
/// White space between the panels of a residual image.
const GAP: u32 = 6;

/// A distinct, saturated colour per cluster (golden-angle hues): the atlas, the segmentation and
/// their legends share it.
pub fn cluster_colour(k: u32) -> [u8; 3] {
    let h = (k as f32 * 137.507_77) % 360.0;
    let (s, v) = (0.75f32, 0.95f32);
    let c = v * s;
    let x = c * (1.0 - ((h / 60.0) % 2.0 - 1.0).abs());
    let (r, g, b) = match (h / 60.0) as u32 {
        0 => (c, x, 0.0),
        1 => (x, c, 0.0),
        2 => (0.0, c, x),
        3 => (0.0, x, c),
        4 => (x, 0.0, c),
        _ => (c, 0.0, x),
    };
    let m = v - c;
    [
        ((r + m) * 255.0) as u8,
        ((g + m) * 255.0) as u8,
        ((b + m) * 255.0) as u8,
    ]
}

/// Draws `text` with its top-left corner at (x, y); what falls outside the image is clipped.
pub fn draw_text(image: &mut RgbImage, x: i64, y: i64, text: &str, colour: Rgb<u8>) {
    for (i, ch) in text.chars().enumerate() {
        let glyph = font8x8::legacy::BASIC_LEGACY
            .get(ch as usize)
            .copied()
            .unwrap_or([0; 8]);
        for (row, bits) in glyph.iter().enumerate() {
            for col in 0..8 {
                if bits & (1 << col) == 0 {
                    continue;
                }
                let (px, py) = (x + i as i64 * 8 + col, y + row as i64);
                if px >= 0 && py >= 0 && px < image.width() as i64 && py < image.height() as i64 {
                    image.put_pixel(px as u32, py as u32, colour);
                }
            }
        }
    }
}

/// A residual value in model units, short: `+1.23e-3`.
fn units(v: f32) -> String {
    if v == 0.0 {
        "0".into()
    } else {
        format!("{v:+.2e}")
    }
}

/// A residual image (x | y | z side by side in `plane`, each `w` wide) labelled: a title line, the
/// axis over each panel, and under each a grey bar from level 0 to 255 with the residuals (model
/// units) they stand for at its ends, zero marked in red, and the size of one grey level.
pub fn residual_picture(
    plane: &GrayImage,
    w: u32,
    title: &str,
    ranges: Option<&FrameRanges>,
) -> RgbImage {
    let h = plane.height();
    let top = 2 * LINE;
    let bar = 8;
    let below = if ranges.is_some() { bar + 3 * LINE } else { 0 };
    let width = 3 * w + 2 * GAP;
    let mut image = RgbImage::from_pixel(width, top + h + below + 2, WHITE);
    draw_text(&mut image, 0, 0, title, INK);
    for axis in 0..3u32 {
        let x0 = axis * (w + GAP);
        for y in 0..h {
            for x in 0..w {
                let g = plane.get_pixel(axis * w + x, y).0[0];
                image.put_pixel(x0 + x, top + y, Rgb([g, g, g]));
            }
        }
        let name = ["x", "y", "z"][axis as usize];
        draw_text(&mut image, (x0 + w / 2) as i64 - 4, LINE as i64, name, INK);
        let Some(range) = ranges.map(|r| r[axis as usize]) else {
            continue;
        };
        let y0 = top + h + 2;
        for x in 0..w {
            let level = (x as f32 / (w - 1).max(1) as f32 * 255.0).round() as u8;
            for y in y0..y0 + bar {
                image.put_pixel(x0 + x, y, Rgb([level, level, level]));
            }
        }
        let (min, max) = (range.min(), range.max());
        if min < 0.0 && max > 0.0 {
            let zero = (-min / (max - min) * (w - 1) as f32).round() as u32;
            for y in y0 - 2..y0 + bar + 2 {
                image.put_pixel(x0 + zero, y, ZERO_MARK);
            }
        }
        let lo = units(min);
        let hi = units(max);
        let text_y = (y0 + bar + 1) as i64;
        draw_text(&mut image, x0 as i64, text_y, &lo, INK);
        let right = (x0 + w) as i64 - 8 * hi.len() as i64;
        draw_text(&mut image, right, text_y + LINE as i64, &hi, INK);
        let step = format!("1 level {:.1e}", range.step);
        draw_text(&mut image, x0 as i64, text_y + 2 * LINE as i64, &step, INK);
    }
    image
}

/// `image` with a legend appended below: a line of `note`, then a swatch and the number of every
/// cluster `0..clusters`, wrapped to the image's width.
pub fn with_legend(image: &RgbImage, clusters: u32, note: &str) -> RgbImage {
    let entry = |k: u32| 8 + 4 + 8 * k.to_string().len() as u32 + 8;
    let width = image.width().max(8 * note.len() as u32);
    let (mut rows, mut x) = (1u32, 0u32);
    for k in 0..clusters {
        if x + entry(k) > width && x > 0 {
            rows += 1;
            x = 0;
        }
        x += entry(k);
    }
    let height = image.height() + LINE * (rows + 1) + 4;
    let mut out = RgbImage::from_pixel(width, height, WHITE);
    image::imageops::replace(&mut out, image, 0, 0);
    let mut y = image.height() + 2;
    draw_text(&mut out, 0, y as i64, note, INK);
    y += LINE;
    let mut x = 0u32;
    for k in 0..clusters {
        if x + entry(k) > width && x > 0 {
            y += LINE;
            x = 0;
        }
        let colour = Rgb(cluster_colour(k));
        for dy in 0..8 {
            for dx in 0..8 {
                out.put_pixel(x + dx, y + dy, colour);
            }
        }
        draw_text(&mut out, (x + 12) as i64, y as i64, &k.to_string(), INK);
        x += entry(k);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_is_drawn_and_clipped() {
        let mut image = RgbImage::from_pixel(20, 10, WHITE);
        draw_text(&mut image, 0, 0, "x0", INK);
        draw_text(&mut image, 15, 5, "long text past the edge", INK);
        assert!(image.pixels().any(|p| *p == INK));
    }

    #[test]
    fn residual_picture_has_three_labelled_panels_and_a_scale() {
        let plane = GrayImage::from_fn(3 * 64, 16, |x, _| image::Luma([(x % 256) as u8]));
        let range = mcgv_video::inspect::AxisRange::new(0.01, 20);
        let picture = residual_picture(&plane, 64, "frame 0", Some(&[range; 3]));
        assert_eq!(picture.width(), 3 * 64 + 2 * GAP);
        assert!(picture.pixels().any(|p| *p == ZERO_MARK));
        assert_eq!(units(-0.5), "-5.00e-1");
    }
}
