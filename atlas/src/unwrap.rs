//! Flattening with `uvunwrap`: one run over the whole mesh, charts kept within materials and
//! polygons, read back as per-face charts and 2D corners with their stretch; and the principal-
//! axis split that [`crate::charts`] uses to cut a chart in two.

use crate::open::OpenMesh;
use crate::stretch::{dot, StretchSum};
use crate::AtlasError;

/// A flattened mesh: every charted face knows its chart and its corners' 2D
/// positions in surface units (one common scale for all charts).
pub(crate) struct Flattening {
    /// Dense chart id per face; `None` for faces the unwrapper dropped (degenerate).
    pub face_chart: Vec<Option<u32>>,
    /// 2D corner positions per face, in the units of the 3D positions.
    pub corner_uv: Vec<[[f64; 2]; 3]>,
    /// Number of charts.
    pub charts: u32,
    /// Stretch sums per chart.
    pub chart_stretch: Vec<StretchSum>,
    /// Rounds of splitting that were run.
    pub split_rounds: u32,
}

fn position(positions: &[[f32; 3]], v: u32) -> [f64; 3] {
    positions
        .get(v as usize)
        .map_or([0.0; 3], |p| p.map(f64::from))
}

/// One `uvunwrap` run on the opened mesh where charts never cross a material boundary and the
/// faces of one polygon stay in one chart; the stretch is measured on the input mesh.
pub(crate) fn flatten_once(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    open: &OpenMesh,
    materials: &[u32],
    polygons: &[u32],
) -> Result<Flattening, AtlasError> {
    let out = unwrap(&open.positions, &open.triangles, materials, polygons)?;
    let mut flat = read_charts(&out, triangles.len());
    flat.chart_stretch = vec![StretchSum::default(); flat.charts as usize];
    for (f, tri) in triangles.iter().enumerate() {
        if let Some(c) = flat.face_chart[f] {
            let q = tri.map(|v| position(positions, v));
            flat.chart_stretch[c as usize].add(q, flat.corner_uv[f]);
        }
    }
    Ok(flat)
}

/// Runs `uvunwrap` on the mesh, one chart hint per face in `materials`.
fn unwrap(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    materials: &[u32],
    polygons: &[u32],
) -> Result<uvunwrap::Atlas, AtlasError> {
    let indices: Vec<u32> = triangles.iter().flatten().copied().collect();
    let mesh = uvunwrap::MeshInput {
        face_materials: Some(materials),
        polygons: Some(polygons),
        ..uvunwrap::MeshInput::new(positions, &indices)
    };
    let options = uvunwrap::Options {
        padding: 0,
        // Wider normal cones and a tighter area-distortion bound than the
        // lightmap defaults (70°, 4): fewer, larger charts with lower stretch
        // and better packing
        // (docs/design.md, "Atlas: whole-piece charts and packing").
        max_chart_angle: 89.0,
        max_area_distortion: 2.0,
        packing: uvunwrap::Packing::Fast,
        ..uvunwrap::Options::default()
    };
    // uvunwrap's sparse Cholesky (faer's AMD ordering) has been seen to index out of bounds on a
    // large many-part mesh (BrainStem, 34k vertices); a bug in a dependency must still reach the
    // user as an error, not a crash.
    let out = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        uvunwrap::generate(&[mesh], &options)
    }))
    .map_err(|payload| {
        let what = payload
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| payload.downcast_ref::<&str>().copied())
            .unwrap_or("unknown failure");
        AtlasError::UnwrapPanicked(what.to_string())
    })??;
    Ok(out)
}

/// Each face's dense chart id (`None` where uvunwrap dropped the face or split its corners over
/// charts) and its corners' 2D positions in surface units; stretch sums left empty.
fn read_charts(out: &uvunwrap::Atlas, faces: usize) -> Flattening {
    let texels = f64::from(out.texels_per_unit);
    let (w, h) = (f64::from(out.width), f64::from(out.height));
    let mesh = out.meshes.first();
    let mut dense = std::collections::HashMap::new();
    let mut face_chart = Vec::with_capacity(faces);
    let mut corner_uv = Vec::with_capacity(faces);
    for f in 0..faces {
        let corners: Option<Vec<&uvunwrap::OutputVertex>> = (0..3)
            .map(|k| {
                let i = mesh?.indices.get(3 * f + k)?;
                mesh?.vertices.get(*i as usize)
            })
            .collect();
        let Some(corners) = corners else {
            face_chart.push(None);
            corner_uv.push([[0.0; 2]; 3]);
            continue;
        };
        let uv = [0, 1, 2].map(|k| {
            let p = corners[k].uv;
            [f64::from(p[0]) * w / texels, f64::from(p[1]) * h / texels]
        });
        let chart = match (corners[0].chart, corners[1].chart, corners[2].chart) {
            (Some(a), Some(b), Some(c)) if a == b && b == c => {
                let next = dense.len() as u32;
                Some(*dense.entry(a).or_insert(next))
            }
            _ => None,
        };
        face_chart.push(chart);
        corner_uv.push(uv);
    }
    Flattening {
        face_chart,
        corner_uv,
        charts: dense.len() as u32,
        chart_stretch: Vec::new(),
        split_rounds: 0,
    }
}

/// Splits a chart's faces in two halves across the principal axis of their
/// centroids; iso-charts uses a spectral embedding, a principal axis is the
/// cheap version of the same idea (cut across the longest extent).
pub(crate) fn split_faces(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    faces: &[usize],
) -> Vec<bool> {
    let centroids: Vec<[f64; 3]> = faces
        .iter()
        .map(|&f| {
            let q = triangles[f].map(|v| position(positions, v));
            [0, 1, 2].map(|i| (q[0][i] + q[1][i] + q[2][i]) / 3.0)
        })
        .collect();
    let n = centroids.len().max(1) as f64;
    let mean = [0, 1, 2].map(|i| centroids.iter().map(|c| c[i]).sum::<f64>() / n);
    let mut cov = [[0.0; 3]; 3];
    for c in &centroids {
        let d = [c[0] - mean[0], c[1] - mean[1], c[2] - mean[2]];
        for (i, row) in cov.iter_mut().enumerate() {
            for (j, x) in row.iter_mut().enumerate() {
                *x += d[i] * d[j];
            }
        }
    }
    let mut axis = [1.0, 0.7, 0.3];
    for _ in 0..50 {
        let next = [0, 1, 2].map(|i| dot(cov[i], axis));
        let len = dot(next, next).sqrt();
        if !(len > 0.0) {
            break;
        }
        axis = next.map(|x| x / len);
    }
    let mut proj: Vec<f64> = centroids.iter().map(|c| dot(*c, axis)).collect();
    let mut sorted = proj.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted.get(sorted.len() / 2).copied().unwrap_or(0.0);
    let mut side: Vec<bool> = proj.iter_mut().map(|p| *p < median).collect();
    // Identical centroids would leave one side empty; alternate instead.
    if side.iter().all(|&s| s) || side.iter().all(|&s| !s) {
        side.iter_mut()
            .enumerate()
            .for_each(|(i, s)| *s = i % 2 == 0);
    }
    side
}
