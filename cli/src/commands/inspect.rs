//! `mcgv-video inspect`.

use crate::annotate;
use crate::args::InspectArgs;
use crate::staging::StagedFolder;
use mcgv_video::codec::Description;
use mcgv_video::codec::Plane;
use mcgv_video::inspect::FrameRanges;
use mcgv_video::Decoder;
use mcgv_video::Header;
use mcgv_video::{Error, Result};
use std::path::Path;

/// Runs `inspect`.
pub fn run(args: &InspectArgs, quiet: bool) -> Result<()> {
    let options = super::decode::decode_options(None, args.input_args.max_positions);
    let mut decoder =
        Decoder::open_with(&args.input, &options).map_err(|e| super::in_file(&args.input, e))?;
    let segments = decoder.segments().to_vec();
    // The codec figures (bit depth, bands, step) are the first segment's.
    decoder
        .seek_segment(0)
        .map_err(|e| super::in_file(&args.input, e))?;
    let stored = decoder
        .describe()
        .ok_or_else(|| Error::Stream("no segment is open".into()))?;
    let header = decoder.header().clone();
    let total = decoder.file_len();
    let parts = decoder.part_bytes();
    if let Some(dir) = &args.png {
        let Some(pictures) = &stored.pictures else {
            return Err(Error::option(
                "png",
                format!(
                    "applies to streams of geometry images: a {} stream has none (its figures \
                     are in the plain and --json output)",
                    stored.codec.name()
                ),
            ));
        };
        write_pngs(&mut decoder, pictures.lattice, args, dir, quiet)?;
    }
    let report = Report {
        header: &header,
        stored: &stored,
        parts: &parts,
        total,
        segments: &segments,
    };
    if args.json {
        return outln!("{}", report.json(decoder.weights().map(|w| w.bits)));
    }
    outln!("{}", summary(&header, &stored, &args.input))?;
    report.print_table()
}

/// What `inspect` prints of a stream: its header, what its codec stored, the bytes of each part.
struct Report<'a> {
    header: &'a Header,
    stored: &'a Description,
    parts: &'a [(String, u64)],
    total: u64,
    segments: &'a [std::ops::Range<usize>],
}

impl Report<'_> {
    fn bpvf(&self) -> f64 {
        self.total as f64 * 8.0 / self.vertex_frames()
    }

    fn vertex_frames(&self) -> f64 {
        self.header.vertices as f64 * self.header.frames as f64
    }

    /// The `--json` object; `weight_bits` those of the skinning weights, if any.
    fn json(&self, weight_bits: Option<u8>) -> serde_json::Value {
        let (header, stored) = (self.header, self.stored);
        let parts_obj: serde_json::Map<String, serde_json::Value> = (self.parts.iter())
            .map(|(n, b)| (n.clone(), serde_json::json!(b * 8)))
            .collect();
        let pictures = stored.pictures.as_ref();
        let bands = stored.bands.as_ref();
        let mut value = serde_json::json!({
            "vertices": header.vertices,
            "frames": header.frames,
            "faces": header.triangles,
            "codec": stored.codec.name(),
            "quality": header.quality,
            "bit_depth": pictures.map(|p| p.bit_depth),
            "clusters": header.clusters,
            "predictor": header.predictor.name(),
            "weight_bits": weight_bits,
            "charts": pictures.map_or(0, |p| p.charts),
            "lattice": pictures.map_or((0, 0), |p| p.lattice),
            "packing_efficiency": pictures.map_or(0.0, |p| p.packing_efficiency),
            "padding": pictures.map(|p| p.padding),
            "bytes": self.total,
            "bpvf": self.bpvf(),
            "parts": parts_obj,
            "segments": self.segments.len(),
            "band_bytes": bands.map(|b| &b.lengths),
            "step": bands.map(|b| b.step),
        });
        for (name, setting) in &stored.settings {
            value[*name] = serde_json::json!(setting);
        }
        value
    }

    /// The plain output after the summary line: segments, the parts' table, the bands.
    fn print_table(&self) -> Result<()> {
        let (segments, total, vf) = (self.segments, self.total, self.vertex_frames());
        if segments.len() > 1 {
            outln!(
                "{} temporal segments of up to {} frames (parts of a kind summed; bands of the first)",
                segments.len(),
                segments[0].len()
            )?;
        }
        // As wide as the longest part's name ("temporal DCT coefficients" overflowed 22).
        let w = (self.parts.iter().map(|(n, _)| n.chars().count())).fold(22, usize::max);
        outln!(
            "{:<w$} {:>12} {:>14} {:>7} {:>8}",
            "part",
            "bytes",
            "bits",
            "%",
            "bpvf"
        )?;
        for (name, bytes) in self.parts {
            outln!(
                "{:<w$} {:>12} {:>14} {:>6.2}% {:>8.4}",
                name,
                bytes,
                bytes * 8,
                100.0 * *bytes as f64 / total as f64,
                *bytes as f64 * 8.0 / vf
            )?;
        }
        outln!(
            "{:<w$} {:>12} {:>14} {:>6.2}% {:>8.4}",
            "total",
            total,
            total * 8,
            100.0,
            self.bpvf()
        )?;
        if let Some(bands) = &self.stored.bands {
            out!("{}", band_table(&bands.lengths, bands.decoded))?;
        }
        Ok(())
    }
}

/// Bands shown one by one in the plain `inspect` output; the rest are summed.
const BANDS_LISTED: usize = 12;

/// The temporal-DCT bands: bytes of the first bands, and how many bands (low to high, the order a
/// truncated stream keeps) hold 50, 90, 99 and 100 % of the coefficient bytes.
fn band_table(bands: &[u64], decoded: usize) -> String {
    let total: u64 = bands.iter().sum();
    let mut s = format!(
        "temporal DCT: {} bands, {} of them empty, {total} bytes; {decoded} decodable\n",
        bands.len(),
        bands.iter().filter(|&&b| b == 0).count()
    );
    s.push_str(&format!(
        "{:<10} {:>10} {:>12}\n",
        "band", "bytes", "cumulative"
    ));
    let mut sum = 0u64;
    for (k, &b) in bands.iter().enumerate().take(BANDS_LISTED) {
        sum += b;
        s.push_str(&format!(
            "{k:<10} {b:>10} {:>11.1}%\n",
            100.0 * sum as f64 / total.max(1) as f64
        ));
    }
    if bands.len() > BANDS_LISTED {
        let rest: u64 = bands[BANDS_LISTED..].iter().sum();
        s.push_str(&format!(
            "{:<10} {rest:>10} {:>11.1}%\n",
            format!("{}..{}", BANDS_LISTED, bands.len() - 1),
            100.0
        ));
    }
    for share in [50.0, 90.0, 99.0, 100.0] {
        let mut sum = 0u64;
        let needed = bands
            .iter()
            .position(|&b| {
                sum += b;
                sum as f64 >= share / 100.0 * total as f64
            })
            .map_or(0, |k| k + 1);
        s.push_str(&format!(
            "{share:>5.0} % of the bytes in the first {needed} bands\n"
        ));
    }
    s
}

/// One line: the animation, the codec and its settings, the motion model, and the pictures'
/// lattice and atlas (or bands).
fn summary(h: &Header, stored: &Description, path: &Path) -> String {
    let settings: Vec<String> = stored
        .settings
        .iter()
        .map(|(name, value)| format!("{name} {value}"))
        .collect();
    let settings = match settings.is_empty() {
        true => String::new(),
        false => format!(" ({})", settings.join(", ")),
    };
    let residuals = match (&stored.pictures, &stored.bands) {
        (Some(p), _) => format!(
            "{} charts in {}x{} (packing {:.1}%), padding {}",
            p.charts,
            p.lattice.0,
            p.lattice.1,
            100.0 * p.packing_efficiency,
            p.padding
        ),
        (None, Some(b)) => format!("{} frequency bands, no atlas", b.lengths.len()),
        (None, None) => "no atlas".into(),
    };
    format!(
        "{}: {} vertices x {}, {}; {} quality {}{settings}; {}, {} predictor; {residuals}",
        path.display(),
        h.vertices,
        crate::output::count(h.frames, "frame"),
        crate::output::count(h.triangles, "face"),
        stored.codec.name(),
        h.quality,
        crate::output::count(h.clusters, "cluster"),
        h.predictor.name(),
    )
}

/// Writes a residual image (levels, x | y | z side by side) with its panels labelled and a scale
/// bar in model units from the frame's ranges.
/// Samples deeper than 8 bits are shown by their 8 high bits.
fn save_residuals(
    path: &Path,
    plane: Plane<u16>,
    w: usize,
    title: &str,
    ranges: Option<&FrameRanges>,
) -> Result<()> {
    let shift = ranges.map_or(0, |r| r[0].depth.saturating_sub(8));
    let data = plane
        .data
        .iter()
        .map(|&v| (v >> shift).min(255) as u8)
        .collect();
    let grey = image::GrayImage::from_raw(plane.width, plane.height, data)
        .ok_or_else(|| Error::Usage("image size mismatch".into()))?;
    annotate::residual_picture(&grey, w as u32, title, ranges)
        .save(path)
        .map_err(|e| Error::Usage(format!("{}: {e}", path.display())))
}

/// The atlas of a `lattice` as the decoder sees it, with a legend of the cluster colours.
fn write_atlas<R: std::io::Read + std::io::Seek>(
    decoder: &Decoder<R>,
    lattice: (u16, u16),
    path: &Path,
) -> Result<()> {
    let header = decoder.header();
    let (w, h) = (usize::from(lattice.0), usize::from(lattice.1));
    // The atlas as the decoder sees it: each vertex pixel in its cluster's colour, the 8×8 grid dimmed.
    let mut atlas_rgb = vec![0u8; w * h * 3];
    for y in 0..h {
        for x in 0..w {
            if x % 8 == 0 || y % 8 == 0 {
                atlas_rgb[(y * w + x) * 3..][..3].copy_from_slice(&[40, 40, 40]);
            }
        }
    }
    for (v, &[u, py]) in decoder.vertex_pixels().iter().enumerate() {
        let c = annotate::cluster_colour(decoder.partition().labels()[v]);
        atlas_rgb[(py as usize * w + u as usize) * 3..][..3].copy_from_slice(&c);
    }
    let atlas = image::RgbImage::from_raw(w as u32, h as u32, atlas_rgb)
        .ok_or_else(|| Error::Usage("atlas image size".into()))?;
    let note = "vertex pixels by cluster; grid: 8x8 blocks";
    annotate::with_legend(&atlas, header.clusters, note)
        .save(path)
        .map_err(|e| Error::Usage(format!("{}: {e}", path.display())))
}

/// Writes the atlas, the segmentation and the chosen frames' residual images into `dir`, staged
/// and put in place once every image is written; the folder is checked before any is made.
fn write_pngs<R: std::io::Read + std::io::Seek>(
    decoder: &mut Decoder<R>,
    lattice: (u16, u16),
    args: &InspectArgs,
    dir: &Path,
    quiet: bool,
) -> Result<()> {
    let header = decoder.header().clone();
    let w = usize::from(lattice.0);
    let frames = match &args.frames {
        Some(frames) => frames.resolve(header.frames as usize, "frames")?,
        None => vec![0],
    };
    let staged =
        StagedFolder::prepare(dir, png_names(&frames, args.original.is_some()), args.force)?;
    let out = staged.path();
    write_atlas(decoder, lattice, &out.join("atlas.png"))?;
    crate::render::render_partition_png(
        decoder.reference(),
        decoder.triangles(),
        decoder.partition().labels(),
        512,
        &out.join("segmentation.png"),
    )?;
    for &f in &frames {
        let plane = decoder.decoded_plane(f)?;
        let ranges = decoder.frame_ranges(f)?;
        save_residuals(
            &out.join(png_name(f, "decoded")),
            plane,
            w,
            &format!("frame {f} decoded residuals"),
            ranges.as_ref(),
        )?;
    }
    if let Some(original) = &args.original {
        write_encoder_pngs(decoder, lattice, args, (original, out), &frames, quiet)?;
    }
    staged.commit_and_tell(quiet)?;
    if !quiet {
        eprintln!("images written to {}", dir.display());
    }
    Ok(())
}

/// The file of frame `f`'s residual image of `kind` (`decoded`, `raw`, `padded`).
fn png_name(f: usize, kind: &str) -> String {
    format!("frame_{f:04}_{kind}.png")
}

/// Every image `--png` writes for `frames` (with the encoder's own when `original`).
fn png_names(frames: &[usize], original: bool) -> Vec<String> {
    let kinds: &[&str] = match original {
        true => &["decoded", "raw", "padded"],
        false => &["decoded"],
    };
    let mut names = vec!["atlas.png".to_string(), "segmentation.png".to_string()];
    for &f in frames {
        names.extend(kinds.iter().map(|kind| png_name(f, kind)));
    }
    names
}

/// The residual images the encoder made (raw and padded) for `frames`, redone from `original`.
fn write_encoder_pngs<R: std::io::Read + std::io::Seek>(
    decoder: &Decoder<R>,
    lattice: (u16, u16),
    args: &InspectArgs,
    (original, dir): (&str, &Path),
    frames: &[usize],
    quiet: bool,
) -> Result<()> {
    let w = usize::from(lattice.0);
    let mesh = super::read_input(original, &(&args.input_args).into(), quiet)?;
    let ranges = decoder.ranges().to_vec();
    for images in mcgv_video::inspect::encoder_images(decoder, &mesh, frames)? {
        let f = images.frame;
        for (kind, plane) in [("raw", images.raw), ("padded", images.padded)] {
            save_residuals(
                &dir.join(png_name(f, kind)),
                plane,
                w,
                &format!("frame {f} {kind} residuals (encoder)"),
                ranges.get(f),
            )?;
        }
    }
    Ok(())
}
