//! The attributes part (`ATTR`): texture coordinates per vertex and the material of each triangle,
//! coded once for the whole animation, in the decoder's vertex and triangle order.
//!
//! Each texture-coordinate set is quantised to `bits` bits over its own bounding box and coded by
//! `super::texcoords` (reuse of a welded copy's coordinate, else the 3D triangle projected into
//! UV) through the stream's adaptive entropy coder. Materials are one
//! "same as the previous triangle" bit per triangle, and the index when not.
//! The coding routine is written once for both directions ([`SymbolCoder`]).

use super::bytes::{ByteReader, ByteWriter};
use super::entropy::{self, BitModel, SymbolCoder, UIntModel};
use super::texcoords::{code_set, Levels, Schedule};
use crate::error::{Error, Result};
use crate::mesh::{Attributes, Point, Triangle};

const VERSION: u8 = 2;
/// glTF viewers use a handful of sets; more is a malformed part.
const MAX_SETS: usize = 8;
const MAX_NAME: usize = 4096;

/// Codes (or decodes into) the material of each triangle, indices below `count`.
fn code_materials<C: SymbolCoder>(coder: &mut C, materials: &mut [u32], count: u32) -> Result<()> {
    let (mut same_model, mut index_model) = (BitModel::default(), UIntModel::default());
    let mut previous = 0u32;
    for m in materials.iter_mut() {
        let same = coder.bit(*m == previous, &mut same_model)?;
        if !same {
            let index = coder.unsigned(u64::from(*m), &mut index_model)?;
            *m = u32::try_from(index)
                .ok()
                .filter(|&i| i < count)
                .ok_or_else(|| Error::Stream("attributes: material index out of range".into()))?;
        } else {
            *m = previous;
        }
        previous = *m;
    }
    Ok(())
}

fn check_triangles(triangles: &[Triangle], vertex_count: usize) -> Result<()> {
    match triangles
        .iter()
        .flatten()
        .any(|&i| i as usize >= vertex_count)
    {
        true => Err(Error::Stream(
            "attributes: a triangle names a missing vertex".into(),
        )),
        false => Ok(()),
    }
}

/// A coordinate set's quantisation grid: its bounding box on `bits` bits.
struct Grid {
    lo: [f32; 2],
    hi: [f32; 2],
    max_level: i64,
}

impl Grid {
    fn fit(set: &[[f32; 2]], bits: u8) -> Self {
        let mut lo = [f32::INFINITY; 2];
        let mut hi = [f32::NEG_INFINITY; 2];
        for uv in set {
            for a in 0..2 {
                lo[a] = lo[a].min(uv[a]);
                hi[a] = hi[a].max(uv[a]);
            }
        }
        if set.is_empty() {
            (lo, hi) = ([0.0; 2], [0.0; 2]);
        }
        Self {
            lo,
            hi,
            max_level: (1i64 << bits) - 1,
        }
    }

    fn quantise(&self, uv: [f32; 2]) -> [i64; 2] {
        std::array::from_fn(|a| {
            let range = f64::from(self.hi[a]) - f64::from(self.lo[a]);
            if range <= 0.0 {
                return 0;
            }
            let s = (f64::from(uv[a]) - f64::from(self.lo[a])) / range;
            (s * self.max_level as f64)
                .round()
                .clamp(0.0, self.max_level as f64) as i64
        })
    }

    fn levels(&self) -> Levels {
        Levels {
            step: std::array::from_fn(|a| {
                (f64::from(self.hi[a]) - f64::from(self.lo[a])) / self.max_level as f64
            }),
            max_level: self.max_level,
        }
    }

    fn dequantise(&self, level: [i64; 2]) -> [f32; 2] {
        std::array::from_fn(|a| {
            let range = f64::from(self.hi[a]) - f64::from(self.lo[a]);
            (f64::from(self.lo[a]) + range * level[a] as f64 / self.max_level as f64) as f32
        })
    }
}

/// The part's bytes for `attributes` of a mesh whose decoder sees `triangles` (both in the decoder's
/// order), coordinates quantised to `uv_bits` bits (1..=24).
pub fn encode_attributes(
    attributes: &Attributes,
    triangles: &[Triangle],
    positions: &[Point],
    uv_bits: u8,
) -> Result<Vec<u8>> {
    let vertex_count = positions.len();
    if !(1..=24).contains(&uv_bits) {
        return Err(Error::option(
            "uv_bits",
            format!("{uv_bits}: must be 1 to 24"),
        ));
    }
    attributes.check(vertex_count, triangles.len())?;
    check_triangles(triangles, vertex_count)?;
    if attributes.texcoords.len() > MAX_SETS {
        return Err(Error::Mesh(format!(
            "{} texture coordinate sets; at most {MAX_SETS} are kept",
            attributes.texcoords.len()
        )));
    }
    let mut out = ByteWriter::new();
    out.u8(VERSION).u8(attributes.texcoords.len() as u8);
    let schedule = Schedule::new(triangles, positions);
    let mut coder = entropy::Encoder::new();
    for set in &attributes.texcoords {
        let grid = Grid::fit(set, uv_bits);
        out.u8(uv_bits)
            .f32(grid.lo[0])
            .f32(grid.lo[1])
            .f32(grid.hi[0])
            .f32(grid.hi[1]);
        let mut levels: Vec<[i64; 2]> = set.iter().map(|&uv| grid.quantise(uv)).collect();
        let mesh = (triangles, positions);
        code_set(&mut coder, &schedule, mesh, &mut levels, &grid.levels())?;
    }
    // Names without per-triangle indices say nothing: they are dropped.
    let names: &[String] = match attributes.materials.is_empty() {
        true => &[],
        false => &attributes.material_names,
    };
    out.u32(names.len() as u32);
    for name in names {
        out.blob(&name.as_bytes()[..name.len().min(MAX_NAME)]);
    }
    let mut materials = attributes.materials.clone();
    if !names.is_empty() {
        code_materials(&mut coder, &mut materials, names.len() as u32)?;
    }
    out.blob(&coder.finish()?);
    Ok(out.into_bytes())
}

/// Reads the part written by [`encode_attributes`] for a stream whose decoded first frame has
/// `triangles` and frame-0 `positions`.
pub fn decode_attributes(
    bytes: &[u8],
    triangles: &[Triangle],
    positions: &[Point],
) -> Result<Attributes> {
    let vertex_count = positions.len();
    check_triangles(triangles, vertex_count)?;
    let mut r = ByteReader::new(bytes, "attributes");
    if r.u8()? != VERSION {
        return Err(Error::Stream("attributes: unknown version".into()));
    }
    let sets = r.u8()? as usize;
    if sets > MAX_SETS {
        return Err(Error::Stream(format!("attributes: {sets} coordinate sets")));
    }
    let mut grids = Vec::with_capacity(sets);
    for _ in 0..sets {
        let bits = r.u8()?;
        let (lo, hi) = ([r.f32()?, r.f32()?], [r.f32()?, r.f32()?]);
        let finite = lo.iter().chain(&hi).all(|c| c.is_finite());
        if !(1..=24).contains(&bits) || !finite || lo[0] > hi[0] || lo[1] > hi[1] {
            return Err(Error::Stream("attributes: bad coordinate grid".into()));
        }
        grids.push(Grid {
            lo,
            hi,
            max_level: (1i64 << bits) - 1,
        });
    }
    let names = r.u32()? as usize;
    if names > triangles.len().max(1) || names > r.remaining() / 4 {
        return Err(Error::Stream(format!("attributes: {names} materials")));
    }
    let material_names = (0..names)
        .map(|_| {
            let raw = r.blob()?;
            String::from_utf8(raw.to_vec())
                .map_err(|_| Error::Stream("attributes: material name is not UTF-8".into()))
        })
        .collect::<Result<Vec<_>>>()?;
    let payload = r.blob()?;
    r.finish()?;
    let mut coder = entropy::Decoder::new(payload)?;
    let schedule = Schedule::new(triangles, positions);
    let mut texcoords = Vec::with_capacity(sets);
    for grid in &grids {
        let mut levels = vec![[0i64; 2]; vertex_count];
        let mesh = (triangles, positions);
        code_set(&mut coder, &schedule, mesh, &mut levels, &grid.levels())?;
        texcoords.push(levels.into_iter().map(|l| grid.dequantise(l)).collect());
    }
    let mut materials = Vec::new();
    if names > 0 {
        materials = vec![0u32; triangles.len()];
        code_materials(&mut coder, &mut materials, names as u32)?;
    }
    Ok(Attributes {
        texcoords,
        materials,
        material_names,
    })
}
