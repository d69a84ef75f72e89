//! Multi-chart geometry-image atlas (MCGV paper §3.3, first half).
//!
//! [`build`] turns a mesh (positions and triangles of its first frame) and a
//! motion partition (one cluster id per vertex) into an [`Atlas`]: every vertex
//! gets its own pixel of a `width × height` lattice (default 256×256), charts
//! own whole 8×8 blocks and never share one, and [`Atlas::splat`] / [`sample`]
//! move per-vertex values into an image and back exactly. The crate knows
//! meshes and numbers only.
//!
//! ```
//! use atlas::{build, sample, AtlasOptions};
//! let positions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
//! let triangles = [[0, 1, 2], [0, 2, 3]];
//! let atlas = build(&positions, &triangles, &[0, 0, 1, 1], &AtlasOptions::default())?;
//! let values = [1.0, 2.0, 3.0, 4.0];
//! let image = atlas.splat(&values); // encoder: 256×256, row-major
//! let back = sample(atlas.vertex_pixels(), atlas.width(), &image)?; // decoder
//! assert_eq!(back, values);
//! # Ok::<(), atlas::AtlasError>(())
//! ```
//!
//! # Steps
//! 1. **Seeds.** Each face takes the majority cluster of its three corners
//!    (the first corner's when all three differ); the faces of one cluster are
//!    split into pieces connected through shared edges, so multi-component
//!    meshes (the 41-part "Chicken") and non-manifold edges are fine. With
//!    [`AtlasOptions::weld`], charting runs on the triangles with vertices at
//!    bit-identical positions welded, so that glTF meshes split at UV seams
//!    (CesiumMan) or not indexed (Fox, 576 loose triangles) do not make every
//!    seam a chart border and every loose triangle a chart; off by default
//!    (see the option for why).
//! 2. **Charts.** A piece that is a disk, or a genus-0 piece with several
//!    boundary loops once shortest paths join the loops (a band around a tube
//!    is an annulus: one cut), is flattened whole, as one chart, by [`uvunwrap`]
//!    0.3 (the piece passed as one polygon, the cut opened by duplicating its
//!    vertices). Closed pieces and pieces of higher genus are first split
//!    across their principal axis (twice at most). Pieces whose whole flattening
//!    fails, and the rest, are flattened as before: each piece a face material,
//!    so that no chart crosses it, and inside a piece uvunwrap may cut further
//!    (normal cone, area distortion); it flattens each chart by LSCM + ARAP.
//!    Then, as iso-charts does, every chart whose normalised L2 stretch
//!    (Sander et al. 2001; 1 is isometric) exceeds [`AtlasOptions::max_stretch`]
//!    is cut in two across the principal axis of its face centroids and
//!    everything is flattened again, for at most
//!    [`AtlasOptions::max_split_rounds`] rounds.
//!
//!    *Why uvunwrap:* pure Rust, builds here, takes per-face chart hints;
//!    `xatlas-rs` 0.1.3 does not link on Linux (its bindings carry Windows
//!    symbol names). uvunwrap's own packing is not used: its charts are
//!    rescaled to surface units and packed below. Left to its segmentation,
//!    uvunwrap grows charts within a normal cone, so a tube band came back in
//!    several charts, and a band passed whole (an annulus cannot be flattened)
//!    was shredded into slivers; pieces flattened whole make far fewer charts
//!    on tubes and tori
//!    (docs/design.md, "Atlas: whole-piece charts and packing").
//! 3. **Vertex ownership.** A vertex shared by several charts is owned by one:
//!    among the charts with a face on it, the one with most faces among those
//!    whose face is in the vertex's own cluster, else the one with most faces
//!    (ties: lower chart id). Its copies in other charts are only triangle
//!    corners for rasterisation. Charts left with fewer than
//!    [`AtlasOptions::min_chart_vertices`] (8) vertices hand them to the
//!    neighbouring chart owning most of their mesh neighbours, at the mean
//!    of those neighbours' 2D positions ([`AtlasStats::absorbed_vertices`];
//!    a chart takes in at most as many vertices as it owns);
//!    charts owning no vertex are dropped. Vertices that no kept face charts
//!    (isolated vertices, vertices of degenerate faces only) go to one extra
//!    chart laid out as a plain grid ([`AtlasStats::faceless_vertices`]).
//! 4. **Packing.** One common scale for all charts (equal sampling density).
//!    At a given scale a chart's frame is its bounding rectangle rounded up to
//!    whole blocks, and the chart owns the blocks of the frame that its
//!    triangles or vertices touch (the whole frame, grown if needed, when
//!    those hold fewer pixels than it has vertices). Footprints are packed
//!    biggest first, bottom-left fill on the block grid, in four orientations,
//!    so small charts nest into big ones' empty blocks. The scale is the
//!    largest that packs (bisection, then a probe a little above since the
//!    greedy packer is not monotonic).
//! 5. **Lattice.** Vertices are rounded to the nearest pixel; a vertex whose
//!    pixel is taken moves to the nearest free pixel of its own chart's
//!    blocks ([`AtlasStats::moved_vertices`]), so the map is injective and
//!    every vertex stays in its chart's blocks. Meshes with more vertices than
//!    pixels, or charts that do not fit even at scale 0, are errors that name
//!    a lattice that would do.
//!
//! # Interior pixels
//! [`Interior::Rasterised`] (default, as the paper) fixes the chart triangles'
//! pixels to barycentric blends of the corner values; [`Interior::Free`]
//! fixes only vertex pixels and leaves the rest to padding. Rasterised codes
//! smaller at equal vertex error on every sequence tried
//! (docs/design.md, "Chart interiors and seams"; `cargo run --release -p
//! atlas --example measure -- --jpeg DIR`).
//!
//! # Packing and moved vertices
//! Packing is chart pixels (covered by a chart triangle or a vertex) over
//! lattice pixels. Long unrolled bands pack no better than the pieces they
//! replace: the packer places bounding frames on the block grid, and a
//! slanted band leaves empty blocks in its frame. Moved vertices are many on
//! dense meshes: at one common scale, regions with more vertices than pixels
//! must spill, fewer on larger lattices. Charts, packing, moved vertices,
//! stretch and time per mesh: `cargo run --release -p atlas --example measure
//! -- INPUT...`, or `mcgv-video inspect STREAM --json` for the encoder's
//! atlas (docs/design.md, "Atlas: whole-piece charts and packing").

// `!(x > t)` is deliberate: unlike `x <= t` it also rejects NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod atlas;
mod build;
mod charts;
mod cut;
mod error;
mod input;
mod lattice;
mod layout;
mod open;
mod options;
mod ownership;
mod pack;
mod picture;
mod raster;
mod scale;
mod seed;
mod stretch;
mod topology;
mod unwrap;
mod weld;
mod whole;

pub use atlas::{sample, Atlas, AtlasStats, Chart, Occupancy};
pub use build::{build, Flattened};
pub use error::AtlasError;
pub use options::{AtlasOptions, Interior};
