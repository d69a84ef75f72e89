//! The static mesh coder for frame 0: connectivity and quantised positions.
//!
//! Layout of [`EncodedFirstFrame::bytes`] (little endian):
//! `version u8, bits u8, flags u8, 0u8, vertices u32, traversed triangles u32,
//! degenerate triangles u32, welded vertices u32, bbox lo 3×f32, largest extent f32,
//! connectivity length u32, geometry length u32, order length u32, crc32 u32` then the three
//! range-coded streams, all over the *welded* mesh, whose vertices are the distinct positions (see
//! `weld`: seam copies and triangle soups become one connected surface):
//! - connectivity: the `traversal` symbols of the triangles whose corners are three welded
//!   vertices, then the copies of each welded vertex and which one each corner uses, then the
//!   degenerate triangles (a repeated welded vertex), which no traversal can reach, as plain
//!   adaptive-coded indices;
//! - geometry: the quantised welded positions in traversal order (those in no triangle appended
//!   in input order), coded after the connectivity by `geometry`: multi-parallelogram
//!   prediction, else the mean of coded neighbours, else the previous vertex;
//! - order: the output → input vertex permutation, absent with `reorder`.
//!
//! Triangles come back in traversal order (face order is not kept: coding it would cost
//! log2(F!) bits) with the input's vertex indices and orientation, possibly rotated.

mod creases;
mod free_ranks;
mod geometry;
mod order;
mod quantise;
mod traversal;
mod weld;

pub use quantise::{Cell, Grid};

use crate::error::{Error, Result};
use crate::mesh::{position_key, Point, Triangle};
use crate::stream::entropy::{check_capacity, Decoder, Encoder, SymbolCoder, UIntModel};
use traversal::{Models, Oracle, UNASSIGNED};
use weld::Weld;

const VERSION: u8 = 4;
/// Bytes of the header in front of the streams; its last four are the CRC-32 of the rest of the
/// header and of the streams (tools that damage a first frame on purpose repair it there).
pub const HEADER_LEN: usize = 52;
const FLAG_ORDER: u8 = 1;
/// Refuses headers past this many vertices or triangles whatever the input length.
const MAX_ELEMENTS: u64 = 1 << 28;

/// How to code the first frame.
#[derive(Clone, Debug)]
pub struct FirstFrameOptions {
    /// Bits per coordinate over the bounding box (1..=24).
    pub bits: u8,
    /// Let the coder number vertices in traversal order (fewer bits; see [`EncodedFirstFrame::permutation`]).
    pub reorder: bool,
}

impl Default for FirstFrameOptions {
    fn default() -> Self {
        Self {
            bits: 12,
            reorder: false,
        }
    }
}

/// The coded first frame and what the decoder will make of it.
#[derive(Clone, Debug)]
pub struct EncodedFirstFrame {
    /// The coded bytes.
    pub bytes: Vec<u8>,
    /// Exactly what [`decode`] will return as positions (in the decoder's vertex order).
    pub decoded_positions: Vec<Point>,
    /// With `reorder`: `permutation[new] = old` vertex index; `None` when the order is kept.
    pub permutation: Option<Vec<u32>>,
    /// Bytes of each stream (read by the first-frame bench and tests).
    #[cfg_attr(not(feature = "internals"), allow(dead_code))]
    pub sizes: StreamSizes,
}

/// Sizes in bytes of the parts of a coded first frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StreamSizes {
    /// Fixed header.
    pub header: usize,
    /// Connectivity stream.
    pub connectivity: usize,
    /// Geometry stream.
    pub geometry: usize,
    /// Vertex order stream.
    pub order: usize,
}

/// Codes the triangles with a repeated vertex index (`model` carries on from one call to the next).
fn code_degenerate<C: SymbolCoder>(
    coder: &mut C,
    model: &mut UIntModel,
    triangles: &mut [Triangle],
    vertex_count: usize,
) -> Result<()> {
    for tri in triangles.iter_mut() {
        for v in tri.iter_mut() {
            let index = coder.unsigned(u64::from(*v), model)?;
            *v = u32::try_from(index)
                .ok()
                .filter(|&i| (i as usize) < vertex_count)
                .ok_or_else(|| {
                    Error::Stream("first frame: degenerate triangle index out of range".into())
                })?;
        }
    }
    Ok(())
}

/// Encodes frame 0: `triangles` index `positions`.
pub fn encode(
    positions: &[Point],
    triangles: &[Triangle],
    opts: &FirstFrameOptions,
) -> Result<EncodedFirstFrame> {
    let vertex_count = positions.len();
    check_encode_input(triangles, vertex_count)?;
    let grid = Grid::fit(positions, opts.bits)?;
    let cells: Vec<Cell> = positions.iter().map(|&p| grid.quantise(p)).collect();
    let weld = weld_exact(positions);
    let welded_count = weld.first.len();
    let (traversable, sources, mut degenerate) = split_welded(triangles, &weld);

    let mut connectivity = Encoder::new();
    let mut geometry = Encoder::new();
    let (state, oracle) = encode_traversal(&mut connectivity, &traversable, welded_count)?;
    let traversal_cells: Vec<Cell> = oracle
        .from_traversal
        .iter()
        .map(|&w| cells[weld.first[w as usize] as usize])
        .collect();
    let decoded_cells = geometry::code_positions(
        &mut geometry,
        &grid,
        &state.triangles,
        welded_count,
        &traversal_cells,
    )?;
    let numbering = encode_copies(
        &mut connectivity,
        (&state, &decoded_cells),
        &oracle,
        &weld,
        &sources,
    )?;
    let mut to_output = vec![0u32; vertex_count];
    for (o, &input) in numbering.inputs.iter().enumerate() {
        to_output[input as usize] = o as u32;
    }
    to_traversal_indices(&mut degenerate, &to_output);
    let mut model = UIntModel::default();
    code_degenerate(&mut connectivity, &mut model, &mut degenerate, vertex_count)?;

    let order_stream = if opts.reorder {
        Vec::new()
    } else {
        encode_order(
            &numbering.triangles,
            &degenerate,
            &numbering.inputs,
            &numbering.welded,
        )?
    };
    let (decoded_positions, permutation) =
        decoded_output(&grid, &numbering, &decoded_cells, vertex_count, opts.reorder);

    let connectivity = connectivity.finish()?;
    let geometry = geometry.finish()?;
    let header = Header {
        bits: opts.bits,
        has_order: !opts.reorder,
        vertex_count: vertex_count as u32,
        traversed: traversable.len() as u32,
        degenerate: degenerate.len() as u32,
        welded: welded_count as u32,
        grid,
        lengths: [
            connectivity.len() as u32,
            geometry.len() as u32,
            order_stream.len() as u32,
        ],
    };
    Ok(EncodedFirstFrame {
        bytes: assemble(&header, &connectivity, &geometry, &order_stream),
        decoded_positions,
        permutation,
        sizes: StreamSizes {
            header: HEADER_LEN,
            connectivity: connectivity.len(),
            geometry: geometry.len(),
            order: order_stream.len(),
        },
    })
}

/// What the decoder will hold: the positions of `decoded_cells` (per welded vertex) in output
/// order, and the permutation to it when `reorder` (see [`place_decoded_positions`]).
fn decoded_output(
    grid: &Grid,
    numbering: &weld::Numbering,
    decoded_cells: &[Cell],
    vertex_count: usize,
    reorder: bool,
) -> (Vec<Point>, Option<Vec<u32>>) {
    let output_cells: Vec<Cell> = numbering
        .welded
        .iter()
        .map(|&w| decoded_cells[w as usize])
        .collect();
    place_decoded_positions(
        grid,
        &output_cells,
        &numbering.inputs,
        vertex_count,
        reorder,
    )
}

/// The input vertices welded by exact position, not by cell: distinct vertices that only share a
/// cell at low bits would weld into degenerate and non-manifold triangles (horse-gallop at 10
/// bits: 129 of 8 431, connectivity 2.2 -> 3.5 bits a vertex). Equal positions have equal cells.
fn weld_exact(positions: &[Point]) -> Weld {
    let keys: Vec<[u32; 3]> = positions.iter().map(position_key).collect();
    Weld::new(&keys)
}

/// The triangles the traversal codes (on three distinct welded vertices, as welded vertices), the
/// input triangles they come from, and the input triangles degenerate once welded.
fn split_welded(
    triangles: &[Triangle],
    weld: &Weld,
) -> (Vec<[u32; 3]>, Vec<Triangle>, Vec<Triangle>) {
    let (mut traversable, mut sources, mut degenerate) = (Vec::new(), Vec::new(), Vec::new());
    for tri in triangles {
        let w = tri.map(|v| weld.welded_of[v as usize]);
        if w[0] != w[1] && w[1] != w[2] && w[0] != w[2] {
            traversable.push(w);
            sources.push(*tri);
        } else {
            degenerate.push(*tri);
        }
    }
    (traversable, sources, degenerate)
}

/// Codes which input vertex (copy of a welded vertex) each corner of the coded triangles uses.
fn encode_copies(
    connectivity: &mut Encoder,
    (state, cells): (&traversal::Traversal, &[Cell]),
    oracle: &Oracle,
    weld: &Weld,
    sources: &[Triangle],
) -> Result<weld::Numbering> {
    let welded_count = weld.first.len();
    let mut copies_of = vec![Vec::new(); welded_count];
    for (v, &w) in weld.welded_of.iter().enumerate() {
        copies_of[oracle.to_traversal[w as usize] as usize].push(v as u32);
    }
    // The input triangle behind each coded one, its corners in the coded triangle's rotation.
    let corners: Vec<Triangle> = oracle
        .coded_order
        .iter()
        .zip(&state.triangles)
        .map(|(&i, coded)| {
            let source = sources[i as usize];
            coded.map(|tw| {
                let w = oracle.from_traversal[tw as usize];
                source
                    .into_iter()
                    .find(|&v| weld.welded_of[v as usize] == w)
                    .unwrap_or(source[0])
            })
        })
        .collect();
    let actual = weld::Actual {
        copies_of: &copies_of,
        corners: &corners,
    };
    weld::code_copies(
        connectivity,
        (&state.triangles, cells),
        welded_count,
        weld.welded_of.len(),
        Some(actual),
    )
}

/// Refuses inputs too large for the header and triangles indexing past the vertices.
fn check_encode_input(triangles: &[Triangle], vertex_count: usize) -> Result<()> {
    if vertex_count as u64 > MAX_ELEMENTS || triangles.len() as u64 > MAX_ELEMENTS {
        return Err(Error::Usage(format!(
            "first frame too large: {vertex_count} vertices"
        )));
    }
    if let Some((t, _)) = triangles
        .iter()
        .enumerate()
        .find(|(_, tri)| tri.iter().any(|&v| v as usize >= vertex_count))
    {
        return Err(Error::Mesh(format!(
            "triangle {t} indexes a vertex past {vertex_count}"
        )));
    }
    Ok(())
}

/// Codes the traversal of the non-degenerate triangles into `connectivity`; the oracle it
/// returns numbers every vertex, those in no traversed triangle last, in input order.
fn encode_traversal<'a>(
    connectivity: &mut Encoder,
    traversable: &'a [Triangle],
    vertex_count: usize,
) -> Result<(traversal::Traversal, Oracle<'a>)> {
    let mut models = Models::default();
    let mut oracle = Oracle::new(traversable, vertex_count);
    let state = traversal::run(
        connectivity,
        Some(&mut oracle),
        traversable.len(),
        vertex_count,
        &mut models,
    )?;
    // Vertices in no traversed triangle follow, in input order.
    for v in 0..vertex_count as u32 {
        if oracle.to_traversal.get(v as usize) == Some(&UNASSIGNED) {
            oracle.assign(v);
        }
    }
    Ok((state, oracle))
}

/// Renumbers the degenerate triangles' input indices to traversal indices.
fn to_traversal_indices(degenerate: &mut [Triangle], to_traversal: &[u32]) {
    for tri in degenerate.iter_mut() {
        for v in tri.iter_mut() {
            *v = to_traversal.get(*v as usize).copied().unwrap_or(0);
        }
    }
}

/// Codes the traversal → input permutation over all triangles.
fn encode_order(
    traversed: &[Triangle],
    degenerate: &[Triangle],
    from_traversal: &[u32],
    welded: &[u32],
) -> Result<Vec<u8>> {
    let mut order_coder = Encoder::new();
    let all: Vec<Triangle> = traversed.iter().chain(degenerate).copied().collect();
    order::code_order(&mut order_coder, &mut from_traversal.to_vec(), &all, welded)?;
    order_coder.finish()
}

/// The positions the decoder will return, and the permutation when it numbers vertices in
/// traversal order (`reorder`); otherwise back in input order.
fn place_decoded_positions(
    grid: &Grid,
    decoded_cells: &[Cell],
    from_traversal: &[u32],
    vertex_count: usize,
    reorder: bool,
) -> (Vec<Point>, Option<Vec<u32>>) {
    let traversal_positions: Vec<Point> =
        decoded_cells.iter().map(|&c| grid.dequantise(c)).collect();
    if reorder {
        return (traversal_positions, Some(from_traversal.to_vec()));
    }
    let mut out = vec![[0.0; 3]; vertex_count];
    for (t, &input) in from_traversal.iter().enumerate() {
        out[input as usize] = traversal_positions[t];
    }
    (out, None)
}

/// The header, with its crc32 over everything, then the three streams.
fn assemble(header: &Header, connectivity: &[u8], geometry: &[u8], order: &[u8]) -> Vec<u8> {
    let mut bytes = header.to_bytes();
    bytes.extend_from_slice(connectivity);
    bytes.extend_from_slice(geometry);
    bytes.extend_from_slice(order);
    let crc = crc32fast::hash(&bytes);
    bytes.splice(HEADER_LEN - 4..HEADER_LEN - 4, crc.to_le_bytes());
    bytes
}

/// Decodes a first frame: its triangles and positions.
pub fn decode(bytes: &[u8]) -> Result<(Vec<Triangle>, Vec<Point>)> {
    let header = Header::parse(bytes)?;
    let payload = bytes.get(HEADER_LEN..).unwrap_or_default();
    let [lc, lg, lo] = header.lengths.map(|l| l as usize);
    let (connectivity, rest) = payload.split_at_checked(lc).ok_or_else(truncated)?;
    let (geometry, order) = rest.split_at_checked(lg).ok_or_else(truncated)?;
    if order.len() != lo {
        return Err(truncated());
    }
    let vertex_count = header.vertex_count as usize;
    let welded_count = header.welded as usize;
    let mut connectivity = Decoder::new(connectivity)?;
    let mut geometry = Decoder::new(geometry)?;
    let mut models = Models::default();
    let grid = header.grid;
    let state = traversal::run(
        &mut connectivity,
        None,
        header.traversed as usize,
        welded_count,
        &mut models,
    )?;
    let cells =
        geometry::code_positions(&mut geometry, &grid, &state.triangles, welded_count, &[])?;
    let numbering = weld::code_copies(
        &mut connectivity,
        (&state.triangles, &cells),
        welded_count,
        vertex_count,
        None,
    )?;
    let degenerate =
        decode_degenerate(&mut connectivity, header.degenerate as usize, vertex_count)?;
    let mut triangles = numbering.triangles;
    triangles.extend(degenerate);
    let welded = numbering.welded;
    let mut positions: Vec<Point> = welded
        .iter()
        .map(|&w| grid.dequantise(cells[w as usize]))
        .collect();
    if header.has_order {
        let mut order_indices = vec![0u32; vertex_count];
        order::code_order(
            &mut Decoder::new(order)?,
            &mut order_indices,
            &triangles,
            &welded,
        )?;
        let mut reordered = vec![[0.0; 3]; vertex_count];
        for (t, &input) in order_indices.iter().enumerate() {
            reordered[input as usize] = positions[t];
        }
        positions = reordered;
        for tri in triangles.iter_mut() {
            for v in tri.iter_mut() {
                *v = order_indices[*v as usize];
            }
        }
    }
    Ok((triangles, positions))
}

/// Decodes `count` degenerate triangles a block at a time: the count is only a claim until they
/// decode, so room is made as they do.
fn decode_degenerate(
    coder: &mut Decoder,
    count: usize,
    vertex_count: usize,
) -> Result<Vec<Triangle>> {
    const BLOCK: usize = 1 << 12;
    let mut model = UIntModel::default();
    let mut degenerate = Vec::new();
    while degenerate.len() < count {
        let at = degenerate.len();
        degenerate.resize(at + (count - at).min(BLOCK), [0u32; 3]);
        code_degenerate(coder, &mut model, &mut degenerate[at..], vertex_count)?;
    }
    Ok(degenerate)
}

fn truncated() -> Error {
    Error::Stream("first frame: truncated".into())
}

/// The fixed-size header in front of the streams.
struct Header {
    bits: u8,
    has_order: bool,
    vertex_count: u32,
    traversed: u32,
    degenerate: u32,
    /// Vertices after welding equal cells (see [`weld`]).
    welded: u32,
    grid: Grid,
    lengths: [u32; 3],
}

impl Header {
    /// The header with a zero checksum, which `encode` fills in.
    fn to_bytes(&self) -> Vec<u8> {
        let mut out = vec![
            VERSION,
            self.bits,
            if self.has_order { FLAG_ORDER } else { 0 },
            0,
        ];
        for v in [self.vertex_count, self.traversed, self.degenerate, self.welded] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        for c in self.grid.lo.iter().chain([&self.grid.extent]) {
            out.extend_from_slice(&c.to_le_bytes());
        }
        for l in self.lengths {
            out.extend_from_slice(&l.to_le_bytes());
        }
        out
    }

    fn parse(bytes: &[u8]) -> Result<Self> {
        let head = bytes.get(..HEADER_LEN).ok_or_else(truncated)?;
        let word = |k: usize| u32::from_le_bytes([head[k], head[k + 1], head[k + 2], head[k + 3]]);
        let float = |k: usize| f32::from_bits(word(k));
        let crc = word(HEADER_LEN - 4);
        let mut hasher = crc32fast::Hasher::new();
        hasher.update(&head[..HEADER_LEN - 4]);
        hasher.update(&bytes[HEADER_LEN..]);
        if hasher.finalize() != crc {
            return Err(Error::Stream("first frame: checksum mismatch".into()));
        }
        if head[0] != VERSION {
            return Err(Error::Stream(format!(
                "first frame: unknown version {}",
                head[0]
            )));
        }
        let bits = head[1];
        if !(1..=Grid::MAX_BITS).contains(&bits) {
            return Err(Error::Stream(format!("first frame: {bits} position bits")));
        }
        let lo = [float(20), float(24), float(28)];
        let extent = float(32);
        if lo.iter().any(|c| !c.is_finite()) || !(extent.is_finite() && extent >= 0.0) {
            return Err(Error::Stream("first frame: bad bounding box".into()));
        }
        let header = Self {
            bits,
            has_order: head[2] & FLAG_ORDER != 0,
            vertex_count: word(4),
            traversed: word(8),
            degenerate: word(12),
            welded: word(16),
            grid: Grid { bits, lo, extent },
            lengths: [word(36), word(40), word(44)],
        };
        // What each stream must hold, in adaptive-coded symbols (each at least 1/710 bit, see
        // `max_symbols`): every welded vertex is three coded residuals in the geometry stream;
        // every vertex is one "a copy per corner?" or "another copy?" decision (a welded vertex
        // of n copies, n of its corners' decisions or more) and every triangle at least three in the
        // connectivity stream (a seed: three new/old bits; a gate: more, flipped and the 5-way kind
        // of its third vertex; a degenerate one: three indices); when the order is stored, every
        // vertex is a choice among 127 candidates and the escape (7 binary decisions, of which 4
        // are asked for here) in the order stream. Checked per stream, before the decoders
        // allocate anything per vertex or triangle.
        let [lc, lg, lo] = header.lengths;
        let vertices = u64::from(header.vertex_count);
        let triangles = u64::from(header.traversed) + u64::from(header.degenerate);
        if vertices > MAX_ELEMENTS || triangles > MAX_ELEMENTS {
            return Err(Error::Stream(format!(
                "first frame: {vertices} vertices and {triangles} triangles are past the limit of \
                 {MAX_ELEMENTS}"
            )));
        }
        let welded = u64::from(header.welded);
        if welded > vertices {
            return Err(Error::Stream(format!(
                "first frame: {welded} welded vertices of {vertices}"
            )));
        }
        let ordered = if header.has_order { vertices } else { 0 };
        for (what, symbols, stream, len) in [
            (format!("{welded} welded vertices"), 3 * welded, "geometry", lg),
            (
                format!("{vertices} vertices and {triangles} triangles"),
                vertices + 3 * triangles,
                "connectivity",
                lc,
            ),
            (format!("{ordered} vertices"), 4 * ordered, "order", lo),
        ] {
            let what = format!("first frame, {what} in the {stream} stream");
            check_capacity(symbols, len as usize, &what)?;
        }
        Ok(header)
    }
}
