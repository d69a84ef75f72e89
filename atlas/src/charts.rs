//! Step 2 of the build, charts: the seed pieces flattened whole where they can be (cut open
//! first where they are not disks, [`crate::whole`]), pieces that cannot split in two and tried
//! again, then iso-charts-like refinement that splits charts whose L2 stretch is too high.
//!
//! A closed piece or one of higher genus is cut across the principal axis of its faces, and each
//! edge-connected part is examined again, up to [`MAX_DEPTH`] times. A piece whose whole
//! flattening fails (folds, or area distortion beyond `uvunwrap`'s bound), or that is still not a
//! disk after those splits, goes to `uvunwrap`'s own segmentation, as every piece did before.
//! Failed pieces are not split recursively: those are big curved pieces, and the principal-axis
//! halves fall apart into many more charts than the segmentation makes
//! (docs/design.md, "Atlas: whole-piece charts and packing").

use crate::seed::components;
use crate::unwrap::{flatten_once, split_faces, Flattening};
use crate::whole::plan;
use crate::AtlasError;

/// Splits of a closed or higher-genus seed piece at most, before its parts go to uvunwrap's
/// segmentation (a torus band needs one split, then one cut per half).
const MAX_DEPTH: u8 = 2;
/// Parts with fewer faces are not split further.
const MIN_SPLIT_FACES: usize = 32;

/// Materials that change between flattenings, and whether each is flattened whole.
struct Materials {
    /// Per face.
    face: Vec<u32>,
    /// Per material: flattened as one polygon (one chart).
    whole: Vec<bool>,
    /// Per material: how many splits made it.
    depth: Vec<u8>,
}

impl Materials {
    /// One polygon per whole material, one per face elsewhere.
    fn polygons(&self) -> Vec<u32> {
        let n = self.whole.len() as u32;
        (0..self.face.len() as u32)
            .map(|f| {
                let m = self.face[f as usize];
                if self.whole[m as usize] {
                    m
                } else {
                    n + f
                }
            })
            .collect()
    }

    /// The whole materials whose faces did not all come back in one chart.
    fn broken(&self, flat: &Flattening) -> Vec<u32> {
        let mut chart_of: Vec<Option<u32>> = vec![None; self.whole.len()];
        let mut broken = vec![false; self.whole.len()];
        for (f, c) in flat.face_chart.iter().enumerate() {
            let (m, Some(c)) = (self.face[f] as usize, c) else {
                continue;
            };
            match chart_of[m] {
                None => chart_of[m] = Some(*c),
                Some(d) if d != *c => broken[m] = true,
                Some(_) => {}
            }
        }
        (0..self.whole.len() as u32)
            .filter(|&m| self.whole[m as usize] && broken[m as usize])
            .collect()
    }

    /// Splits each face set of `which` (a material's or a chart's) across its principal axis;
    /// each half's edge-connected parts become materials, whole if the first face's material was.
    /// Unless `always`, materials too small or too deep to split are handed to the segmentation
    /// instead.
    fn split(
        &mut self,
        positions: &[[f32; 3]],
        triangles: &[[u32; 3]],
        which: &[Vec<usize>],
        always: bool,
    ) {
        let mut label = self.face.clone();
        let mut whole = self.whole.clone();
        let mut depth = self.depth.clone();
        for faces in which {
            let Some(&first) = faces.first() else {
                continue;
            };
            let m = self.face[first] as usize;
            if !always && (faces.len() < MIN_SPLIT_FACES || self.depth[m] >= MAX_DEPTH) {
                whole[m] = false;
                continue;
            }
            let next = whole.len() as u32;
            for (&f, &s) in faces.iter().zip(&split_faces(positions, triangles, faces)) {
                label[f] = next + u32::from(s);
            }
            whole.extend([self.whole[m]; 2]);
            depth.extend([self.depth[m].saturating_add(1); 2]);
        }
        let (face, count) = components(triangles, &label);
        self.whole = vec![false; count as usize];
        self.depth = vec![0; count as usize];
        for (f, &m) in face.iter().enumerate() {
            self.whole[m as usize] = whole[label[f] as usize];
            self.depth[m as usize] = depth[label[f] as usize];
        }
        self.face = face;
    }

    /// The faces of each of `materials`.
    fn faces_of(&self, materials: &[u32]) -> Vec<Vec<usize>> {
        let mut slot = vec![usize::MAX; self.whole.len()];
        for (i, &m) in materials.iter().enumerate() {
            slot[m as usize] = i;
        }
        let mut faces = vec![Vec::new(); materials.len()];
        for (f, &m) in self.face.iter().enumerate() {
            if let Some(list) = faces.get_mut(slot[m as usize]) {
                list.push(f);
            }
        }
        faces
    }
}

/// Each chart's faces.
fn chart_faces(flat: &Flattening) -> Vec<Vec<usize>> {
    let mut chart_faces = vec![Vec::new(); flat.charts as usize];
    for (f, c) in flat.face_chart.iter().enumerate() {
        if let Some(c) = c {
            chart_faces[*c as usize].push(f);
        }
    }
    chart_faces
}

/// The faces of each chart stretched beyond `max_stretch` (with at least two faces).
fn stretched(flat: &Flattening, max_stretch: f64) -> Vec<Vec<usize>> {
    chart_faces(flat)
        .into_iter()
        .enumerate()
        .filter(|(c, faces)| {
            faces.len() >= 2
                && flat.chart_stretch[*c]
                    .value()
                    .is_some_and(|s| s > max_stretch)
        })
        .map(|(_, faces)| faces)
        .collect()
}

/// Flattens the mesh with charts seeded by `face_piece` (one id per face, `pieces` in all),
/// whole where possible, splitting charts stretched beyond `max_stretch` for up to `rounds`
/// rounds.
pub(crate) fn flatten(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    face_piece: &[u32],
    pieces: u32,
    max_stretch: f64,
    rounds: u32,
) -> Result<Flattening, AtlasError> {
    let mut m = Materials {
        face: face_piece.to_vec(),
        whole: vec![true; pieces as usize],
        depth: vec![0; pieces as usize],
    };
    let mut round = 0;
    // Every pass splits a material, gives up whole materials or ends; depths, the number of
    // whole materials and rounds bound the passes, and this bound only guards against a mistake
    // in that reasoning.
    for _ in 0..4 * (u32::from(MAX_DEPTH) + rounds + 2) {
        let plan = plan(positions, triangles, &m.face, &m.whole);
        if !plan.unfit.is_empty() {
            let unfit = m.faces_of(&plan.unfit);
            m.split(positions, triangles, &unfit, false);
            continue;
        }
        let mut flat = flatten_once(positions, triangles, &plan.mesh, &m.face, &m.polygons())?;
        flat.split_rounds = round;
        let broken = m.broken(&flat);
        if !broken.is_empty() {
            broken.iter().for_each(|&b| m.whole[b as usize] = false);
            continue;
        }
        let stretched = stretched(&flat, max_stretch);
        if round >= rounds || stretched.is_empty() {
            return Ok(flat);
        }
        m.split(positions, triangles, &stretched, true);
        round += 1;
    }
    // Not reached on any mesh tried; if it is, everything goes to uvunwrap's segmentation.
    m.whole.iter_mut().for_each(|w| *w = false);
    let plan = plan(positions, triangles, &m.face, &m.whole);
    flatten_once(positions, triangles, &plan.mesh, &m.face, &m.polygons())
}
