//! Texture-coordinate prediction for the attributes part: the order vertices are coded in and
//! how each one's quantised coordinate is predicted, written once for both directions.
//!
//! glTF meshes (and the OBJ reader) split a vertex wherever its UV or normal differs, so the
//! decoded triangles are cut at every texture seam and often at every hard edge (Fox: every
//! triangle stands alone). The coder therefore walks a *welded* mesh — vertices joined where the
//! decoded frame-0 positions are bit-identical, which the decoder knows before the UVs — and:
//! - a vertex whose welded position already has coded copies first says whether it reuses one of
//!   their coordinates (a split for normals only, or the near side of a seam), the candidate
//!   nearest the geometric prediction first;
//! - otherwise its coordinate is predicted from the two other corners of the triangle it is
//!   reached through by projecting the 3D triangle into UV (as Draco's texture-coordinate
//!   predictor does), with one adaptive bit for the side of the edge the corner falls on (mirrored
//!   charts flip it); with one coded corner, that corner; with none, the previous vertex.
//!
//! The walk is depth first over triangles that share the input's vertices across an edge (surely
//! no seam), and only when none is left over triangles that share positions (perhaps a seam), so
//! a chart is finished before the walk jumps.

use super::entropy::{BitModel, IntModel, SymbolCoder, UIntModel};
use crate::error::{Error, Result};
use crate::mesh::{Point, Triangle};
use std::collections::HashMap;

/// Distinct coordinates remembered per welded position (real meshes have a handful).
const MAX_COPIES: usize = 16;

/// One vertex to code: the vertex, and the triangle and corner it is reached through (`None` for
/// vertices in no triangle).
#[derive(Clone, Copy)]
pub(super) struct Step {
    vertex: u32,
    corner: Option<(u32, u8)>,
}

/// The coding order and the welded copies of each vertex: computed from the decoded triangles and
/// frame-0 positions alone, so the encoder and the decoder agree.
pub(super) struct Schedule {
    steps: Vec<Step>,
    /// Welded position id of each vertex.
    weld: Vec<u32>,
    welded_count: usize,
}

fn edge_key(a: u32, b: u32) -> u64 {
    (u64::from(a.min(b)) << 32) | u64::from(a.max(b))
}

fn weld(positions: &[Point]) -> (Vec<u32>, usize) {
    let mut ids: HashMap<[u32; 3], u32> = HashMap::with_capacity(positions.len());
    let weld = positions
        .iter()
        .map(|p| {
            let next = ids.len() as u32;
            *ids.entry(p.map(f32::to_bits)).or_insert(next)
        })
        .collect();
    (weld, ids.len())
}

/// Triangles waiting to be walked into: (triangle, the corner opposite the edge it is entered
/// through). `sure` ones share the input's vertices on that edge (no seam), `welded` ones only
/// positions.
#[derive(Default)]
struct Gates {
    sure: Vec<(u32, u8)>,
    welded: Vec<(u32, u8)>,
}

/// The walk's view of the mesh: triangles, welded ids and the triangles on each welded edge.
struct Walk<'a> {
    triangles: &'a [Triangle],
    weld: &'a [u32],
    by_edge: HashMap<u64, Vec<u32>>,
}

impl Walk<'_> {
    fn welded_edge(&self, a: u32, b: u32) -> u64 {
        edge_key(self.weld[a as usize], self.weld[b as usize])
    }

    /// Queues the not yet visited triangles across each edge of triangle `t`.
    fn open_gates(&self, t: u32, visited: &[bool], gates: &mut Gates) {
        let tri = self.triangles[t as usize];
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            let key = self.welded_edge(a, b);
            for &n in self.by_edge.get(&key).map_or(&[][..], Vec::as_slice) {
                if visited[n as usize] {
                    continue;
                }
                let other = self.triangles[n as usize];
                let opposite = (0..3)
                    .find(|&c| self.welded_edge(other[(c + 1) % 3], other[(c + 2) % 3]) == key);
                let Some(c) = opposite else { continue };
                let shares = other.contains(&a) && other.contains(&b);
                let list = if shares {
                    &mut gates.sure
                } else {
                    &mut gates.welded
                };
                list.push((n, c as u8));
            }
        }
    }
}

impl Schedule {
    /// The walk over `triangles` (vertex indices below `positions.len()`, checked by the caller).
    pub(super) fn new(triangles: &[Triangle], positions: &[Point]) -> Self {
        let (weld, welded_count) = weld(positions);
        let mut walk = Walk {
            triangles,
            weld: &weld,
            by_edge: HashMap::new(),
        };
        for (t, tri) in triangles.iter().enumerate() {
            for k in 0..3 {
                let key = walk.welded_edge(tri[k], tri[(k + 1) % 3]);
                walk.by_edge.entry(key).or_default().push(t as u32);
            }
        }
        let mut visited = vec![false; triangles.len()];
        let mut coded = vec![false; positions.len()];
        let mut steps = Vec::with_capacity(positions.len());
        let mut gates = Gates::default();
        let mut seed = 0usize;
        loop {
            let (t, opposite) = match gates.sure.pop().or_else(|| gates.welded.pop()) {
                Some(g) => g,
                None => match (seed..triangles.len()).find(|&t| !visited[t]) {
                    Some(t) => {
                        seed = t;
                        (t as u32, 2)
                    }
                    None => break,
                },
            };
            if std::mem::replace(&mut visited[t as usize], true) {
                continue;
            }
            let tri = triangles[t as usize];
            for j in 1..=3 {
                let k = (opposite as usize + j) % 3;
                if !std::mem::replace(&mut coded[tri[k] as usize], true) {
                    steps.push(Step {
                        vertex: tri[k],
                        corner: Some((t, k as u8)),
                    });
                }
            }
            walk.open_gates(t, &visited, &mut gates);
        }
        drop(walk);
        let isolated = coded.iter().enumerate().filter(|(_, &c)| !c);
        steps.extend(isolated.map(|(v, _)| Step {
            vertex: v as u32,
            corner: None,
        }));
        Self {
            steps,
            weld,
            welded_count,
        }
    }
}

/// The quantisation of one coordinate set, for predictions made in UV units.
pub(super) struct Levels {
    /// Size of one level step on each axis (UV units); 0 for a flat axis.
    pub(super) step: [f64; 2],
    pub(super) max_level: i64,
}

/// Adaptive contexts of one coordinate set.
#[derive(Default)]
struct Models {
    /// "Reuses a coded copy?", by the previous answer and whether there are several copies.
    reuse: [[BitModel; 2]; 2],
    candidate: UIntModel,
    side: BitModel,
    /// Residuals per prediction kind (projection, one corner, previous vertex) and axis.
    residual: [[IntModel; 2]; 3],
}

/// A geometric prediction in levels, with the alternative on the other side of the edge.
struct Prediction {
    kind: usize,
    value: [i64; 2],
    mirrored: Option<[i64; 2]>,
}

fn sub(a: Point, b: Point) -> [f64; 3] {
    std::array::from_fn(|i| f64::from(a[i]) - f64::from(b[i]))
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Corner `x` of a triangle whose other corners `a`, `b` have coordinates: the 3D triangle
/// projected into UV (the foot of `x` on edge `ab` at the same fraction, then the same height
/// ratio off the edge), on both sides of the edge.
fn project(
    positions: [Point; 3],
    [ua, ub]: [[i64; 2]; 2],
    levels: &Levels,
) -> Option<([i64; 2], [i64; 2])> {
    let [px, pa, pb] = positions;
    let edge = sub(pb, pa);
    let length2 = dot(edge, edge);
    if length2 <= 0.0 {
        return None;
    }
    let along = dot(sub(px, pa), edge) / length2;
    let foot: [f64; 3] = std::array::from_fn(|i| f64::from(pa[i]) + along * edge[i]);
    let off: [f64; 3] = std::array::from_fn(|i| f64::from(px[i]) - foot[i]);
    let height = (dot(off, off) / length2).sqrt();
    // In UV units, so that the perpendicular is one on the texture, not on the level grid.
    let [su, sv] = levels.step;
    let d = [(ub[0] - ua[0]) as f64 * su, (ub[1] - ua[1]) as f64 * sv];
    let base = [
        ua[0] as f64 * su + along * d[0],
        ua[1] as f64 * sv + along * d[1],
    ];
    let to_level = |value: f64, step: f64| -> i64 {
        if step <= 0.0 {
            return 0;
        }
        (value / step).round().clamp(0.0, levels.max_level as f64) as i64
    };
    let side = |sign: f64| {
        [
            to_level(base[0] - sign * height * d[1], su),
            to_level(base[1] + sign * height * d[0], sv),
        ]
    };
    Some((side(1.0), side(-1.0)))
}

fn predict(
    step: Step,
    triangles: &[Triangle],
    positions: &[Point],
    levels: &[[i64; 2]],
    coded: &[bool],
    previous: Option<u32>,
    scale: &Levels,
) -> Prediction {
    let far = Prediction {
        kind: 2,
        value: previous.map_or([0, 0], |p| levels[p as usize]),
        mirrored: None,
    };
    let Some((t, k)) = step.corner else {
        return far;
    };
    let tri = triangles[t as usize];
    let (k, x) = (k as usize, step.vertex as usize);
    let (a, b) = (tri[(k + 1) % 3] as usize, tri[(k + 2) % 3] as usize);
    match (coded[a], coded[b]) {
        (true, true) => {
            let corners = [positions[x], positions[a], positions[b]];
            match project(corners, [levels[a], levels[b]], scale) {
                Some((value, other)) => Prediction {
                    kind: 0,
                    value,
                    mirrored: (other != value).then_some(other),
                },
                None => Prediction {
                    kind: 1,
                    value: levels[a],
                    mirrored: None,
                },
            }
        }
        (true, false) | (false, true) => Prediction {
            kind: 1,
            value: levels[if coded[a] { a } else { b }],
            mirrored: None,
        },
        (false, false) => far,
    }
}

fn distance(a: [i64; 2], b: [i64; 2]) -> i64 {
    (a[0] - b[0]).abs() + (a[1] - b[1]).abs()
}

/// Codes (or decodes into) one set of quantised coordinates, `levels` in `0..=max_level`.
pub(super) fn code_set<C: SymbolCoder>(
    coder: &mut C,
    schedule: &Schedule,
    (triangles, positions): (&[Triangle], &[Point]),
    levels: &mut [[i64; 2]],
    scale: &Levels,
) -> Result<()> {
    let mut models = Models::default();
    let mut coded = vec![false; levels.len()];
    // The distinct coordinates already coded at each welded position.
    let mut at_position: Vec<Vec<[i64; 2]>> = vec![Vec::new(); schedule.welded_count];
    let (mut previous, mut last_side) = (None, false);
    let mut last_reuse = false;
    for &step in &schedule.steps {
        let v = step.vertex as usize;
        let mut prediction = predict(step, triangles, positions, levels, &coded, previous, scale);
        let here = &mut at_position[schedule.weld[v] as usize];
        let mut value = None;
        if !here.is_empty() {
            let mut candidates = here.clone();
            candidates.sort_by_key(|&c| distance(c, prediction.value));
            let found = candidates.iter().position(|&c| c == levels[v]);
            let context =
                &mut models.reuse[usize::from(last_reuse)][usize::from(candidates.len() > 1)];
            let reuse = coder.bit(found.is_some(), context)?;
            last_reuse = reuse;
            if reuse {
                let index = coder.unsigned(found.unwrap_or(0) as u64, &mut models.candidate)?;
                let chosen = usize::try_from(index).ok().and_then(|i| candidates.get(i));
                value = Some(*chosen.ok_or_else(|| {
                    Error::Stream("attributes: coordinate reuses no coded copy".into())
                })?);
            }
        }
        let value = match value {
            Some(value) => value,
            None => {
                if let Some(other) = prediction.mirrored {
                    let nearer = distance(other, levels[v]) < distance(prediction.value, levels[v]);
                    let flip = coder.bit(nearer != last_side, &mut models.side)?;
                    let side = flip != last_side;
                    last_side = side;
                    if side {
                        prediction.value = other;
                    }
                }
                let mut value = [0i64; 2];
                for axis in 0..2 {
                    let model = &mut models.residual[prediction.kind][axis];
                    let residual = levels[v][axis] - prediction.value[axis];
                    value[axis] = prediction.value[axis] + coder.signed(residual, model)?;
                    if !(0..=scale.max_level).contains(&value[axis]) {
                        return Err(Error::Stream("attributes: coordinate out of range".into()));
                    }
                }
                value
            }
        };
        levels[v] = value;
        // A bounded list keeps a hostile stream (every vertex at one position) linear.
        if here.len() < MAX_COPIES && !here.contains(&value) {
            here.push(value);
        }
        coded[v] = true;
        previous = Some(step.vertex);
    }
    Ok(())
}
