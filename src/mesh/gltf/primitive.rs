//! One primitive's vertex data (a part of the scene's mesh): its positions, morph target
//! displacements and joint influences, read after checking the accessors that feed them.

use super::validate::{check_accessor, check_extent};
use super::{buffer_data, Buffers};
use crate::mesh::Point;
use gltf::accessor::{DataType, Dimensions};
use nalgebra::Vector4;

/// Joint influence sets (`JOINTS_n`/`WEIGHTS_n`) read per vertex.
pub(super) const MAX_INFLUENCE_SETS: u32 = 4;

/// The vertices of a node's primitive and what moves them.
pub(super) struct Part {
    pub(super) node: usize,
    pub(super) skin: Option<usize>,
    pub(super) positions: Vec<Point>,
    /// Position displacements per morph target.
    targets: Vec<Vec<Point>>,
    /// Per vertex, `influences_per_vertex` (joint, weight) pairs.
    influences: Vec<(u16, f32)>,
    influences_per_vertex: usize,
}

impl Part {
    /// The vertex data of one primitive; `None` when it draws no triangles or has no positions.
    pub(super) fn read<'a>(
        node: &gltf::Node<'a>,
        primitive: &gltf::Primitive<'a>,
        data: Buffers,
        name: &str,
    ) -> Result<Option<Self>, String> {
        use gltf::mesh::Mode;
        if !matches!(
            primitive.mode(),
            Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
        ) {
            return Ok(None);
        }
        check_vertex_accessors(primitive, name)?;
        let reader = primitive.reader(|b| buffer_data(data, b));
        let Some(positions) = reader.read_positions() else {
            return Ok(None);
        };
        let positions: Vec<Point> = positions.collect();
        let n = positions.len();
        if positions.iter().flatten().any(|c| !c.is_finite()) {
            return Err(format!("{name}: a position is not a finite number"));
        }
        let targets = read_morph_targets(primitive, data, n, name)?;
        let skin = node.skin().map(|s| s.index());
        let sets = match skin {
            Some(_) => read_influence_sets(primitive, data, n, name)?,
            None => Vec::new(),
        };
        let influences_per_vertex = 4 * sets.len();
        let influences = (0..n)
            .flat_map(|v| {
                sets.iter()
                    .flat_map(move |s| s[4 * v..4 * v + 4].iter().copied())
            })
            .collect();
        Ok(Some(Part {
            node: node.index(),
            skin: skin.filter(|_| influences_per_vertex > 0),
            positions,
            targets,
            influences,
            influences_per_vertex,
        }))
    }

    /// Vertex `v` displaced by the morph targets at `weights`, as a homogeneous point.
    pub(super) fn morphed(&self, v: usize, weights: &[f64]) -> Vector4<f64> {
        let p = self.positions[v];
        let mut p = Vector4::new(p[0] as f64, p[1] as f64, p[2] as f64, 1.0);
        for (target, &w) in self.targets.iter().zip(weights) {
            if w != 0.0 {
                let d = target[v];
                p.x += w * d[0] as f64;
                p.y += w * d[1] as f64;
                p.z += w * d[2] as f64;
            }
        }
        p
    }

    /// The (joint, weight) pairs of vertex `v`.
    pub(super) fn influences(&self, v: usize) -> &[(u16, f32)] {
        let k = self.influences_per_vertex;
        &self.influences[v * k..(v + 1) * k]
    }
}

/// Checks every accessor the reader will open: positions (base and morph) must be float triples,
/// morph normals and tangents too, joints and weights of the types glTF allows.
fn check_vertex_accessors(primitive: &gltf::Primitive, name: &str) -> Result<(), String> {
    // The reader would take quantised (KHR_mesh_quantization) positions for floats.
    let float_vec3 =
        |a: &gltf::Accessor| a.data_type() == DataType::F32 && a.dimensions() == Dimensions::Vec3;
    let positions_accessors = primitive
        .get(&gltf::Semantic::Positions)
        .into_iter()
        .chain(primitive.morph_targets().filter_map(|t| t.positions()));
    for a in positions_accessors {
        if !float_vec3(&a) {
            return Err(format!(
                "{name}: positions in accessor {} are not float triples (quantised meshes are not supported)",
                a.index()
            ));
        }
        check_extent(&a, &format!("{name} positions"))?;
    }
    // Morph normals and tangents are not used, but reading the targets opens their accessors.
    for target in primitive.morph_targets() {
        for a in [target.normals(), target.tangents()] {
            check_accessor(
                a,
                &format!("{name} morph target"),
                Dimensions::Vec3,
                &[DataType::F32],
            )?;
        }
    }
    for set in 0..MAX_INFLUENCE_SETS {
        check_accessor(
            primitive.get(&gltf::Semantic::Joints(set)),
            &format!("{name} JOINTS_{set}"),
            Dimensions::Vec4,
            &[DataType::U8, DataType::U16],
        )?;
        check_accessor(
            primitive.get(&gltf::Semantic::Weights(set)),
            &format!("{name} WEIGHTS_{set}"),
            Dimensions::Vec4,
            &[DataType::F32, DataType::U8, DataType::U16],
        )?;
    }
    Ok(())
}

/// Per morph target, the displacement of each of the `n` vertices (zero for a target without
/// positions); each must cover every vertex with finite numbers.
fn read_morph_targets(
    primitive: &gltf::Primitive,
    data: Buffers,
    n: usize,
    name: &str,
) -> Result<Vec<Vec<Point>>, String> {
    let reader = primitive.reader(|b| buffer_data(data, b));
    let mut targets = Vec::new();
    for (t, (displacements, _, _)) in reader.read_morph_targets().enumerate() {
        let d: Vec<Point> = match displacements {
            Some(it) => it.collect(),
            None => vec![[0.0; 3]; n],
        };
        if d.len() != n || d.iter().flatten().any(|c| !c.is_finite()) {
            return Err(format!(
                "{name}: morph target {t} has {} finite displacements for {n} vertices",
                d.len()
            ));
        }
        targets.push(d);
    }
    Ok(targets)
}

/// The (joint, weight) pairs of each `JOINTS_n`/`WEIGHTS_n` set present (up to the first missing
/// one), four per vertex; each must cover all `n` vertices.
fn read_influence_sets(
    primitive: &gltf::Primitive,
    data: Buffers,
    n: usize,
    name: &str,
) -> Result<Vec<Vec<(u16, f32)>>, String> {
    let reader = primitive.reader(|b| buffer_data(data, b));
    let mut sets = Vec::new();
    for set in 0..MAX_INFLUENCE_SETS {
        let (Some(joints), Some(weights)) = (reader.read_joints(set), reader.read_weights(set))
        else {
            break;
        };
        let pairs: Vec<(u16, f32)> = joints
            .into_u16()
            .zip(weights.into_f32())
            .flat_map(|(j, w)| j.into_iter().zip(w))
            .collect();
        if pairs.len() != 4 * n {
            return Err(format!(
                "{name}: JOINTS_{set}/WEIGHTS_{set} cover {} of {n} vertices",
                pairs.len() / 4
            ));
        }
        sets.push(pairs);
    }
    Ok(sets)
}
