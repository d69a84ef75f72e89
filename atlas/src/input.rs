//! Checks a build's inputs before any work: options, partition length, finite positions,
//! triangle indices, and that the lattice has a pixel per vertex (else the error names one that does).

use crate::{AtlasError, AtlasOptions};

/// Refuses inputs the build cannot use, with an error that says why.
pub(crate) fn check_input(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    partition: &[u32],
    opts: &AtlasOptions,
) -> Result<(), AtlasError> {
    opts.validate()?;
    if partition.len() != positions.len() {
        return Err(AtlasError::PartitionLength {
            partition: partition.len(),
            vertices: positions.len(),
        });
    }
    if let Some(i) = positions
        .iter()
        .position(|p| p.iter().any(|c| !c.is_finite()))
    {
        return Err(AtlasError::NonFinitePosition(i));
    }
    for (t, tri) in triangles.iter().enumerate() {
        if let Some(&v) = tri.iter().find(|&&v| v as usize >= positions.len()) {
            return Err(AtlasError::VertexOutOfRange {
                triangle: t,
                vertex: v,
                vertices: positions.len(),
            });
        }
    }
    let pixels = u64::from(opts.width) * u64::from(opts.height);
    if positions.len() as u64 > pixels {
        return Err(AtlasError::TooManyVertices {
            vertices: positions.len(),
            width: opts.width,
            height: opts.height,
            suggest: suggest_side(positions.len(), opts),
        });
    }
    Ok(())
}

/// A power-of-two square lattice with room for twice the vertices.
fn suggest_side(vertices: usize, opts: &AtlasOptions) -> u32 {
    let mut side = opts
        .width
        .max(opts.height)
        .max(opts.block)
        .next_power_of_two();
    while (side as usize) * (side as usize) < 2 * vertices && side < 16384 {
        side *= 2;
    }
    side
}
