//! Which materials (seed pieces, or parts of them) are flattened whole, as one chart each, and
//! the cuts that make them disks.
//!
//! Left to its own segmentation, `uvunwrap` grows charts within a normal cone, so a band around
//! a tube (normals all around the circle) comes back in several charts, and an annulus cannot
//! flatten at all; every chart border is padding in the geometry images. A material that is a
//! disk, or a genus-0 surface with several boundary loops once cuts join them (an annulus: one
//! cut), is instead handed over as one `uvunwrap` polygon, which keeps it in one chart; the
//! unwrapper still parameterises it (LSCM + ARAP) and rejects results that fold or exceed its
//! area distortion bound ([`crate::charts`] splits those). Closed materials and those of higher
//! genus are reported as unfit, to be split before flattening.

use crate::cut::joining_cuts;
use crate::open::{open, OpenMesh};
use crate::topology::{classify, Kind};

/// The mesh with the cuts of the whole materials opened, and the whole materials that no cut of
/// this kind makes a disk.
pub(crate) struct Plan {
    pub mesh: OpenMesh,
    pub unfit: Vec<u32>,
}

/// Classifies each whole material (`face_material` per face, `whole` per material) and opens the
/// cuts of the holed ones.
pub(crate) fn plan(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    face_material: &[u32],
    whole: &[bool],
) -> Plan {
    let mut material_faces = vec![Vec::new(); whole.len()];
    for (f, &m) in face_material.iter().enumerate() {
        if whole[m as usize] {
            material_faces[m as usize].push(f);
        }
    }
    let mut cuts = Vec::new();
    let mut unfit = Vec::new();
    for (m, faces) in material_faces.into_iter().enumerate() {
        if faces.is_empty() {
            continue;
        }
        match classify(triangles, &faces) {
            Kind::Disk => {}
            Kind::Holed(loops) => match joining_cuts(positions, triangles, &faces, &loops) {
                Some(edges) => cuts.push((faces, edges)),
                None => unfit.push(m as u32),
            },
            Kind::Closed | Kind::Other => unfit.push(m as u32),
        }
    }
    Plan {
        mesh: open(positions, triangles, &cuts),
        unfit,
    }
}
