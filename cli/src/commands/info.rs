//! `mcgv-video info`: what an animation is made of, as text or one JSON object.

use crate::args::InfoArgs;
use mcgv_video::error::{Error, Result};
use mcgv_video::mesh::topology::{ManifoldReport, VertexAdjacency};
use mcgv_video::mesh::{bounding_box, read_animation, AnimatedMesh, Point, ReadOptions};
use std::time::Instant;

/// What `info` reports; the field names are the JSON keys.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Info {
    /// Vertices per frame (V).
    pub vertices: usize,
    /// Frames (F).
    pub frames: usize,
    /// Triangles shared by all frames.
    pub faces: usize,
    /// Connected components (isolated vertices count as components).
    pub components: usize,
    /// Whether every edge has at most two triangles, every vertex one fan, no triangle degenerate.
    pub manifold: bool,
    /// The details behind `manifold`.
    pub manifold_report: ManifoldReport,
    /// Frame 0's bounding box, minimum corner.
    pub bbox_min: Point,
    /// Frame 0's bounding box, maximum corner.
    pub bbox_max: Point,
    /// Frame 0's bounding-box diagonal: the unit the error measures use.
    pub bbox_diagonal: f64,
    /// Bounding box of all frames together, minimum corner.
    pub animation_bbox_min: Point,
    /// Bounding box of all frames together, maximum corner.
    pub animation_bbox_max: Point,
    /// Seconds spent reading the input.
    pub read_seconds: f64,
}

impl Info {
    /// Measures `mesh`; `read_seconds` is how long reading it took.
    pub fn of(mesh: &AnimatedMesh, read_seconds: f64) -> Self {
        let v = mesh.vertex_count();
        let triangles = mesh.triangles();
        let (_, components) = VertexAdjacency::new(v, triangles).components();
        let manifold_report = ManifoldReport::new(v, triangles);
        let (bbox_min, bbox_max) = bounding_box(mesh.frame(0));
        let (animation_bbox_min, animation_bbox_max) = mesh
            .frames()
            .iter()
            .map(|f| bounding_box(f))
            .reduce(|(lo, hi), (l, h)| {
                (
                    [lo[0].min(l[0]), lo[1].min(l[1]), lo[2].min(l[2])],
                    [hi[0].max(h[0]), hi[1].max(h[1]), hi[2].max(h[2])],
                )
            })
            .unwrap_or((bbox_min, bbox_max));
        Self {
            vertices: v,
            frames: mesh.frame_count(),
            faces: triangles.len(),
            components,
            manifold: manifold_report.is_manifold(),
            manifold_report,
            bbox_min,
            bbox_max,
            bbox_diagonal: mesh.bbox_diagonal(),
            animation_bbox_min,
            animation_bbox_max,
            read_seconds,
        }
    }
}

/// Runs `info`.
pub fn run(args: &InfoArgs, _quiet: bool) -> Result<()> {
    let start = Instant::now();
    let mesh = read_animation(&args.input, &ReadOptions::from(&args.input_args))?;
    let info = Info::of(&mesh, start.elapsed().as_secs_f64());
    if args.json {
        let text = serde_json::to_string(&info)
            .map_err(|e| Error::Usage(format!("cannot print JSON: {e}")))?;
        println!("{text}");
        return Ok(());
    }
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
    println!("  read in        {:.3} s", info.read_seconds);
    Ok(())
}
