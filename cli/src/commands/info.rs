//! `mcgv-video info`: what an animation is made of, as text or one JSON object.

use crate::args::InfoArgs;
use mcgv_video::error::{Error, Result};
use mcgv_video::mesh::{read_animation, Point, ReadOptions, Summary};
use std::time::Instant;

/// What `info` reports; the field names are the JSON keys.
#[derive(serde::Serialize)]
struct Info {
    #[serde(flatten)]
    summary: Summary,
    /// Seconds spent reading the input.
    read_seconds: f64,
}

/// Runs `info`.
pub fn run(args: &InfoArgs, _quiet: bool) -> Result<()> {
    let start = Instant::now();
    let mesh = read_animation(&args.input, &ReadOptions::from(&args.input_args))?;
    let info = Info {
        summary: Summary::of(&mesh),
        read_seconds: start.elapsed().as_secs_f64(),
    };
    if args.json {
        let text = serde_json::to_string(&info)
            .map_err(|e| Error::Usage(format!("cannot print JSON: {e}")))?;
        println!("{text}");
        return Ok(());
    }
    let read_seconds = info.read_seconds;
    let info = info.summary;
    let r = &info.manifold_report;
    let point = |p: Point| format!("({} {} {})", p[0], p[1], p[2]);
    println!("{}", args.input);
    println!("  vertices (V)   {}", info.vertices);
    println!("  frames (F)     {}", info.frames);
    println!("  faces          {}", info.faces);
    println!("  components     {}", info.components);
    println!(
        "  manifold       {} ({} non-manifold edges, {} non-manifold vertices, {} boundary edges, \
         {} degenerate triangles, {} isolated vertices)",
        if info.manifold { "yes" } else { "no" },
        r.non_manifold_edges,
        r.non_manifold_vertices,
        r.boundary_edges,
        r.degenerate_triangles,
        r.isolated_vertices
    );
    println!(
        "  bounding box   {} – {} (frame 0), diagonal {}",
        point(info.bbox_min),
        point(info.bbox_max),
        info.bbox_diagonal
    );
    println!(
        "  all frames     {} – {}",
        point(info.animation_bbox_min),
        point(info.animation_bbox_max)
    );
    println!("  read in        {:.3} s", read_seconds);
    Ok(())
}
