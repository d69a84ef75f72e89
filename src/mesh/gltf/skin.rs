//! Linear blend skinning: each skin's joints and inverse bind matrices, the joint matrices of a
//! pose, and their weighted blend for one vertex.

use super::nodes::Posed;
use super::validate::check_accessor;
use super::{buffer_data, Buffers};
use gltf::accessor::{DataType, Dimensions};
use nalgebra::Matrix4;

/// A skin: its joint nodes and inverse bind matrices.
pub(super) struct Skin {
    joints: Vec<usize>,
    inverse_bind: Vec<Matrix4<f64>>,
}

/// Every skin of the document; a skin needs an inverse bind matrix per joint (identity when the
/// file gives none).
pub(super) fn read_skins(document: &gltf::Document, data: Buffers) -> Result<Vec<Skin>, String> {
    document
        .skins()
        .map(|skin| {
            let joints: Vec<usize> = skin.joints().map(|j| j.index()).collect();
            check_accessor(
                skin.inverse_bind_matrices(),
                &format!("skin {} inverse bind matrices", skin.index()),
                Dimensions::Mat4,
                &[DataType::F32],
            )?;
            let inverse_bind: Vec<Matrix4<f64>> = match skin
                .reader(|b| buffer_data(data, b))
                .read_inverse_bind_matrices()
            {
                Some(it) => it
                    .map(|m| Matrix4::from_fn(|r, c| m[c][r] as f64))
                    .collect(),
                None => vec![Matrix4::identity(); joints.len()],
            };
            if inverse_bind.len() < joints.len() {
                return Err(format!(
                    "skin {}: {} inverse bind matrices for {} joints",
                    skin.index(),
                    inverse_bind.len(),
                    joints.len()
                ));
            }
            Ok(Skin {
                joints,
                inverse_bind,
            })
        })
        .collect()
}

impl Skin {
    /// Per joint, its world transform in `posed` times its inverse bind matrix.
    pub(super) fn joint_matrices(&self, posed: &Posed) -> Vec<Matrix4<f64>> {
        self.joints
            .iter()
            .zip(&self.inverse_bind)
            .map(|(&j, ibm)| posed.world_of(j) * ibm)
            .collect()
    }
}

/// The weighted sum of the joint matrices, weights normalised to sum 1 (exporters round them);
/// `None` for a vertex no joint moves, which then follows its node.
pub(super) fn blend(
    influences: &[(u16, f32)],
    joint_matrices: &[Matrix4<f64>],
) -> Option<Matrix4<f64>> {
    let mut m = Matrix4::zeros();
    let mut total = 0.0;
    for &(j, w) in influences {
        if w > 0.0 {
            if let Some(jm) = joint_matrices.get(j as usize) {
                m += jm * w as f64;
                total += w as f64;
            }
        }
    }
    (total > 0.0).then(|| m / total)
}

#[cfg(test)]
mod tests {
    use super::super::geometry::Geometry;
    use super::super::nodes::Pose;
    use super::*;
    use std::path::Path;

    /// With every node at rest, each joint matrix is the mesh node's transform in these samples, so
    /// skinning must give the unskinned mesh placed by its node: a check of the matrix conventions.
    #[test]
    fn rest_pose_skinning_is_the_bind_pose() {
        for name in ["CesiumMan.glb", "RiggedFigure.glb"] {
            let path = Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("media")
                .join(name);
            let gltf::Gltf { document, blob } = gltf::Gltf::open(&path).unwrap();
            let buffers = gltf::import_buffers(&document, None, blob).unwrap();
            let scene = document.default_scene().unwrap();
            let geometry = Geometry::gather(&document, &scene, &buffers).unwrap();
            let skins = read_skins(&document, &buffers).unwrap();
            assert!(geometry.parts.iter().all(|p| p.skin.is_some()), "{name}");
            let rest = Pose::new(&document).at(0.0, &[]);
            let skinned = geometry.bake(&rest, &skins);
            let placed = geometry.bake(&rest, &[]);
            let worst = skinned
                .iter()
                .zip(&placed)
                .flat_map(|(a, b)| (0..3).map(move |k| (a[k] - b[k]).abs()))
                .fold(0.0, f32::max);
            assert!(worst < 1e-4, "{name}: {worst}");
        }
    }
}
