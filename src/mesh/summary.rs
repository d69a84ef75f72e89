//! A summary of an animation: vertex, frame, face and component counts, manifoldness and
//! bounding boxes.

use super::topology::{ManifoldReport, VertexAdjacency};
use super::{bounding_box, AnimatedMesh, Point};

/// What an animation is made of: counts, topology and bounding boxes (serialisable; the field
/// names are the keys of `mcgv-video info --json`).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Summary {
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
}

impl Summary {
    /// Measures `mesh`.
    pub fn of(mesh: &AnimatedMesh) -> Self {
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
        }
    }
}
