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
//!    was shredded into slivers: a skinned snake made 414 charts for 20
//!    clusters. A generated snake (4322 vertices, K = 20) now has 23 charts
//!    (41 before), a torus 22 (41); see the measured table below.
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
//! fixes only vertex pixels and leaves the rest to padding. Measured with
//! JPEG (8-bit, one channel) on the x displacement between frames 1 and 11,
//! free pixels filled by 300 Jacobi sweeps (a stand-in for the padding
//! crate), Rasterised codes smaller at equal vertex error on all four
//! sequences tried (rmse relative to the signal range):
//!
//! | mesh | Rasterised q50 | Free q50 | Free q75 |
//! |---|---|---|---|
//! | pdance | 3895 B, 0.0089 | 3657 B, 0.0112 | 5150 B, 0.0092 |
//! | pcow | 3600 B, 0.0096 | 3510 B, 0.0148 | 4855 B, 0.0121 |
//! | horse-gallop | 2234 B, 0.0064 | 2161 B, 0.0070 | 2824 B, 0.0055 |
//! | chickenCrossing | 4774 B, 0.0186 | 4181 B, 0.0222 | 5966 B, 0.0183 |
//!
//! With a plain mean fill instead, Free is far worse (dance q50: 0.0597 vs
//! 0.0278). Command: `cargo run --release -p atlas --example measure --
//! --jpeg bench-out/media/pdance` (and the other folders; the OBJ sequences
//! as `make bench` unpacks them from `../shared/media`).
//!
//! # Charts and packing in the encoder (motion k-means, K = 20, auto lattice)
//! `mcgv-video encode IN -o s.mcgv --codec jpeg --quality 50 --quiet` then
//! `mcgv-video inspect s.mcgv --json` (`charts`, `packing_efficiency`); snake
//! and torus are generated OBJ sequences (a closed bending tube of 24 × 180
//! quads with capped ends, 40 frames; a 96 × 32 torus whose cross-section
//! breathes), before → after whole-piece charts (glTF rows: after, then with
//! [`AtlasOptions::weld`]):
//!
//! | mesh | V | charts | packing |
//! |---|---|---|---|
//! | snake (generated) | 4322 | 41 → 23 | 58.8% → 57.9% |
//! | torus (generated) | 3072 | 41 → 22 | 49.6% → 45.3% |
//! | CesiumMan | 3273 | 327 → 341; 44 | 41.6% → 39.3%; 52.7% |
//! | Fox | 1728 | 576 → 576; 109 | 15.2% → 15.2%; 42.0% |
//! | RiggedFigure | 370 | 87 → 87; 43 | 31.9% → 32.0%; 46.1% |
//! | pdance | 7061 | 73 → 69 | 51.3% → 51.1% |
//! | pcow | 2904 | 61 → 55 | 47.2% → 50.5% |
//! | chickenCrossing | 3030 | 98 → 116 | 46.8% → 50.9% |
//! | horse-gallop | 8431 | 106 → 93 | 48.5% → 49.8% |
//!
//! Long unrolled bands pack no better than the pieces they replace: the
//! packer places bounding frames on the block grid, and a slanted band
//! leaves empty blocks in its frame.
//!
//! The table below was measured before those changes, with the measuring
//! example's stand-in partition.
//!
//! # Measured (256×256, K = 20 k-means partition, release build)
//! `cargo run --release -p atlas --example measure -- bench-out/media/pdance ...`
//!
//! | mesh | V | charts | packing | moved | L2 stretch | build |
//! |---|---|---|---|---|---|---|
//! | chickenCrossing | 3030 | 145 | 40.7% | 400 | 1.001 | 0.16 s |
//! | pcow | 2904 | 54 | 49.8% | 108 | 1.001 | 0.11 s |
//! | pdance | 7061 | 82 | 49.1% | 1728 | 1.001 | 0.20 s |
//! | horse-gallop | 8431 | 85 | 49.8% | 2294 | 1.001 | 0.21 s |
//! | horse-collapse | 8431 | 92 | 48.9% | 2303 | 1.001 | 0.22 s |
//! | walking_cat | 1297 | 57 | 45.6% | 122 | 1.002 | 0.08 s |
//!
//! Packing is chart pixels (covered by a chart triangle or a vertex) over
//! lattice pixels. Moved vertices are many on dense meshes: at one common
//! scale, regions with more vertices than pixels must spill: with
//! `--lattice 512` dance moves 289 and horse-gallop 613 (packing 58.5%,
//! 59.0%), with 1024 14 and 137. BrainStem (32559 welded vertices, 995
//! charts) needs 512×512: 40.8% packing, 9457 moved, 2.1 s.

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
pub use build::build;
pub use error::AtlasError;
pub use options::{AtlasOptions, Interior};
