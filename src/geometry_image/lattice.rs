//! The lattice the atlas is built on: a fixed size, or one sized from the vertex count and grown
//! until the charts fit.

use crate::error::{Error, Result};
use crate::mesh::Point;
use crate::motion::Partition;

/// The size of the geometry-image lattice.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Lattice {
    /// Sized from the vertex count (see [`auto_side`]), grown until the charts fit.
    Auto,
    /// Exactly this width and height.
    Fixed(u16, u16),
}

/// Lattice pixels per vertex for `Lattice::Auto`. The papers' sequences (2900–8400 vertices) use
/// 256×256; a small mesh in that lattice pays for pixels it does not need: RiggedFigure (370
/// vertices) costs 96 bpvf at 256×256 and 37 bpvf at 96×96 at about the same RMSE, Fox (1728) is
/// best near 224×224 (encode --lattice WxH, eval; JPEG q30/q75).
const AUTO_PIXELS_PER_VERTEX: f64 = 28.0;

/// Lattice pixels per vertex below which `Lattice::Auto` grows past 256×256: BrainStem (34 159
/// vertices) at 336×336 had 70 % of its vertices moved off colliding pixels, at 512×512 28 %. At
/// 7.5 the papers' largest meshes (8431-vertex horses) stay at 256×256 and BrainStem gets 512×512.
const MIN_PIXELS_PER_VERTEX: f64 = 7.5;

/// The first lattice side `Lattice::Auto` tries for `vertices`: about
/// [`AUTO_PIXELS_PER_VERTEX`] pixels per vertex, at least 32, at most the papers' 256 unless that
/// leaves fewer than [`MIN_PIXELS_PER_VERTEX`] (meshes over 8738 vertices).
pub fn auto_side(vertices: usize) -> u16 {
    let v = vertices as f64;
    let side = (v * AUTO_PIXELS_PER_VERTEX)
        .sqrt()
        .min(256.0)
        .max((v * MIN_PIXELS_PER_VERTEX).sqrt());
    round_up_16(side).max(32)
}

fn round_up_16(x: f64) -> u16 {
    ((x / 16.0).ceil() * 16.0).min(4096.0) as u16
}

/// Fails unless `w`×`h` is a lattice the stream can carry.
pub fn check(w: u16, h: u16) -> Result<()> {
    let max = crate::stream::header::MAX_LATTICE_SIDE;
    if w == 0 || h == 0 || w % 16 != 0 || h % 16 != 0 || w > max || h > max {
        return Err(Error::option(
            "lattice",
            format!("{w}x{h}: width and height must be multiples of 16 between 16 and {max}"),
        ));
    }
    Ok(())
}

/// An atlas built once and handed to every encoding on the same first frame, partition and
/// lattice option: the automatic choice codes several predictors on one partition, and building
/// the atlas costs as much as coding a dozen frames' pictures.
#[derive(Debug, Default)]
pub struct AtlasCache(std::sync::OnceLock<((u16, u16), atlas::Atlas)>);

impl AtlasCache {
    /// The cached atlas, or `build`'s result (kept for the next call).
    pub fn get_or_build(
        &self,
        build: impl FnOnce() -> Result<((u16, u16), atlas::Atlas)>,
    ) -> Result<((u16, u16), atlas::Atlas)> {
        if let Some(built) = self.0.get() {
            return Ok(built.clone());
        }
        let built = build()?;
        // A racing caller's equal atlas may have been kept instead; either serves.
        let _ = self.0.set(built.clone());
        Ok(built)
    }
}

/// Builds the atlas on the requested lattice, or for `Lattice::Auto` on the smallest lattice from
/// [`auto_side`] upwards on which the charts fit.
pub fn build_atlas(
    reference: &[Point],
    triangles: &[[u32; 3]],
    partition: &Partition,
    lattice: Lattice,
) -> Result<((u16, u16), atlas::Atlas)> {
    let build = |w: u16, h: u16| {
        atlas::build(
            reference,
            triangles,
            partition.labels(),
            &atlas::AtlasOptions {
                width: u32::from(w),
                height: u32::from(h),
                ..atlas::AtlasOptions::default()
            },
        )
    };
    let mut side = match lattice {
        Lattice::Fixed(w, h) => return Ok(((w, h), build(w, h)?)),
        Lattice::Auto => auto_side(reference.len()),
    };
    loop {
        let next = match build(side, side) {
            Ok(a) => return Ok(((side, side), a)),
            Err(atlas::AtlasError::ChartsDoNotFit { blocks, block, .. }) => {
                // Room for the blocks with some slack, and at least a quarter more each time.
                let needed = f64::from(block) * (blocks as f64 * 1.3).sqrt();
                round_up_16(needed.max(f64::from(side) * 1.25))
            }
            Err(atlas::AtlasError::TooManyVertices { vertices, .. }) => {
                round_up_16((vertices as f64 * 2.0).sqrt().max(f64::from(side) * 1.25))
            }
            Err(e) => return Err(e.into()),
        };
        if side >= 4096 {
            return Err(Error::Mesh(format!(
                "atlas: the charts do not fit even a {side}x{side} lattice"
            )));
        }
        side = next;
    }
}

#[cfg(test)]
mod tests {
    use super::auto_side;

    #[test]
    fn auto_lattice_scales_with_vertices_up_to_the_papers_size() {
        assert_eq!(auto_side(3), 32);
        assert_eq!(auto_side(160), 80);
        assert_eq!(auto_side(1728), 224);
        assert_eq!(auto_side(3030), 256);
        assert_eq!(auto_side(8431), 256);
        assert_eq!(auto_side(34_159), 512);
        assert_eq!(auto_side(160) % 16, 0);
    }
}
