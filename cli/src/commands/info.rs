//! `mcgv-video info`: what an animation is made of, as text or one JSON object.

use crate::args::InfoArgs;
use mcgv_video::mesh::{clips, Clip, Point, ReadOptions, Summary};
use mcgv_video::{Error, Result};
use std::time::Instant;

/// What `info` reports; the field names are the JSON keys.
#[derive(serde::Serialize)]
struct Info {
    #[serde(flatten)]
    summary: Summary,
    /// Seconds spent reading the input.
    read_seconds: f64,
    /// The glTF file's clips (empty for other inputs); the one read is `clip` (default 0).
    clips: Vec<Clip>,
}

/// Runs `info`.
pub fn run(args: &InfoArgs, _quiet: bool) -> Result<()> {
    let start = Instant::now();
    let opts = ReadOptions::from(&args.input_args);
    // `info` lists every clip itself: no note about which one was taken.
    let mesh = super::read_input(&args.input, &opts, true)?;
    let info = Info {
        summary: Summary::of(&mesh),
        read_seconds: start.elapsed().as_secs_f64(),
        clips: clips(&args.input, opts.fps)?,
    };
    if args.json {
        let text = serde_json::to_string(&info)
            .map_err(|e| Error::Usage(format!("cannot print JSON: {e}")))?;
        return outln!("{text}");
    }
    let read_seconds = info.read_seconds;
    let clip_lines = clip_lines(&info.clips, opts.clip.as_deref());
    let info = info.summary;
    let r = &info.manifold_report;
    let point = |p: Point| format!("({} {} {})", p[0], p[1], p[2]);
    outln!("{}", args.input)?;
    outln!("  vertices (V)   {}", info.vertices)?;
    outln!("  frames (F)     {}", info.frames)?;
    outln!("  faces          {}", info.faces)?;
    outln!("  components     {}", info.components)?;
    outln!(
        "  manifold       {} ({} non-manifold edges, {} non-manifold vertices, {} boundary edges, \
         {} degenerate triangles, {} isolated vertices)",
        if info.manifold { "yes" } else { "no" },
        r.non_manifold_edges,
        r.non_manifold_vertices,
        r.boundary_edges,
        r.degenerate_triangles,
        r.isolated_vertices
    )?;
    outln!(
        "  bounding box   {} – {} (frame 0), diagonal {}",
        point(info.bbox_min),
        point(info.bbox_max),
        info.bbox_diagonal
    )?;
    outln!(
        "  all frames     {} – {}",
        point(info.animation_bbox_min),
        point(info.animation_bbox_max)
    )?;
    out!("{clip_lines}")?;
    outln!("  read in        {:.3} s", read_seconds)
}

/// One line per glTF clip, the one read marked with `*`.
fn clip_lines(clips: &[Clip], chosen: Option<&str>) -> String {
    let mut s = String::new();
    for (i, c) in clips.iter().enumerate() {
        let read = match chosen {
            None => i == 0,
            Some(name) => name == c.name || name == c.index.to_string(),
        };
        s.push_str(&format!(
            "  {:<14} {} `{}`: {} frames at {} fps ({:.2} s){}\n",
            if i == 0 { "clips" } else { "" },
            c.index,
            c.name,
            c.frames,
            c.fps,
            c.seconds,
            if read { "  * read" } else { "" }
        ));
    }
    s
}
