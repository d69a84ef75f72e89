//! Entropy coding of the lattice coordinates: the pixel of each vertex in the picture codecs'
//! atlas, vertex by vertex, each as a difference from a guess made of its already-coded mesh
//! neighbours.
//!
//! A vertex's neighbours mostly lie in its own chart, a pixel or two away; across a chart border
//! they lie in another chart, anywhere in the atlas, and a mean over both sides guesses nowhere.
//! So the coded neighbours are first gathered into groups of nearby pixels (a chart's side each,
//! most likely). With one group the guess is its mean; with several, the encoder names the group
//! whose mean is nearest (one symbol, coded only along chart borders). A vertex without coded
//! neighbours is guessed at the previous vertex's pixel. The differences of the three cases have
//! models of their own (picture set-up version 3; docs/design.md, "Lattice coordinates: guessed
//! from the nearest group of neighbours").

use crate::error::{Error, Result};
use crate::mesh::topology::VertexAdjacency;
use crate::mesh::Triangle;
use crate::stream::entropy::{self, Decoder, Encoder, IntModel, SymbolCoder, SymbolModel};

/// Pixels (along each axis) within which a coded neighbour joins a group's centre.
const GROUP_RADIUS: i64 = 4;
/// Groups a guess chooses among; neighbours beyond them are left out.
const MAX_GROUPS: usize = 4;
/// Coded neighbours a vertex's guess reads, in the adjacency's order: grouping is quadratic in
/// them, and a hostile mesh's hub vertex must not make decoding so.
const MAX_NEIGHBOURS: usize = 16;

/// The adaptive models of the lattice part.
struct Models {
    /// Differences from one group's mean, per axis.
    single: [IntModel; 2],
    /// Differences from the named group's mean, per axis.
    several: [IntModel; 2],
    /// Differences from the previous vertex's pixel, per axis.
    alone: [IntModel; 2],
    /// Which group, by how many there are (2 ..= [`MAX_GROUPS`]).
    choice: Vec<SymbolModel>,
}

impl Models {
    fn new() -> Self {
        Self {
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

fn code_lattice<C: SymbolCoder>(
    c: &mut C,
    pixels: &mut [[u16; 2]],
    size: (u16, u16),
    adj: &VertexAdjacency,
) -> Result<()> {
    let mut models = Models::new();
    let limits = [size.0 as i64, size.1 as i64];
    let (mut coded, mut means) = (Vec::with_capacity(MAX_NEIGHBOURS), Vec::new());
    for v in 0..pixels.len() {
        coded.clear();
        let earlier = adj.neighbours(v).iter().filter(|&&w| (w as usize) < v);
        for &w in earlier.take(MAX_NEIGHBOURS) {
            let p = pixels[w as usize];
            coded.push([p[0] as i64, p[1] as i64]);
        }
        group_means(&coded, &mut means);
        let own = [pixels[v][0] as i64, pixels[v][1] as i64];
        let (guess, axes) = match means.len() {
            0 => {
                let previous = v.checked_sub(1).map_or([0, 0], |u| pixels[u]);
                let guess = [previous[0] as i64, previous[1] as i64];
                (guess, &mut models.alone)
            }
            1 => (means[0], &mut models.single),
            n => {
                let model = &mut models.choice[n - 2];
                let k = c.symbol(nearest(&means, own), model)?;
                let guess = *means
                    .get(k)
                    .ok_or_else(|| Error::Stream("lattice coordinates: no such group".into()))?;
                (guess, &mut models.several)
            }
        };
        for a in 0..2 {
            let d = c.signed(own[a] - guess[a], &mut axes[a])?;
            let value = guess[a] + d;
            if !(0..limits[a]).contains(&value) {
                return Err(Error::Stream(format!(
                    "lattice coordinate of vertex {v} is outside the lattice"
                )));
            }
            pixels[v][a] = value as u16;
        }
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
    code_lattice(&mut enc, &mut pixels.to_vec(), size, &adj)?;
    enc.finish()
}

/// Decodes `vertices` lattice pixels inside a `size` lattice.
pub fn decode_lattice(
    bytes: &[u8],
    vertices: usize,
    size: (u16, u16),
    triangles: &[Triangle],
) -> Result<Vec<[u16; 2]>> {
    entropy::check_capacity(2 * vertices as u64, bytes.len(), "lattice coordinates")?;
    let adj = VertexAdjacency::new(vertices, triangles);
    let mut dec = Decoder::new(bytes)?;
    let mut pixels = vec![[0u16; 2]; vertices];
    code_lattice(&mut dec, &mut pixels, size, &adj)?;
    Ok(pixels)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A strip of quads cut into two charts placed apart in the atlas: every vertex comes back,
    /// the seam's included.
    #[test]
    fn a_strip_cut_into_two_charts_round_trips() {
        let (columns, rows) = (24u32, 6u32);
        let index = |x: u32, y: u32| y * columns + x;
        let mut triangles = Vec::new();
        for y in 0..rows - 1 {
            for x in 0..columns - 1 {
                triangles.push([index(x, y), index(x + 1, y), index(x, y + 1)]);
                triangles.push([index(x + 1, y), index(x + 1, y + 1), index(x, y + 1)]);
            }
        }
        // Columns from 12 on are a second chart, placed 40 pixels lower in the atlas.
        let pixels: Vec<[u16; 2]> = (0..rows)
            .flat_map(|y| (0..columns).map(move |x| (x, y)))
            .map(|(x, y)| {
                let (px, py) = (2 * x as u16, 2 * y as u16);
                if x >= 12 {
                    [px - 20, py + 40]
                } else {
                    [px, py]
                }
            })
            .collect();
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
}
