//! Rate-distortion plots for `make bench`: one PNG per sequence, RMSE against bpvf on log-log axes,
//! one line per codec, from any number of CSVs in the schema of `scripts/sweep.sh` (mcgv-video rows,
//! encoder variants labelled `CODEC+VARIANT`, e.g. `mpeg4+skinning`) and `scripts/peers.py` (peer
//! codecs). Colour is the encoder variant or the peer, the marker mcgv-video's image codec; the legend
//! sits in a column to the right of the axes.
//!
//! ```text
//! cargo run --release --example rd_plot -- OUT_DIR CSV...
//! ```
//! Writes `OUT_DIR/SEQUENCE.png`. Lossless rows (RMSE 0, zstd) cannot sit on a log axis, so they are
//! drawn as a vertical line at their rate. The font is DejaVu Sans read from
//! `/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf` (Debian's `fonts-dejavu-core`, installed by
//! `make deps`) or from `$MCGV_FONT`, rasterised by `ab_glyph`, so no system fontconfig is needed.

use plotters::coord::CoordTranslate;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use std::collections::BTreeMap;
use std::error::Error;
use std::path::{Path, PathBuf};

type Res<T> = Result<T, Box<dyn Error>>;

const WIDTH: u32 = 1380;
/// Right-hand column holding the legend.
const LEGEND_WIDTH: u32 = 380;
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

/// Marker shapes: mcgv-video's image codecs each have their own, peers share the circle.
#[derive(Clone, Copy)]
enum Marker {
    Circle,
    Triangle,
    Square,
    Diamond,
}

/// How one series is drawn: colour, marker, dashed or solid line, legend text.
struct Look {
    colour: RGBColor,
    marker: Marker,
    dashed: bool,
    label: String,
    /// Legend order: mcgv-video's series first (by image codec, then variant), then peers.
    rank: (u8, u8, String),
}

/// mcgv-video's rows are `CODEC` or `CODEC+VARIANT` (scripts/sweep.sh): the variant sets the colour
/// (default affine + k-means blue, skinning orange, decimation cyan, both brown), the image codec the
/// marker and line (JPEG triangles on a dashed line, MPEG-4 squares, TDCT diamonds; HEVC and AV1
/// squares and their all-intra modes triangles on a dashed line, each in a colour of its own), so
/// every plot reads
/// the same way. Peers keep one fixed colour each, with circles.
fn look(codec: &str, fallback: usize) -> Look {
    let (base, variant) = codec.split_once('+').unwrap_or((codec, ""));
    let ours = [
        "jpeg",
        "mpeg4",
        "tdct",
        "hevc",
        "hevc-intra",
        "av1",
        "av1-intra",
    ]
    .iter()
    .position(|c| *c == base.split('@').next().unwrap_or(base));
    let pick = || {
        let (r, g, b) = Palette99::pick(fallback).to_rgba().rgb();
        RGBColor(r, g, b)
    };
    if let Some(order) = ours {
        let variants = ["", "skinning", "decimation", "skinning+decimation"];
        let v = variants.iter().position(|x| *x == variant);
        let colour = match v {
            // HEVC's and AV1's series apart from the paper's codecs: one colour per mode.
            Some(0) if order == 3 => RGBColor(214, 39, 140),
            Some(0) if order == 4 => RGBColor(120, 60, 160),
            Some(0) if order == 5 => RGBColor(44, 160, 44),
            Some(0) if order == 6 => RGBColor(188, 189, 34),
            Some(0) => RGBColor(31, 119, 180),
            Some(1) => RGBColor(255, 127, 14),
            Some(2) => RGBColor(23, 190, 207),
            Some(3) => RGBColor(140, 86, 75),
            _ => pick(),
        };
        return Look {
            colour,
            marker: [
                Marker::Triangle,
                Marker::Square,
                Marker::Diamond,
                Marker::Square,
                Marker::Triangle,
                Marker::Square,
                Marker::Triangle,
            ][order],
            dashed: base == "jpeg" || base.contains("-intra"),
            label: format!("mcgv-video {codec}"),
            rank: (0, order as u8, format!("{}{variant}", v.unwrap_or(9))),
        };
    }
    let colour = match codec {
        "draco" => RGBColor(214, 39, 40),
        "pca" => RGBColor(44, 160, 44),
        "dynapack" => RGBColor(148, 103, 189),
        "dynapack-ac" => RGBColor(227, 119, 194),
        "gltfpack" => RGBColor(188, 189, 34),
        "gltfpack-br" => RGBColor(107, 110, 0),
        "meshopt-fm" => RGBColor(0, 0, 128),
        "meshopt-vm" => RGBColor(255, 200, 0),
        "zstd" => RGBColor(60, 60, 60),
        _ => pick(),
    };
    Look {
        colour,
        marker: Marker::Circle,
        dashed: false,
        label: if codec == "zstd" {
            "zstd float32 (lossless)".into()
        } else {
            codec.into()
        },
        rank: (1, 0, codec.into()),
    }
}

fn draw_marker<CT: CoordTranslate>(
    area: &DrawingArea<BitMapBackend, CT>,
    at: CT::From,
    marker: Marker,
    colour: RGBColor,
) -> Res<()> {
    let style = colour.filled();
    let at = EmptyElement::at(at);
    match marker {
        Marker::Circle => area.draw(&(at + Circle::new((0, 0), 4, style)))?,
        Marker::Triangle => area.draw(&(at + TriangleMarker::new((0, 0), 6, style)))?,
        Marker::Square => area.draw(&(at + Rectangle::new([(-4, -4), (4, 4)], style)))?,
        Marker::Diamond => {
            area.draw(&(at + Polygon::new(vec![(0, -6), (6, 0), (0, 6), (-6, 0)], style)))?
        }
    }
    Ok(())
}

/// The values m·10^k (m from `mantissas`) within lo..=hi: the rate axis is labelled at 1, 2, 3, 5 of
/// every decade, as plotters' log scale labels only the powers of ten and most rates lie between them.
fn ticks(lo: f64, hi: f64, mantissas: &[f64]) -> Vec<f64> {
    let mut out = vec![];
    for k in lo.log10().floor() as i32..=hi.log10().ceil() as i32 {
        for m in mantissas {
            let v = m * 10f64.powi(k);
            if (lo..=hi).contains(&v) {
                out.push(v);
            }
        }
    }
    out
}

fn plot(path: &Path, sequence: &str, codecs: &BTreeMap<String, Vec<(f64, f64)>>) -> Res<()> {
    let lossy = || codecs.values().flatten().filter(|p| p.0 > 0.0 && p.1 > 0.0);
    let xs = codecs.values().flatten().map(|p| p.0).filter(|x| *x > 0.0);
    let (x0, x1) = xs.fold((f64::MAX, f64::MIN), |(a, b), x| (a.min(x), b.max(x)));
    let (y0, y1) = lossy().fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.1), b.max(p.1)));
    if x0 > x1 || y0 > y1 {
        return Err(format!("{sequence}: no lossy points to plot").into());
    }
    let mut series: Vec<(Look, &Vec<(f64, f64)>)> = codecs
        .iter()
        .enumerate()
        .map(|(i, (codec, points))| (look(codec, i), points))
        .collect();
    series.sort_by(|a, b| a.0.rank.cmp(&b.0.rank));
    let mut buffer = vec![0u8; (WIDTH * HEIGHT * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buffer, (WIDTH, HEIGHT)).into_drawing_area();
        root.fill(&WHITE)?;
        // The legend has its own column on the right, so it never hides a point however many series.
        let (plot_area, legend_area) = root.split_horizontally(WIDTH - LEGEND_WIDTH);
        let mut chart = ChartBuilder::on(&plot_area)
            .caption(format!("{sequence}: RMSE against rate"), ("sans-serif", 26))
            .margin(15)
            .x_label_area_size(50)
            .y_label_area_size(90)
            .build_cartesian_2d(
                (x0 / 1.3..x1 * 1.3)
                    .log_scale()
                    .with_key_points(ticks(x0 / 1.3, x1 * 1.3, &[1.0, 2.0, 3.0, 5.0]))
                    .with_light_points(ticks(x0 / 1.3, x1 * 1.3, &[4.0, 6.0, 7.0, 8.0, 9.0])),
                (y0 / 1.5..y1 * 1.5).log_scale(),
            )?;
        chart
            .configure_mesh()
            .x_desc("bpvf (bits per vertex per frame, whole file)")
            .y_desc("RMSE (fraction of bbox diagonal)")
            .y_label_formatter(&|y| format!("{y:.0e}"))
            .x_label_formatter(&|x| {
                if *x >= 1.0 {
                    format!("{x:.0}")
                } else {
                    format!("{x:.1}")
                }
            })
            .label_style(("sans-serif", 16))
            .axis_desc_style(("sans-serif", 18))
            .draw()?;
        // Peers first, so mcgv-video's series are drawn on top of them.
        for (look, points) in series.iter().rev() {
            let c = look.colour;
            let mut lossy: Vec<(f64, f64)> = points
                .iter()
                .copied()
                .filter(|p| p.0 > 0.0 && p.1 > 0.0)
                .collect();
            lossy.sort_by(|a, b| a.0.total_cmp(&b.0));
            if lossy.is_empty() {
                // Lossless: a vertical line at its rate, the floor every lossy codec must undercut.
                let x = points[0].0;
                chart.draw_series(LineSeries::new(
                    [(x, y0 / 1.5), (x, y1 * 1.5)],
                    c.stroke_width(2),
                ))?;
                continue;
            }
            if look.dashed {
                chart.draw_series(DashedLineSeries::new(
                    lossy.clone(),
                    9,
                    5,
                    c.stroke_width(2),
                ))?;
            } else {
                chart.draw_series(LineSeries::new(lossy.clone(), c.stroke_width(2)))?;
            }
            for &p in &lossy {
                draw_marker(chart.plotting_area(), p, look.marker, c)?;
            }
        }
        for (i, (look, points)) in series.iter().enumerate() {
            let y = 40 + 26 * i as i32;
            let style = look.colour.stroke_width(2);
            if look.dashed {
                legend_area.draw(&DashedPathElement::new([(8, y), (48, y)], 9, 5, style))?;
            } else {
                legend_area.draw(&PathElement::new([(8, y), (48, y)], style))?;
            }
            if points.iter().any(|p| p.1 > 0.0) {
                draw_marker(&legend_area, (28, y), look.marker, look.colour)?;
            }
            legend_area.draw(&Text::new(
                look.label.clone(),
                (56, y - 9),
                ("sans-serif", 16),
            ))?;
        }
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
