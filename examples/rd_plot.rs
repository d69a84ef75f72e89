//! Rate-distortion plots for `make bench`: one PNG per sequence, RMSE against bpvf on log-log axes,
//! one line per codec, from any number of CSVs in the schema of `scripts/sweep.sh` (mcgv-video rows)
//! and `scripts/peers.py` (peer codecs).
//!
//! ```text
//! cargo run --release --example rd_plot -- OUT_DIR CSV...
//! ```
//! Writes `OUT_DIR/SEQUENCE.png`. Lossless rows (RMSE 0, zstd) cannot sit on a log axis, so they are
//! drawn as a vertical line at their rate. The font is DejaVu Sans read from
//! `/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf` (Debian's `fonts-dejavu-core`, installed by
//! `make deps`) or from `$MCGV_FONT`, rasterised by `ab_glyph`, so no system fontconfig is needed.

use plotters::prelude::*;
use std::collections::BTreeMap;
use std::error::Error;
use std::path::{Path, PathBuf};

type Res<T> = Result<T, Box<dyn Error>>;

const WIDTH: u32 = 1000;
const HEIGHT: u32 = 700;
const DEFAULT_FONT: &str = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";

/// Sequence → codec → (bpvf, rmse) points.
type Table = BTreeMap<String, BTreeMap<String, Vec<(f64, f64)>>>;

fn read_csvs(paths: &[PathBuf]) -> Res<Table> {
    let mut table = Table::new();
    for path in paths {
        let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let mut lines = text.lines();
        let header: Vec<&str> = lines.next().ok_or("empty CSV")?.split(',').collect();
        let column = |name: &str| {
            header
                .iter()
                .position(|h| *h == name)
                .ok_or_else(|| format!("{}: no column `{name}`", path.display()))
        };
        let (seq, codec, bpvf, rmse) = (
            column("sequence")?,
            column("codec")?,
            column("bpvf")?,
            column("rmse")?,
        );
        for (n, line) in lines.enumerate() {
            if line.trim().is_empty() {
                continue;
            }
            let cells: Vec<&str> = line.split(',').collect();
            if cells.len() != header.len() {
                return Err(
                    format!("{}: line {}: wrong number of cells", path.display(), n + 2).into(),
                );
            }
            let number = |i: usize| -> Res<f64> {
                cells[i].parse::<f64>().map_err(|e| {
                    format!("{}: line {}: `{}`: {e}", path.display(), n + 2, cells[i]).into()
                })
            };
            table
                .entry(cells[seq].to_string())
                .or_default()
                .entry(cells[codec].to_string())
                .or_default()
                .push((number(bpvf)?, number(rmse)?));
        }
    }
    Ok(table)
}

/// A fixed colour per known codec, so every plot reads the same way.
fn colour(codec: &str, fallback: usize) -> RGBColor {
    match codec {
        "jpeg" => RGBColor(31, 119, 180),
        "mpeg4" => RGBColor(255, 127, 14),
        "draco" => RGBColor(214, 39, 40),
        "pca" => RGBColor(44, 160, 44),
        "dynapack" => RGBColor(148, 103, 189),
        "zstd" => RGBColor(60, 60, 60),
        _ => {
            let (r, g, b) = Palette99::pick(fallback).to_rgba().rgb();
            RGBColor(r, g, b)
        }
    }
}

/// Lines of mcgv-video's own codecs carry the tool's name, so a reader sees which lines are ours.
fn label(codec: &str) -> String {
    match codec {
        "jpeg" | "mpeg4" => format!("mcgv-video {codec}"),
        "zstd" => "zstd float32 (lossless)".into(),
        other => other.into(),
    }
}

fn plot(path: &Path, sequence: &str, codecs: &BTreeMap<String, Vec<(f64, f64)>>) -> Res<()> {
    let lossy = || codecs.values().flatten().filter(|p| p.0 > 0.0 && p.1 > 0.0);
    let xs = codecs.values().flatten().map(|p| p.0).filter(|x| *x > 0.0);
    let (x0, x1) = xs.fold((f64::MAX, f64::MIN), |(a, b), x| (a.min(x), b.max(x)));
    let (y0, y1) = lossy().fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.1), b.max(p.1)));
    if x0 > x1 || y0 > y1 {
        return Err(format!("{sequence}: no lossy points to plot").into());
    }
    let mut buffer = vec![0u8; (WIDTH * HEIGHT * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buffer, (WIDTH, HEIGHT)).into_drawing_area();
        root.fill(&WHITE)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(format!("{sequence}: RMSE against rate"), ("sans-serif", 26))
            .margin(15)
            .x_label_area_size(50)
            .y_label_area_size(90)
            .build_cartesian_2d(
                (x0 / 1.3..x1 * 1.3).log_scale(),
                (y0 / 1.5..y1 * 1.5).log_scale(),
            )?;
        chart
            .configure_mesh()
            .x_desc("bpvf (bits per vertex per frame, whole file)")
            .y_desc("RMSE (fraction of bbox diagonal)")
            .y_label_formatter(&|y| format!("{y:.0e}"))
            .x_label_formatter(&|x| format!("{x}"))
            .label_style(("sans-serif", 16))
            .axis_desc_style(("sans-serif", 18))
            .draw()?;
        for (i, (codec, points)) in codecs.iter().enumerate() {
            let c = colour(codec, i);
            let mut lossy: Vec<(f64, f64)> = points
                .iter()
                .copied()
                .filter(|p| p.0 > 0.0 && p.1 > 0.0)
                .collect();
            lossy.sort_by(|a, b| a.0.total_cmp(&b.0));
            if lossy.is_empty() {
                // Lossless: a vertical line at its rate, the floor every lossy codec must undercut.
                let x = points[0].0;
                chart
                    .draw_series(LineSeries::new(
                        [(x, y0 / 1.5), (x, y1 * 1.5)],
                        c.stroke_width(2),
                    ))?
                    .label(label(codec))
                    .legend(move |(x, y)| {
                        PathElement::new([(x, y), (x + 20, y)], c.stroke_width(2))
                    });
                continue;
            }
            chart
                .draw_series(LineSeries::new(lossy.clone(), c.stroke_width(2)))?
                .label(label(codec))
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], c.stroke_width(2)));
            chart.draw_series(lossy.iter().map(|&p| Circle::new(p, 4, c.filled())))?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 16))
            .position(SeriesLabelPosition::UpperRight)
            .draw()?;
        root.present()?;
    }
    image::save_buffer(path, &buffer, WIDTH, HEIGHT, image::ColorType::Rgb8)?;
    Ok(())
}

fn main() -> Res<()> {
    let args: Vec<PathBuf> = std::env::args_os().skip(1).map(PathBuf::from).collect();
    if args.len() < 2 {
        return Err("usage: rd_plot OUT_DIR CSV...".into());
    }
    let font_path = std::env::var("MCGV_FONT").unwrap_or_else(|_| DEFAULT_FONT.into());
    let font = std::fs::read(&font_path)
        .map_err(|e| format!("{font_path}: {e} (install fonts-dejavu-core or set MCGV_FONT)"))?;
    // plotters keeps fonts for the whole run and wants 'static bytes: leaking one file is that.
    plotters::style::register_font(
        "sans-serif",
        FontStyle::Normal,
        Box::leak(font.into_boxed_slice()),
    )
    .map_err(|_| format!("{font_path}: not a font ab_glyph can read"))?;
    let out = &args[0];
    std::fs::create_dir_all(out)?;
    for (sequence, codecs) in read_csvs(&args[1..])? {
        let path = out.join(format!("{sequence}.png"));
        plot(&path, &sequence, &codecs)?;
        println!("{}", path.display());
    }
    Ok(())
}
