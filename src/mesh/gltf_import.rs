//! glTF 2.0 animations baked to frames: node (TRS) animation, morph targets and skinning.
//!
//! Every mesh primitive drawn by the scene becomes part of one animated mesh, in world space, in
//! scene order. Primitives of one node that share their vertex data (the same position, joint,
//! weight and morph accessors, as multi-material meshes do) share their vertices too. Point and
//! line primitives are skipped. The `gltf` crate parses and validates; the posing (sampling the
//! channels, node hierarchy, morphing, linear blend skinning) is the glTF 2.0 specification's, written
//! out here because no maintained crate bakes glTF animation without a renderer attached.

use super::{AnimatedMesh, Point, Triangle};
use crate::error::{Error, Result};
use gltf::accessor::{DataType, Dimensions};
use gltf::animation::util::ReadOutputs;
use gltf::animation::{Interpolation, Property};
use gltf::json::validation::Validate;
use nalgebra::{Matrix4, Quaternion, UnitQuaternion, Vector3, Vector4};
use std::collections::HashMap;
use std::path::Path;

/// Frame rate used when the clip's own keyframe rate cannot be told.
const FALLBACK_FPS: f64 = 30.0;
/// Estimated keyframe rates outside this range are not trusted (sparse or dense keys).
const PLAUSIBLE_FPS: std::ops::RangeInclusive<f64> = 10.0..=240.0;
/// More positions (frames × vertices) than this would not fit in memory: surely a mistaken `--fps`.
const MAX_POSITIONS: f64 = 4e8;
/// Joint influence sets (`JOINTS_n`/`WEIGHTS_n`) read per vertex.
const MAX_INFLUENCE_SETS: u32 = 4;

/// Reads `path` and bakes the chosen clip (name or index, default the first) at `fps` (default the
/// clip's keyframe rate if plausible, else 30).
pub(crate) fn read_gltf(path: &Path, fps: Option<f64>, clip: Option<&str>) -> Result<AnimatedMesh> {
    // Read whole and parsed from memory: gltf's own reader allocates what a GLB header claims (up to
    // 4 GB for a 12-byte file) before reading it.
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let gltf = from_slice(&bytes, path)?;
    bake(gltf, path.parent(), path, fps, clip)
}

/// Parses glTF JSON or a GLB, after checking the GLB header's total length (gltf 1.4 subtracts
/// the header size from it unchecked, which overflows for lengths under 12).
fn from_slice(bytes: &[u8], path: &Path) -> Result<gltf::Gltf> {
    let fail = |what: String| Error::Mesh(format!("{}: {what}", path.display()));
    if bytes.starts_with(b"glTF") {
        let length = bytes
            .get(8..12)
            .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]) as usize);
        match length {
            Some(n) if (12..=bytes.len()).contains(&n) => {}
            Some(n) => {
                return Err(fail(format!(
                    "GLB header gives a length of {n} bytes, the file has {} (at least 12 needed)",
                    bytes.len()
                )))
            }
            None => return Err(fail("GLB header is truncated".into())),
        }
    }
    let gltf = gltf::Gltf::from_slice_without_validation(bytes).map_err(|e| fail(e.to_string()))?;
    // gltf-json's validation looks up a primitive's POSITION accessor before checking the index
    // (an out-of-range one panics), so indices are checked first and the validation run here.
    let root = gltf.document.as_json();
    for (m, mesh) in root.meshes.iter().enumerate() {
        for primitive in &mesh.primitives {
            if let Some(bad) = primitive
                .attributes
                .values()
                .find(|a| a.value() >= root.accessors.len())
            {
                return Err(fail(format!(
                    "mesh {m}: attribute accessor {} does not exist ({} accessors)",
                    bad.value(),
                    root.accessors.len()
                )));
            }
        }
    }
    // Nor does it check an animation channel's target (gltf 1.4 unwraps an unknown `path` and
    // indexes the node unchecked; found by the read_mesh fuzzer).
    for (a, animation) in root.animations.iter().enumerate() {
        for (c, channel) in animation.channels.iter().enumerate() {
            let target = &channel.target;
            if target.node.value() >= root.nodes.len() {
                return Err(fail(format!(
                    "animation {a} channel {c}: target node {} does not exist ({} nodes)",
                    target.node.value(),
                    root.nodes.len()
                )));
            }
            if matches!(target.path, gltf::json::validation::Checked::Invalid) {
                return Err(fail(format!(
                    "animation {a} channel {c}: unknown target path"
                )));
            }
        }
    }
    let mut errors = Vec::new();
    root.validate(root, gltf::json::Path::new, &mut |path, error| {
        errors.push(format!("{}: {error}", path()))
    });
    match errors.first() {
        Some(first) => Err(fail(format!(
            "invalid glTF ({} problems), first: {first}",
            errors.len()
        ))),
        None => Ok(gltf),
    }
}

/// The glTF file and the buffer files beside it that it refers to (those that can be told without
/// reading them); an unreadable file is just itself, reading it reports the error.
pub(crate) fn files(path: &Path) -> Vec<std::path::PathBuf> {
    let mut out = vec![path.to_path_buf()];
    let gltf = std::fs::read(path)
        .ok()
        .and_then(|bytes| from_slice(&bytes, path).ok());
    if let (Some(gltf), Some(folder)) = (gltf, path.parent()) {
        for buffer in gltf.document.buffers() {
            if let gltf::buffer::Source::Uri(uri) = buffer.source() {
                if !uri.contains(':') {
                    out.push(folder.join(uri));
                }
            }
        }
    }
    out
}

/// Parses a `.gltf` or `.glb` held in memory and bakes it like [`read_gltf`]; `path` only names
/// errors. Nothing is read from disk, so buffers must be embedded (GLB chunk or `data:` URI).
pub(crate) fn parse_gltf(
    bytes: &[u8],
    path: &Path,
    fps: Option<f64>,
    clip: Option<&str>,
) -> Result<AnimatedMesh> {
    let gltf = from_slice(bytes, path)?;
    bake(gltf, None, path, fps, clip)
}

/// Bakes a parsed glTF; buffer files are looked up in `folder` (none: only embedded buffers).
fn bake(
    gltf: gltf::Gltf,
    folder: Option<&Path>,
    path: &Path,
    fps: Option<f64>,
    clip: Option<&str>,
) -> Result<AnimatedMesh> {
    let fail = |what: String| Error::Mesh(format!("{}: {what}", path.display()));
    let gltf::Gltf { document, blob } = gltf;
    for buffer in document.buffers() {
        if let gltf::buffer::Source::Uri(uri) = buffer.source() {
            if !uri.contains(':') && !percent_decodes_to_utf8(uri) {
                return Err(fail(format!(
                    "buffer {}: the file name {uri:?} is not valid percent-encoded UTF-8",
                    buffer.index()
                )));
            }
        }
    }
    let buffers =
        gltf::import_buffers(&document, folder, blob).map_err(|e| fail(format!("buffer: {e}")))?;
    let data = buffers.as_slice();

    let scene = document
        .default_scene()
        .or_else(|| document.scenes().next())
        .ok_or_else(|| fail("no scene".into()))?;
    let animation = pick_clip(&document, clip).map_err(fail)?;
    let channels = read_channels(&animation, data).map_err(fail)?;
    let geometry = Geometry::gather(&document, &scene, data).map_err(fail)?;
    let skins = read_skins(&document, data).map_err(fail)?;

    let (start, end) = channels
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(s, e), c| {
            let first = c.times.first().copied().unwrap_or(0.0) as f64;
            let last = c.times.last().copied().unwrap_or(0.0) as f64;
            (s.min(first), e.max(last))
        });
    let rate = fps.unwrap_or_else(|| keyframe_rate(&channels).unwrap_or(FALLBACK_FPS));
    let frame_count = ((end - start).max(0.0) * rate + 1e-6).floor() + 1.0;
    if !(frame_count.is_finite() && frame_count * geometry.vertex_count as f64 <= MAX_POSITIONS) {
        return Err(fail(format!(
            "{:.3} s at {rate} frames/s is {frame_count} frames of {} vertices: too many, lower --fps",
            end - start,
            geometry.vertex_count
        )));
    }
    let pose = Pose::new(&document);
    let mut frames = Vec::with_capacity(frame_count as usize);
    for f in 0..frame_count as usize {
        let time = (start + f as f64 / rate).min(end);
        let posed = pose.at(time, &channels);
        frames.push(geometry.bake(&posed, &skins));
    }
    AnimatedMesh::new(geometry.triangles, frames).map_err(|e| fail(e.to_string()))
}

/// The clip named or numbered by `clip`, or the first; an error lists the clips there are.
fn pick_clip<'a>(
    document: &'a gltf::Document,
    clip: Option<&str>,
) -> Result<gltf::Animation<'a>, String> {
    let mut clips = document.animations();
    let Some(wanted) = clip else {
        return clips.next().ok_or_else(|| {
            "no animation in the file (a still mesh: there is nothing to compress over time)".into()
        });
    };
    let by_name = document.animations().find(|a| a.name() == Some(wanted));
    let by_index = || {
        wanted
            .parse::<usize>()
            .ok()
            .and_then(|i| document.animations().nth(i))
    };
    by_name.or_else(by_index).ok_or_else(|| {
        let known: Vec<String> = document
            .animations()
            .map(|a| format!("{} `{}`", a.index(), a.name().unwrap_or("")))
            .collect();
        if known.is_empty() {
            format!("no clip `{wanted}`: the file has no animations")
        } else {
            format!("no clip `{wanted}`; the clips are {}", known.join(", "))
        }
    })
}

/// The file's buffers, loaded.
type Buffers<'d> = &'d [gltf::buffer::Data];

fn buffer_data<'d>(buffers: Buffers<'d>, buffer: gltf::Buffer) -> Option<&'d [u8]> {
    buffers.get(buffer.index()).map(|d| &d.0[..])
}

/// One animated property of one node: key times and the values at them, flattened.
#[derive(Debug)]
struct Channel {
    node: usize,
    property: Property,
    interpolation: Interpolation,
    times: Vec<f32>,
    /// Per key `width` values; cubic splines store in-tangent, value, out-tangent per key.
    values: Vec<f32>,
    /// Components per value: 3 (translation, scale), 4 (rotation) or the morph target count.
    width: usize,
}

/// The gltf crate's readers take an accessor's element type from its use and only debug-assert (or
/// `unreachable!`) that the file agrees; a file that lies about it must be an error, not a panic or
/// a misread.
fn check_accessor(
    accessor: Option<gltf::Accessor>,
    what: &str,
    dimensions: Dimensions,
    types: &[DataType],
) -> Result<(), String> {
    match accessor {
        Some(a) if a.dimensions() != dimensions || !types.contains(&a.data_type()) => Err(format!(
            "{what}: accessor {} holds {:?} {:?}, expected {dimensions:?} of {types:?}",
            a.index(),
            a.dimensions(),
            a.data_type()
        )),
        Some(a) => check_extent(&a, what),
        None => Ok(()),
    }
}

/// An accessor must have elements and end inside its buffer view: gltf 1.4 computes its end as
/// `offset + stride * (count - 1) + size` unchecked (overflow for count 0 or huge counts).
fn check_extent(a: &gltf::Accessor, what: &str) -> Result<(), String> {
    if a.count() == 0 {
        return Err(format!("{what}: accessor {} has no elements", a.index()));
    }
    if let Some(view) = a.view() {
        let stride = view.stride().unwrap_or(a.size());
        if stride < a.size() {
            return Err(format!(
                "{what}: accessor {} has elements of {} bytes in a buffer view of stride {stride}",
                a.index(),
                a.size()
            ));
        }
        let end = (a.count() - 1)
            .checked_mul(stride)
            .and_then(|n| n.checked_add(a.offset()))
            .and_then(|n| n.checked_add(a.size()));
        if end.is_none_or(|e| e > view.length()) {
            return Err(format!(
                "{what}: accessor {} runs past the end of its buffer view",
                a.index()
            ));
        }
    }
    Ok(())
}

/// Whether a relative URI percent-decodes to UTF-8: gltf 1.4 unwraps that decoding, so a file naming
/// a buffer `%FF` would panic inside `import_buffers`. Decodes as the `urlencoding` crate does: a `%`
/// not followed by two hex digits stays as it is.
fn percent_decodes_to_utf8(uri: &str) -> bool {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = bytes
            .get(i + 1..i + 3)
            .and_then(|h| std::str::from_utf8(h).ok())
            .and_then(|h| u8::from_str_radix(h, 16).ok());
        match (bytes[i], hex) {
            (b'%', Some(b)) => {
                out.push(b);
                i += 3;
            }
            (b, _) => {
                out.push(b);
                i += 1;
            }
        }
    }
    String::from_utf8(out).is_ok()
}

/// Component types glTF allows for rotations and morph weights (floats or normalised integers).
const NORMALISED: [DataType; 5] = [
    DataType::F32,
    DataType::I8,
    DataType::U8,
    DataType::I16,
    DataType::U16,
];

fn read_channels<'a>(
    animation: &gltf::Animation<'a>,
    data: Buffers,
) -> Result<Vec<Channel>, String> {
    let mut channels = Vec::new();
    for channel in animation.channels() {
        let name = format!(
            "animation {} channel {}",
            animation.index(),
            channel.index()
        );
        let sampler = channel.sampler();
        check_accessor(
            Some(sampler.input()),
            &format!("{name} key times"),
            Dimensions::Scalar,
            &[DataType::F32],
        )?;
        let (dimensions, types): (Dimensions, &[DataType]) = match channel.target().property() {
            Property::Translation | Property::Scale => (Dimensions::Vec3, &[DataType::F32]),
            Property::Rotation => (Dimensions::Vec4, &NORMALISED),
            Property::MorphTargetWeights => (Dimensions::Scalar, &NORMALISED),
        };
        check_accessor(
            Some(sampler.output()),
            &format!("{name} values"),
            dimensions,
            types,
        )?;
        let reader = channel.reader(|b| buffer_data(data, b));
        let times: Vec<f32> = reader
            .read_inputs()
            .ok_or_else(|| format!("{name}: key times unreadable"))?
            .collect();
        let values: Vec<f32> = match reader
            .read_outputs()
            .ok_or_else(|| format!("{name}: values unreadable"))?
        {
            ReadOutputs::Translations(it) => it.flatten().collect(),
            ReadOutputs::Scales(it) => it.flatten().collect(),
            ReadOutputs::Rotations(it) => it.into_f32().flatten().collect(),
            ReadOutputs::MorphTargetWeights(it) => it.into_f32().collect(),
        };
        if times.is_empty() {
            continue;
        }
        if times.iter().any(|t| !t.is_finite()) || times.windows(2).any(|w| w[1] < w[0]) {
            return Err(format!(
                "{name}: key times are not increasing finite numbers"
            ));
        }
        let interpolation = channel.sampler().interpolation();
        let per_key = times.len()
            * if interpolation == Interpolation::CubicSpline {
                3
            } else {
                1
            };
        let width = values.len() / per_key;
        let expected_width = match channel.target().property() {
            Property::Translation | Property::Scale => Some(3),
            Property::Rotation => Some(4),
            Property::MorphTargetWeights => None,
        };
        if width == 0
            || width * per_key != values.len()
            || expected_width.is_some_and(|e| e != width)
        {
            return Err(format!(
                "{name}: {} values do not fit {} keys",
                values.len(),
                times.len()
            ));
        }
        if values.iter().any(|v| !v.is_finite()) {
            return Err(format!("{name}: a value is not a finite number"));
        }
        channels.push(Channel {
            node: channel.target().node().index(),
            property: channel.target().property(),
            interpolation,
            times,
            values,
            width,
        });
    }
    if channels.is_empty() {
        return Err(format!("animation {} has no keyframes", animation.index()));
    }
    Ok(channels)
}

/// The clip's keyframe rate: 1 / the median step between distinct key times, rounded to a whole
/// rate when within 0.1 % of one (key times are stored rounded); `None` when there are too few keys or the rate is implausible.
fn keyframe_rate(channels: &[Channel]) -> Option<f64> {
    let mut times: Vec<f64> = channels
        .iter()
        .flat_map(|c| c.times.iter().map(|&t| t as f64))
        .collect();
    times.sort_by(f64::total_cmp);
    times.dedup_by(|a, b| (*a - *b).abs() < 1e-4);
    let mut steps: Vec<f64> = times.windows(2).map(|w| w[1] - w[0]).collect();
    if steps.len() < 2 {
        return None;
    }
    steps.sort_by(f64::total_cmp);
    let rate = 1.0 / steps[steps.len() / 2];
    let rate = if (rate - rate.round()).abs() < 0.001 * rate {
        rate.round()
    } else {
        rate
    };
    PLAUSIBLE_FPS.contains(&rate).then_some(rate)
}

impl Channel {
    /// The (interpolated) value at `time`, clamped to the first and last keys.
    fn sample(&self, time: f64) -> Vec<f64> {
        let w = self.width;
        let cubic = self.interpolation == Interpolation::CubicSpline;
        // Key k's value (the middle of the three cubic-spline entries).
        let value = |k: usize| -> Vec<f64> {
            let at = if cubic { (3 * k + 1) * w } else { k * w };
            self.values[at..at + w].iter().map(|&v| v as f64).collect()
        };
        let last = self.times.len() - 1;
        let next = self.times.partition_point(|&t| (t as f64) <= time);
        if next == 0 {
            return value(0);
        }
        if next > last {
            return value(last);
        }
        let k = next - 1;
        let (t0, t1) = (self.times[k] as f64, self.times[next] as f64);
        let dt = t1 - t0;
        let s = if dt > 0.0 { (time - t0) / dt } else { 0.0 };
        let mut out = match self.interpolation {
            Interpolation::Step => return value(k),
            Interpolation::Linear if self.property == Property::Rotation => {
                return slerp(&value(k), &value(next), s);
            }
            Interpolation::Linear => {
                let (a, b) = (value(k), value(next));
                a.iter()
                    .zip(&b)
                    .map(|(a, b)| a + (b - a) * s)
                    .collect::<Vec<f64>>()
            }
            Interpolation::CubicSpline => {
                let part = |key: usize, which: usize, i: usize| {
                    self.values[(3 * key + which) * w + i] as f64
                };
                let (s2, s3) = (s * s, s * s * s);
                (0..w)
                    .map(|i| {
                        (2.0 * s3 - 3.0 * s2 + 1.0) * part(k, 1, i)
                            + (s3 - 2.0 * s2 + s) * dt * part(k, 2, i)
                            + (-2.0 * s3 + 3.0 * s2) * part(next, 1, i)
                            + (s3 - s2) * dt * part(next, 0, i)
                    })
                    .collect()
            }
        };
        if self.property == Property::Rotation {
            normalize(&mut out);
        }
        out
    }
}

/// Spherical interpolation of two `[x, y, z, w]` quaternions along the shorter arc.
fn slerp(a: &[f64], b: &[f64], s: f64) -> Vec<f64> {
    let q = |v: &[f64]| UnitQuaternion::new_normalize(Quaternion::new(v[3], v[0], v[1], v[2]));
    let (qa, mut qb) = (q(a), q(b));
    if qa.coords.dot(&qb.coords) < 0.0 {
        qb = UnitQuaternion::new_unchecked(-qb.into_inner());
    }
    let r = qa.try_slerp(&qb, s, 1e-9).unwrap_or_else(|| {
        UnitQuaternion::new_normalize(qa.into_inner().lerp(&qb.into_inner(), s))
    });
    vec![r.i, r.j, r.k, r.w]
}

fn normalize(v: &mut [f64]) {
    let n = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    if n > 0.0 {
        v.iter_mut().for_each(|x| *x /= n);
    }
}

/// Node transforms and morph weights at rest, posed at any time by the channels.
struct Pose {
    rest: Vec<Trs>,
    rest_weights: Vec<Vec<f64>>,
    /// Parents before children, so world transforms can be built in one pass.
    order: Vec<usize>,
    parent: Vec<Option<usize>>,
}

/// World transforms and morph weights of every node at one time.
struct Posed {
    world: Vec<Matrix4<f64>>,
    weights: Vec<Vec<f64>>,
}

#[derive(Debug, Clone)]
struct Trs {
    translation: Vector3<f64>,
    rotation: UnitQuaternion<f64>,
    scale: Vector3<f64>,
}

impl Trs {
    fn matrix(&self) -> Matrix4<f64> {
        Matrix4::new_translation(&self.translation)
            * self.rotation.to_homogeneous()
            * Matrix4::new_nonuniform_scaling(&self.scale)
    }
}

impl Pose {
    fn new(document: &gltf::Document) -> Self {
        let rest = document
            .nodes()
            .map(|n| {
                let (t, r, s) = n.transform().decomposed();
                Trs {
                    translation: Vector3::new(t[0], t[1], t[2]).cast(),
                    rotation: UnitQuaternion::new_normalize(
                        Quaternion::new(r[3], r[0], r[1], r[2]).cast(),
                    ),
                    scale: Vector3::new(s[0], s[1], s[2]).cast(),
                }
            })
            .collect();
        let rest_weights = document
            .nodes()
            .map(|n| {
                let w = n.weights().or_else(|| n.mesh().and_then(|m| m.weights()));
                w.unwrap_or(&[]).iter().map(|&x| x as f64).collect()
            })
            .collect();
        let count = document.nodes().count();
        let mut parent = vec![None; count];
        for node in document.nodes() {
            for child in node.children() {
                parent[child.index()] = Some(node.index());
            }
        }
        let children: Vec<Vec<usize>> = document
            .nodes()
            .map(|n| n.children().map(|c| c.index()).collect())
            .collect();
        let mut order = Vec::with_capacity(count);
        let mut seen = vec![false; count];
        let mut stack: Vec<usize> = (0..count).filter(|&n| parent[n].is_none()).rev().collect();
        while let Some(n) = stack.pop() {
            if std::mem::replace(&mut seen[n], true) {
                continue;
            }
            order.push(n);
            stack.extend(children[n].iter().rev());
        }
        Self {
            rest,
            rest_weights,
            order,
            parent,
        }
    }

    fn at(&self, time: f64, channels: &[Channel]) -> Posed {
        let mut local = self.rest.clone();
        let mut weights = self.rest_weights.clone();
        for c in channels {
            let (Some(trs), Some(w)) = (local.get_mut(c.node), weights.get_mut(c.node)) else {
                continue;
            };
            let v = c.sample(time);
            match c.property {
                Property::Translation => trs.translation = Vector3::new(v[0], v[1], v[2]),
                Property::Scale => trs.scale = Vector3::new(v[0], v[1], v[2]),
                Property::Rotation => {
                    trs.rotation =
                        UnitQuaternion::new_normalize(Quaternion::new(v[3], v[0], v[1], v[2]))
                }
                Property::MorphTargetWeights => *w = v,
            }
        }
        let mut world = vec![Matrix4::identity(); local.len()];
        for &n in &self.order {
            let own = local[n].matrix();
            world[n] = match self.parent[n] {
                Some(p) => world[p] * own,
                None => own,
            };
        }
        Posed { world, weights }
    }
}

/// A skin: its joint nodes and inverse bind matrices.
struct Skin {
    joints: Vec<usize>,
    inverse_bind: Vec<Matrix4<f64>>,
}

fn read_skins(document: &gltf::Document, data: Buffers) -> Result<Vec<Skin>, String> {
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

/// The scene's triangles and, per part (a node's primitive with its own vertices), what moves them.
struct Geometry {
    triangles: Vec<Triangle>,
    parts: Vec<Part>,
    vertex_count: usize,
}

struct Part {
    node: usize,
    skin: Option<usize>,
    positions: Vec<Point>,
    /// Position displacements per morph target.
    targets: Vec<Vec<Point>>,
    /// Per vertex, `influences_per_vertex` (joint, weight) pairs.
    influences: Vec<(u16, f32)>,
    influences_per_vertex: usize,
}

impl Geometry {
    fn gather<'a>(
        document: &'a gltf::Document,
        scene: &gltf::Scene<'a>,
        data: Buffers,
    ) -> Result<Self, String> {
        let mut geometry = Geometry {
            triangles: Vec::new(),
            parts: Vec::new(),
            vertex_count: 0,
        };
        // First vertex and count of the vertex data already read, to share it between primitives.
        let mut first_vertex: HashMap<VertexSource, (usize, usize)> = HashMap::new();
        let mut stack: Vec<gltf::Node> = scene.nodes().collect();
        stack.reverse();
        let mut visited = vec![false; document.nodes().count()];
        while let Some(node) = stack.pop() {
            if std::mem::replace(&mut visited[node.index()], true) {
                continue;
            }
            let children: Vec<gltf::Node> = node.children().collect();
            stack.extend(children.into_iter().rev());
            let Some(mesh) = node.mesh() else { continue };
            for primitive in mesh.primitives() {
                let name = format!("mesh {} primitive {}", mesh.index(), primitive.index());
                let key = (node.index(), vertex_accessors(&primitive));
                let (first, count) = match first_vertex.get(&key) {
                    Some(&range) => range,
                    None => {
                        let Some(part) = Part::read(&node, &primitive, data, &name)? else {
                            continue;
                        };
                        let range = (geometry.vertex_count, part.positions.len());
                        geometry.vertex_count += part.positions.len();
                        geometry.parts.push(part);
                        first_vertex.insert(key, range);
                        range
                    }
                };
                check_accessor(
                    primitive.indices(),
                    &format!("{name} indices"),
                    Dimensions::Scalar,
                    &[DataType::U8, DataType::U16, DataType::U32],
                )?;
                let reader = primitive.reader(|b| buffer_data(data, b));
                let indices: Vec<u32> = match reader.read_indices() {
                    Some(it) => it.into_u32().collect(),
                    None => (0..count as u32).collect(),
                };
                if let Some(&bad) = indices.iter().find(|&&i| i as usize >= count) {
                    return Err(format!("{name}: index {bad} but {count} vertices"));
                }
                let offset = first as u32;
                let shifted = triangles_of(primitive.mode(), &indices)
                    .map(|t| [t[0] + offset, t[1] + offset, t[2] + offset]);
                geometry.triangles.extend(shifted);
            }
        }
        if geometry.vertex_count == 0 {
            return Err("the scene draws no triangles".into());
        }
        Ok(geometry)
    }

    /// World-space positions of every vertex in one pose.
    fn bake(&self, posed: &Posed, skins: &[Skin]) -> Vec<Point> {
        let mut out = Vec::with_capacity(self.vertex_count);
        for part in &self.parts {
            let weights = posed.weights.get(part.node).map_or(&[][..], Vec::as_slice);
            let joint_matrices: Option<Vec<Matrix4<f64>>> =
                part.skin.and_then(|s| skins.get(s)).map(|skin| {
                    skin.joints
                        .iter()
                        .zip(&skin.inverse_bind)
                        .map(|(&j, ibm)| {
                            posed
                                .world
                                .get(j)
                                .copied()
                                .unwrap_or_else(Matrix4::identity)
                                * ibm
                        })
                        .collect()
                });
            let node_world = posed
                .world
                .get(part.node)
                .copied()
                .unwrap_or_else(Matrix4::identity);
            for (v, p) in part.positions.iter().enumerate() {
                let mut p = Vector4::new(p[0] as f64, p[1] as f64, p[2] as f64, 1.0);
                for (target, &w) in part.targets.iter().zip(weights) {
                    if w != 0.0 {
                        let d = target[v];
                        p.x += w * d[0] as f64;
                        p.y += w * d[1] as f64;
                        p.z += w * d[2] as f64;
                    }
                }
                let skinning = joint_matrices.as_ref().and_then(|jm| {
                    let k = part.influences_per_vertex;
                    blend(&part.influences[v * k..(v + 1) * k], jm)
                });
                let q = skinning.unwrap_or(node_world) * p;
                out.push([q.x as f32, q.y as f32, q.z as f32]);
            }
        }
        out
    }
}

/// The weighted sum of the joint matrices, weights normalised to sum 1 (exporters round them);
/// `None` for a vertex no joint moves, which then follows its node.
fn blend(influences: &[(u16, f32)], joint_matrices: &[Matrix4<f64>]) -> Option<Matrix4<f64>> {
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

/// A node and the accessors that feed a primitive's vertices (see [`vertex_accessors`]).
type VertexSource = (usize, Vec<Option<usize>>);

/// Indices of every accessor that feeds a primitive's vertices: equal lists mean shared vertices.
fn vertex_accessors(primitive: &gltf::Primitive) -> Vec<Option<usize>> {
    use gltf::Semantic;
    let mut keys = vec![primitive.get(&Semantic::Positions).map(|a| a.index())];
    for set in 0..MAX_INFLUENCE_SETS {
        keys.push(primitive.get(&Semantic::Joints(set)).map(|a| a.index()));
        keys.push(primitive.get(&Semantic::Weights(set)).map(|a| a.index()));
    }
    keys.extend(
        primitive
            .morph_targets()
            .map(|t| t.positions().map(|a| a.index())),
    );
    keys
}

/// The triangles of a primitive's index list; nothing for points and lines.
fn triangles_of(
    mode: gltf::mesh::Mode,
    indices: &[u32],
) -> Box<dyn Iterator<Item = Triangle> + '_> {
    use gltf::mesh::Mode;
    match mode {
        Mode::Triangles => Box::new(indices.chunks_exact(3).map(|c| [c[0], c[1], c[2]])),
        Mode::TriangleStrip => Box::new(indices.windows(3).enumerate().map(|(i, w)| {
            // Every other strip triangle is flipped back to keep one orientation.
            if i % 2 == 0 {
                [w[0], w[1], w[2]]
            } else {
                [w[1], w[0], w[2]]
            }
        })),
        Mode::TriangleFan => match indices.split_first() {
            Some((&hub, rest)) => Box::new(rest.windows(2).map(move |w| [hub, w[0], w[1]])),
            None => Box::new(std::iter::empty()),
        },
        _ => Box::new(std::iter::empty()),
    }
}

impl Part {
    /// The vertex data of one primitive; `None` when it draws no triangles or has no positions.
    fn read<'a>(
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
        // The reader would take quantised (KHR_mesh_quantization) positions for floats.
        let float_vec3 = |a: &gltf::Accessor| {
            a.data_type() == gltf::accessor::DataType::F32
                && a.dimensions() == gltf::accessor::Dimensions::Vec3
        };
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
        let reader = primitive.reader(|b| buffer_data(data, b));
        let Some(positions) = reader.read_positions() else {
            return Ok(None);
        };
        let positions: Vec<Point> = positions.collect();
        let n = positions.len();
        if positions.iter().flatten().any(|c| !c.is_finite()) {
            return Err(format!("{name}: a position is not a finite number"));
        }
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
        let skin = node.skin().map(|s| s.index());
        let mut sets: Vec<Vec<(u16, f32)>> = Vec::new();
        if skin.is_some() {
            for set in 0..MAX_INFLUENCE_SETS {
                let (Some(joints), Some(weights)) =
                    (reader.read_joints(set), reader.read_weights(set))
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
        }
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
}

#[cfg(test)]
mod tests {
    use super::*;

    fn channel(
        property: Property,
        interpolation: Interpolation,
        times: &[f32],
        values: &[f32],
        width: usize,
    ) -> Channel {
        Channel {
            node: 0,
            property,
            interpolation,
            times: times.to_vec(),
            values: values.to_vec(),
            width,
        }
    }

    #[test]
    fn step_linear_and_cubic_sampling() {
        let step = channel(
            Property::Translation,
            Interpolation::Step,
            &[0.0, 1.0],
            &[0., 0., 0., 2., 4., 6.],
            3,
        );
        assert_eq!(step.sample(0.99), vec![0.0; 3]);
        assert_eq!(step.sample(1.0), vec![2.0, 4.0, 6.0]);
        let linear = channel(
            Property::Translation,
            Interpolation::Linear,
            &[1.0, 2.0],
            &[0., 0., 0., 2., 4., 6.],
            3,
        );
        assert_eq!(
            linear.sample(0.0),
            vec![0.0; 3],
            "clamped before the first key"
        );
        assert_eq!(linear.sample(1.25), vec![0.5, 1.0, 1.5]);
        assert_eq!(
            linear.sample(9.0),
            vec![2.0, 4.0, 6.0],
            "clamped after the last key"
        );
        // Tangents chosen so the Hermite curve is the straight line v = 3t (tangent 3 per second).
        let cubic = channel(
            Property::MorphTargetWeights,
            Interpolation::CubicSpline,
            &[0.0, 2.0],
            &[3.0, 0.0, 3.0, 3.0, 6.0, 3.0],
            1,
        );
        for t in [0.0, 0.5, 1.0, 1.7, 2.0] {
            assert!((cubic.sample(t)[0] - 3.0 * t).abs() < 1e-9, "t = {t}");
        }
    }

    #[test]
    fn rotations_take_the_short_way() {
        let h = std::f32::consts::FRAC_1_SQRT_2;
        // Identity, then a quarter turn about z written with a negated (equivalent) quaternion.
        let rotation = channel(
            Property::Rotation,
            Interpolation::Linear,
            &[0.0, 1.0],
            &[0., 0., 0., 1., 0., 0., -h, -h],
            4,
        );
        let half = rotation.sample(0.5);
        let expected = [
            0.0,
            0.0,
            (std::f64::consts::PI / 8.0).sin(),
            (std::f64::consts::PI / 8.0).cos(),
        ];
        let same = half.iter().zip(expected).all(|(a, b)| (a - b).abs() < 1e-6);
        let opposite = half.iter().zip(expected).all(|(a, b)| (a + b).abs() < 1e-6);
        assert!(same || opposite, "{half:?}");
    }

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
