//! The lattice the atlas is built on: a fixed size, or one sized from the vertex count and grown
//! until the charts fit.

use crate::error::{Error, Result};
use crate::mesh::Point;
use crate::motion::Partition;

/// The size of the geometry-image lattice.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Lattice {
    /// Sized from the vertex count (about 2 pixels a vertex), grown until the charts fit.
    #[default]
    Auto,
    /// Exactly this width and height.
    Fixed(u16, u16),
}

/// Lattice pixels per vertex `Lattice::Auto` starts from; it then grows until the charts fit, so
/// in practice the lattice is the smallest one the atlas packs. Every pixel is coded, and pixels
/// without a vertex (interpolated chart interiors, padding between charts) only cost bits: the
/// smallest lattice that fits needs the fewest bits at equal surface RMSE, although more vertices
/// then move off a shared rounded pixel (docs/design.md, "Lattice: the smallest that fits").
const AUTO_PIXELS_PER_VERTEX: f64 = 1.9;

/// The first lattice side `Lattice::Auto` tries for `vertices`: about
/// `AUTO_PIXELS_PER_VERTEX` pixels per vertex, at least 32, in multiples of 16.
pub fn auto_side(vertices: usize) -> u16 {
    round_up_16((vertices as f64 * AUTO_PIXELS_PER_VERTEX).sqrt()).max(32)
}

fn round_up_16(x: f64) -> u16 {
    ((x / 16.0).ceil() * 16.0).min(f64::from(MAX_LATTICE_SIDE)) as u16
}

/// Largest lattice side the encoder makes (and a decoder accepts): a forged stream cannot make the
/// picture decoders allocate pictures of 3 × 65535 × 65535 samples.
pub const MAX_LATTICE_SIDE: u16 = 4096;

/// Fails unless `w`×`h` is a lattice the stream can carry.
pub fn check(w: u16, h: u16) -> Result<()> {
    let max = MAX_LATTICE_SIDE;
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
#[cfg(feature = "encode")]
#[derive(Debug, Default)]
pub struct AtlasCache(std::sync::OnceLock<((u16, u16), atlas::Atlas)>);

#[cfg(feature = "encode")]
impl AtlasCache {
    /// A cache that already holds `built` (an encoding's atlas, handed on to later encodings on
    /// the same first frame, partition and lattice option).
    pub fn holding(built: ((u16, u16), atlas::Atlas)) -> Self {
        Self(std::sync::OnceLock::from(built))
    }

    /// The atlas held, if one was built.
    pub fn into_inner(self) -> Option<((u16, u16), atlas::Atlas)> {
        self.0.into_inner()
    }

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
#[cfg(feature = "encode")]
pub fn build_atlas(
    reference: &[Point],
    triangles: &[[u32; 3]],
    partition: &Partition,
    lattice: Lattice,
) -> Result<((u16, u16), atlas::Atlas)> {
    let options = |w: u16, h: u16| atlas::AtlasOptions {
        width: u32::from(w),
        height: u32::from(h),
        ..atlas::AtlasOptions::default()
    };
    let labels = partition.labels();
    let mut side = match lattice {
        Lattice::Fixed(w, h) => {
            let atlas = atlas::build(reference, triangles, labels, &options(w, h))?;
            return Ok(((w, h), atlas));
        }
        Lattice::Auto => auto_side(reference.len()),
    };
    // The charts are flattened once (most of the work), then laid out on each size tried.
    let mut flattened: Option<atlas::Flattened> = None;
    loop {
        let u32_side = u32::from(side);
        let attempt = match &flattened {
            Some(charts) => charts.lay_out(u32_side, u32_side),
            None => atlas::Flattened::new(reference, triangles, labels, &options(side, side))
                .and_then(|charts| {
                    let atlas = charts.lay_out(u32_side, u32_side);
                    flattened = Some(charts);
                    atlas
                }),
        };
        let next = match attempt {
            Ok(a) => return Ok(((side, side), a)),
            // The smallest square with as many blocks as the charts need, then 16 more at a time:
            // the greedy packer may need a little more than the bound, and each step of 16 costs a
            // build but a larger lattice than needed costs bits in every frame.
            Err(atlas::AtlasError::ChartsDoNotFit { blocks, block, .. }) => {
                round_up_16(f64::from(block) * (blocks as f64).sqrt()).max(side + 16)
            }
            Err(atlas::AtlasError::TooManyVertices { vertices, .. }) => {
                round_up_16((vertices as f64).sqrt()).max(side + 16)
            }
            Err(e) => return Err(e.into()),
        };
        if side >= MAX_LATTICE_SIDE {
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
    fn auto_lattice_starts_near_two_pixels_per_vertex() {
        assert_eq!(auto_side(3), 32);
        assert_eq!(auto_side(160), 32);
        assert_eq!(auto_side(1297), 64);
        assert_eq!(auto_side(3273), 80);
        assert_eq!(auto_side(8431), 128);
        assert_eq!(auto_side(34_159), 256);
        assert_eq!(auto_side(1728) % 16, 0);
    }
}
