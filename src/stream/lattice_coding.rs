//! Entropy coding of the lattice coordinates: the pixel of each vertex in the picture codecs'
//! atlas, vertex by vertex, each placed from a guess made of its already-coded mesh neighbours.
//!
//! A vertex's neighbours mostly lie in its own chart, a pixel or two away; across a chart border
//! they lie in another chart, anywhere in the atlas, and a mean over both sides guesses nowhere.
//! So the coded neighbours are first gathered into groups of nearby pixels (a chart's side each,
//! most likely). With one group the guess is its mean; with several, the encoder names the group
//! whose mean is nearest (one symbol, coded only along chart borders). A vertex without coded
//! neighbours is guessed at the previous vertex's pixel.
//!
//! The atlas gives every vertex a pixel of its own, and the coded neighbours already hold pixels
//! nearest the guess. So a guessed vertex is coded as its *rank* among the free pixels around the
//! guess, nearest first (`Spiral`): the occupied ones cost nothing (picture set-up version 4). A
//! pixel beyond the spiral or already taken (an atlas that shares pixels) escapes to its difference
//! from the guess. The cases have models of their own (docs/design.md, "Lattice coordinates:
//! guessed from the nearest group of neighbours").

use crate::error::{Error, Result};
use crate::geometry_image::lattice;
use crate::mesh::topology::VertexAdjacency;
use crate::mesh::Triangle;
use crate::stream::entropy::{
    self, Decoder, Encoder, IntModel, SymbolCoder, SymbolModel, UIntModel,
};

/// Pixels (along each axis) within which a coded neighbour joins a group's centre.
const GROUP_RADIUS: i64 = 4;
/// Groups a guess chooses among; neighbours beyond them are left out.
const MAX_GROUPS: usize = 4;
/// Coded neighbours a vertex's guess reads, in the adjacency's order: grouping is quadratic in
/// them, and a hostile mesh's hub vertex must not make decoding so.
const MAX_NEIGHBOURS: usize = 16;

/// Pixels (along each axis) the spiral of ranked pixels reaches from the guess.
const SPIRAL_RADIUS: i32 = 16;

/// The pixels around a guess, nearest first (by squared distance, then row, then column): a
/// vertex's rank counts the free pixels before its own.
struct Spiral(Vec<[i32; 2]>);

impl Spiral {
    fn new() -> Self {
        let r = SPIRAL_RADIUS;
        let mut offsets: Vec<[i32; 2]> = (-r..=r)
            .flat_map(|dy| (-r..=r).map(move |dx| [dx, dy]))
            .collect();
        offsets.sort_by_key(|&[dx, dy]| (dx * dx + dy * dy, dy, dx));
        Self(offsets)
    }

    /// The free pixels of the lattice around `guess`, nearest first.
    fn free<'a>(
        &'a self,
        guess: [i64; 2],
        taken: &'a Occupancy,
    ) -> impl Iterator<Item = [i64; 2]> + 'a {
        self.0
            .iter()
            .map(move |o| [guess[0] + i64::from(o[0]), guess[1] + i64::from(o[1])])
            .filter(move |&p| taken.is_free(p))
    }
}

/// Which lattice pixels the vertices coded so far hold.
struct Occupancy {
    size: [i64; 2],
    bits: Vec<u64>,
}

impl Occupancy {
    fn new(size: (u16, u16)) -> Self {
        let pixels = size.0 as usize * size.1 as usize;
        Self {
            size: [size.0 as i64, size.1 as i64],
            bits: vec![0; pixels.div_ceil(64)],
        }
    }

    fn index(&self, p: [i64; 2]) -> Option<usize> {
        let inside = (0..self.size[0]).contains(&p[0]) && (0..self.size[1]).contains(&p[1]);
        inside.then(|| (p[1] * self.size[0] + p[0]) as usize)
    }

    /// Inside the lattice and held by no coded vertex.
    fn is_free(&self, p: [i64; 2]) -> bool {
        self.index(p)
            .is_some_and(|i| self.bits[i / 64] >> (i % 64) & 1 == 0)
    }

    fn take(&mut self, p: [i64; 2]) {
        if let Some(i) = self.index(p) {
            self.bits[i / 64] |= 1 << (i % 64);
        }
    }
}

/// Coded ranks (a rank plus one, 0 for an escape) below `RANKED_SYMBOLS - 1` are symbols of
/// their own (ranks 0 to 29); the last symbol stands for the rest, followed by the remainder.
const RANKED_SYMBOLS: usize = 32;

/// The models of a rank: its symbol, and what lies beyond the last.
struct RankModels(SymbolModel, UIntModel);

impl Default for RankModels {
    fn default() -> Self {
        Self(SymbolModel::new(RANKED_SYMBOLS), UIntModel::default())
    }
}

/// The adaptive models of the lattice part.
struct Models {
    /// A guessed vertex's rank among the free pixels around the guess, plus one (0: escape), with
    /// one group and with several.
    rank: [RankModels; 2],
    /// Escaped differences from one group's mean, per axis.
    single: [IntModel; 2],
    /// Escaped differences from the named group's mean, per axis.
    several: [IntModel; 2],
    /// Differences from the previous vertex's pixel, per axis.
    alone: [IntModel; 2],
    /// Which group, by how many there are (2 ..= [`MAX_GROUPS`]).
    choice: Vec<SymbolModel>,
}

impl Models {
    fn new() -> Self {
        Self {
            rank: Default::default(),
            single: Default::default(),
            several: Default::default(),
            alone: Default::default(),
            choice: (2..=MAX_GROUPS).map(SymbolModel::new).collect(),
        }
    }
}

/// The rounded means of the groups of `points` (non-negative pixels), the largest group first:
/// each group is the points within [`GROUP_RADIUS`] of the remaining point that has the most
/// remaining points that near (the earliest on a tie), at most [`MAX_GROUPS`] of them.
fn group_means(points: &[[i64; 2]], means: &mut Vec<[i64; 2]>) {
    means.clear();
    let near = |p: &[i64; 2], q: &[i64; 2]| {
        (p[0] - q[0]).abs() <= GROUP_RADIUS && (p[1] - q[1]).abs() <= GROUP_RADIUS
    };
    let mut left: Vec<[i64; 2]> = points.to_vec();
    while !left.is_empty() && means.len() < MAX_GROUPS {
        let mut centre = left[0];
        let mut most = 0;
        for p in &left {
            let count = left.iter().filter(|q| near(p, q)).count();
            if count > most {
                (centre, most) = (*p, count);
            }
        }
        let (mut sum, mut n) = ([0i64; 2], 0i64);
        for p in left.iter().filter(|q| near(&centre, q)) {
            sum = [sum[0] + p[0], sum[1] + p[1]];
            n += 1;
        }
        means.push([(sum[0] + n / 2) / n, (sum[1] + n / 2) / n]);
        left.retain(|q| !near(&centre, q));
    }
}

/// The index of the mean nearest `pixel` (city-block distance; the first on a tie).
fn nearest(means: &[[i64; 2]], pixel: [i64; 2]) -> usize {
    let distance = |m: &[i64; 2]| (pixel[0] - m[0]).abs() + (pixel[1] - m[1]).abs();
    let mut best = 0;
    for (i, m) in means.iter().enumerate() {
        if distance(m) < distance(&means[best]) {
            best = i;
        }
    }
    best
}

/// Codes `own` (the encoder's pixel; `None` on the decoder) as a difference from `guess` with
/// `axes`, checking the decoded pixel lies in the lattice.
fn code_difference<C: SymbolCoder>(
    c: &mut C,
    own: Option<[i64; 2]>,
    guess: [i64; 2],
    axes: &mut [IntModel; 2],
    size: [i64; 2],
) -> Result<[i64; 2]> {
    let mut pixel = [0; 2];
    for a in 0..2 {
        let d = c.signed(own.map_or(0, |p| p[a] - guess[a]), &mut axes[a])?;
        pixel[a] = guess[a] + d;
        if !(0..size[a]).contains(&pixel[a]) {
            return Err(Error::Stream(
                "lattice coordinates: a pixel outside the lattice".into(),
            ));
        }
    }
    Ok(pixel)
}

/// Codes `value` (a rank plus one, or 0): the small ones as symbols of their own, whose odds
/// adapt one by one (an Exp-Golomb code sends all but its top two bits raw), the rest beyond.
fn code_rank<C: SymbolCoder>(c: &mut C, value: u64, models: &mut RankModels) -> Result<u64> {
    let last = RANKED_SYMBOLS as u64 - 1;
    let symbol = c.symbol(value.min(last) as usize, &mut models.0)? as u64;
    if symbol < last {
        return Ok(symbol);
    }
    // A forged remainder may be any u64: past the spiral, it is refused by the caller's `nth`.
    let beyond = c.unsigned(value.saturating_sub(last), &mut models.1)?;
    last.checked_add(beyond)
        .ok_or_else(|| Error::Stream("lattice coordinates: a rank past any lattice".into()))
}

/// Codes `own` as its rank among the free pixels around `guess` (plus one), or 0 and the escaped
/// difference when it is not among them; `several` picks the models of a named group.
fn code_ranked<C: SymbolCoder>(
    c: &mut C,
    own: Option<[i64; 2]>,
    (guess, several): ([i64; 2], bool),
    models: &mut Models,
    (spiral, taken): (&Spiral, &Occupancy),
) -> Result<[i64; 2]> {
    let rank = own.and_then(|own| spiral.free(guess, taken).position(|p| p == own));
    let model = &mut models.rank[usize::from(several)];
    let coded = code_rank(c, rank.map_or(0, |r| r as u64 + 1), model)?;
    if coded == 0 {
        let axes = match several {
            false => &mut models.single,
            true => &mut models.several,
        };
        return code_difference(c, own, guess, axes, taken.size);
    }
    let nth = usize::try_from(coded - 1).unwrap_or(usize::MAX);
    spiral.free(guess, taken).nth(nth).ok_or_else(|| {
        Error::Stream("lattice coordinates: a rank past the pixels around the guess".into())
    })
}

/// Codes every vertex's pixel in vertex order; `encoding` when `pixels` hold them (the encoder).
fn code_lattice<C: SymbolCoder>(
    c: &mut C,
    pixels: &mut [[u16; 2]],
    (size, encoding): ((u16, u16), bool),
    adj: &VertexAdjacency,
) -> Result<()> {
    let mut models = Models::new();
    let spiral = Spiral::new();
    let mut taken = Occupancy::new(size);
    let (mut coded, mut means) = (Vec::with_capacity(MAX_NEIGHBOURS), Vec::new());
    for v in 0..pixels.len() {
        coded.clear();
        let earlier = adj.neighbours(v).iter().filter(|&&w| (w as usize) < v);
        for &w in earlier.take(MAX_NEIGHBOURS) {
            let p = pixels[w as usize];
            coded.push([p[0] as i64, p[1] as i64]);
        }
        group_means(&coded, &mut means);
        let own = encoding.then(|| [pixels[v][0] as i64, pixels[v][1] as i64]);
        let pixel = match means.len() {
            0 => {
                let previous = v.checked_sub(1).map_or([0, 0], |u| pixels[u]);
                let guess = [previous[0] as i64, previous[1] as i64];
                code_difference(c, own, guess, &mut models.alone, taken.size)?
            }
            1 => code_ranked(c, own, (means[0], false), &mut models, (&spiral, &taken))?,
            n => {
                let model = &mut models.choice[n - 2];
                let k = c.symbol(own.map_or(0, |own| nearest(&means, own)), model)?;
                let guess = *means
                    .get(k)
                    .ok_or_else(|| Error::Stream("lattice coordinates: no such group".into()))?;
                code_ranked(c, own, (guess, true), &mut models, (&spiral, &taken))?
            }
        };
        taken.take(pixel);
        pixels[v] = [pixel[0] as u16, pixel[1] as u16];
    }
    Ok(())
}

/// Codes the lattice pixel of each vertex.
pub fn encode_lattice(
    pixels: &[[u16; 2]],
    size: (u16, u16),
    triangles: &[Triangle],
) -> Result<Vec<u8>> {
    let adj = VertexAdjacency::new(pixels.len(), triangles);
    let mut enc = Encoder::new();
    code_lattice(&mut enc, &mut pixels.to_vec(), (size, true), &adj)?;
    enc.finish()
}

/// Decodes `vertices` lattice pixels inside a `size` lattice (one the stream can carry: at most
/// [`lattice::MAX_LATTICE_SIDE`] a side, since the decoder keeps a bit per pixel).
pub fn decode_lattice(
    bytes: &[u8],
    vertices: usize,
    size: (u16, u16),
    triangles: &[Triangle],
) -> Result<Vec<[u16; 2]>> {
    lattice::check(size.0, size.1)?;
    entropy::check_capacity(2 * vertices as u64, bytes.len(), "lattice coordinates")?;
    let adj = VertexAdjacency::new(vertices, triangles);
    let mut dec = Decoder::new(bytes)?;
    let mut pixels = vec![[0u16; 2]; vertices];
    code_lattice(&mut dec, &mut pixels, (size, false), &adj)?;
    Ok(pixels)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A strip of quads cut into two charts placed apart in the atlas: every vertex comes back,
    /// the seam's included.
    #[test]
    fn a_strip_cut_into_two_charts_round_trips() {
        // Columns from 12 on are a second chart, placed 40 pixels lower in the atlas.
        let (triangles, pixels) = quads((24, 6), |x, y| {
            let (px, py) = (2 * x as u16, 2 * y as u16);
            if x >= 12 {
                [px - 20, py + 40]
            } else {
                [px, py]
            }
        });
        let size = (64, 64);
        let bytes = encode_lattice(&pixels, size, &triangles).unwrap();
        let back = decode_lattice(&bytes, pixels.len(), size, &triangles).unwrap();
        assert_eq!(back, pixels);
        // Garbage or a cut part is an error, never a panic.
        for cut in [0, 1, bytes.len() / 2] {
            let _ = decode_lattice(&bytes[..cut], pixels.len(), size, &triangles);
        }
    }

    #[test]
    fn groups_follow_the_densest_points_first() {
        let mut means = Vec::new();
        group_means(&[[0, 0], [40, 40], [1, 1], [2, 0], [41, 40]], &mut means);
        assert_eq!(means, vec![[1, 0], [41, 40]]);
        group_means(&[], &mut means);
        assert!(means.is_empty());
        let spread: Vec<[i64; 2]> = (0..9).map(|i| [20 * i, 0]).collect();
        group_means(&spread, &mut means);
        assert_eq!(means.len(), MAX_GROUPS, "at most {MAX_GROUPS} groups");
        assert_eq!(nearest(&[[0, 0], [10, 10], [3, 3]], [4, 4]), 2);
    }

    /// A grid of `columns × rows` vertices cut into triangles, (x, y) at pixel `place(x, y)`.
    pub(crate) fn quads(
        (columns, rows): (u32, u32),
        place: impl Fn(u32, u32) -> [u16; 2],
    ) -> (Vec<Triangle>, Vec<[u16; 2]>) {
        let index = |x: u32, y: u32| y * columns + x;
        let mut triangles = Vec::new();
        for y in 0..rows - 1 {
            for x in 0..columns - 1 {
                triangles.push([index(x, y), index(x + 1, y), index(x, y + 1)]);
                triangles.push([index(x + 1, y), index(x + 1, y + 1), index(x, y + 1)]);
            }
        }
        let pixels = (0..rows).flat_map(|y| (0..columns).map(move |x| (x, y)));
        (triangles, pixels.map(|(x, y)| place(x, y)).collect())
    }

    /// A regular atlas, two pixels a vertex, where every guessed vertex has the same rank: the
    /// rank's own symbol learns it (96 bytes for 1 600 vertices; version 3's differences from the
    /// guess took 160, ranks in an Exp-Golomb code, whose low bits are raw, 296).
    #[test]
    fn ranks_skip_the_pixels_of_coded_neighbours() {
        let (triangles, pixels) = quads((40, 40), |x, y| [2 * x as u16, 2 * y as u16]);
        let bytes = encode_lattice(&pixels, (96, 96), &triangles).unwrap();
        assert!(bytes.len() < 120, "{} bytes", bytes.len());
        let back = decode_lattice(&bytes, pixels.len(), (96, 96), &triangles).unwrap();
        assert_eq!(back, pixels);
    }

    /// Pixels a vertex shares with a coded one, and pixels beyond the spiral, escape.
    #[test]
    fn shared_and_far_pixels_round_trip() {
        let far = 3 * SPIRAL_RADIUS as u16;
        let (triangles, pixels) = quads((12, 12), |x, y| match (x, y) {
            (5, 5) => [far, far],
            (6, 6) => [10, 10],
            _ => [x as u16 * 2 / 3, y as u16],
        });
        let size = (64, 64);
        let bytes = encode_lattice(&pixels, size, &triangles).unwrap();
        let back = decode_lattice(&bytes, pixels.len(), size, &triangles).unwrap();
        assert_eq!(back, pixels);
    }
}
