//! Multi-chart geometry-image atlas (MCGV paper §3.3, first half).
//!
//! [`build`] turns a mesh (positions and triangles of its first frame) and a
//! motion partition (one cluster id per vertex) into an [`Atlas`]: every vertex
//! gets its own pixel of a `width × height` lattice, charts own whole 8×8
//! blocks, and [`Atlas::splat`] / [`sample`] move per-vertex values into an
//! image and back exactly.
//!
//! # Steps
//! 1. **Seeds.** Each face takes the majority cluster of its three corners
//!    (the first corner's when all three differ); the faces of one cluster are
//!    split into pieces connected through shared edges, so multi-component
//!    meshes (the 41-part "Chicken") and non-manifold edges are fine.
//! 2. **Charts.** The pieces are flattened with [`uvunwrap`] 0.3, each piece
//!    passed as a face material so that no chart crosses it; inside a piece
//!    uvunwrap may cut further (normal cone, area distortion) and flattens each
//!    chart by LSCM + ARAP. Then, as iso-charts does, every chart whose
//!    normalised L2 stretch (Sander et al. 2001; 1 is isometric) exceeds
//!    [`AtlasOptions::max_stretch`] is cut in two across the principal axis of
//!    its face centroids and everything is flattened again, for at most
//!    [`AtlasOptions::max_split_rounds`] rounds.
//!    *Why uvunwrap:* pure Rust, builds here, takes per-face chart hints;
//!    `xatlas-rs` 0.1.3 does not link on Linux (its bindings carry Windows
//!    symbol names). uvunwrap's own packing is not used: its 2D charts are
//!    rescaled to surface units and packed below.
//! 3. **Vertex ownership.** A vertex on the boundary of several charts is
//!    owned by the chart of the first face (in triangle order) that uses it
//!    and lies in the vertex's own cluster, or else by the chart of the first
//!    charted face that uses it. Its copies in other charts are only corners
//!    for rasterisation. Charts that own no vertex are dropped. Vertices that
//!    no kept face charts (isolated vertices, vertices of degenerate faces
//!    only) go to one extra chart laid out as a plain grid.
//! 4. **Packing.** One common scale for all charts (equal sampling density);
//!    each chart's bounding rectangle is rounded up to whole blocks (and grown
//!    until it has a pixel per owned vertex), then the rectangles are packed
//!    bottom-left-fill on the block grid, both orientations tried, biggest
//!    first. The scale is the largest that fits (bisection).
//! 5. **Lattice.** Vertices are rounded to the nearest pixel; a vertex whose
//!    pixel is taken moves to the nearest free pixel of its own chart's
//!    rectangle ([`AtlasStats::moved_vertices`] counts them), so the map is
//!    injective. With [`Interior::Rasterised`] the chart triangles' pixels are
//!    fixed too and carry barycentric blends of the corner values.

// `!(x > t)` is deliberate: unlike `x <= t` it also rejects NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod atlas;
mod build;
mod error;
mod options;
mod pack;
mod picture;
mod seed;
mod stretch;
mod unwrap;

pub use atlas::{sample, Atlas, AtlasStats, Chart, Occupancy};
pub use build::build;
pub use error::AtlasError;
pub use options::{AtlasOptions, Interior};
