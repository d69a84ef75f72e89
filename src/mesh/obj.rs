//! Wavefront OBJ: one frame per file, frames ordered by the number in their file names.
//!
//! The parser is written here rather than taken from `tobj` because the transcoder must keep the
//! file's global vertex order and every vertex, referenced or not (the stream, the PC2 caches and the
//! error measures all rely on vertex `i` of one frame being vertex `i` of the next). `tobj` splits the
//! file into models at every `o`/`g`/`usemtl`, renumbers each model's vertices in order of first use
//! and drops unused ones, and does not expose the original indices, so that order cannot be recovered
//! from its output. `v`, `f`, `vt` and `usemtl` lines matter here; everything else (normals, groups,
//! lines, points) is skipped. Polygons become triangle fans around their first corner, as `tobj`
//! triangulates them; `tests/it/mesh_io.rs` checks the two agree
//! (docs/design.md, "Own OBJ parser").
//!
//! Texture coordinates are per vertex in [`Attributes`] (as in glTF, `v` pointing down: OBJ's `vt`
//! is flipped on the way in and out). They are kept when every face names a `vt` and each vertex
//! gets one coordinate from all its corners (files whose seams split vertices, as game exporters
//! write them); a file whose corners give a vertex several is read without them, since splitting
//! vertices would break the vertex-for-vertex match of the frames. `usemtl` names each triangle's
//! material (`default` before the first).

use super::obj_skeleton::FirstObj;
use super::{AnimatedMesh, Attributes, Point, Triangle};
use crate::error::{Error, Result};
use std::borrow::Cow;
use std::path::{Path, PathBuf};

/// The geometry of one OBJ file: positions in the file's `v` order and its faces as triangles.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ObjFrame {
    /// Positions in the order of the file's `v` lines.
    pub positions: Vec<Point>,
    /// Faces triangulated as fans, indices into `positions`.
    pub triangles: Vec<Triangle>,
    /// Per-vertex `vt` coordinates and `usemtl` materials, when the file has them.
    pub attributes: Attributes,
}

/// The `vt` and `usemtl` lines of a file and what each triangle corner takes from them.
#[derive(Default)]
struct Looks {
    texcoords: Vec<[f32; 2]>,
    /// Per triangle, each corner's 1-based `vt` reference (None: the corner has none).
    corners: Vec<[Option<i64>; 3]>,
    names: Vec<String>,
    current: Option<u32>,
    materials: Vec<Option<u32>>,
}

impl Looks {
    fn texcoord<'a>(
        &mut self,
        mut words: impl Iterator<Item = &'a str>,
    ) -> std::result::Result<(), String> {
        let mut uv = [0f32; 2];
        for c in &mut uv {
            let word = words.next().unwrap_or("0");
            *c = word
                .parse()
                .map_err(|_| format!("`{word}` is not a number"))?;
        }
        if uv.iter().any(|c| !c.is_finite()) {
            return Err("a texture coordinate is not a finite number".into());
        }
        self.texcoords.push([uv[0], 1.0 - uv[1]]);
        Ok(())
    }

    fn use_material(&mut self, name: &str) {
        let index = match self.names.iter().position(|n| n == name) {
            Some(i) => i,
            None => {
                self.names.push(name.to_string());
                self.names.len() - 1
            }
        };
        self.current = Some(index as u32);
    }

    /// The attributes of `triangles` (0-based), or none of a kind the file does not give fully.
    fn attributes(mut self, triangles: &[Triangle], vertices: usize) -> Attributes {
        let count = self.texcoords.len() as i64;
        let mut per_vertex: Vec<Option<[f32; 2]>> = vec![None; vertices];
        let mut consistent = !self.texcoords.is_empty();
        'faces: for (t, corners) in triangles.iter().zip(&self.corners) {
            for (&v, vt) in t.iter().zip(corners) {
                let uv = vt
                    .map(|i| if i < 0 { count + i } else { i - 1 })
                    .filter(|i| (0..count).contains(i))
                    .map(|i| self.texcoords[i as usize]);
                let slot = &mut per_vertex[v as usize];
                match (uv, *slot) {
                    (None, _) => consistent = false,
                    (Some(uv), None) => *slot = Some(uv),
                    (Some(uv), Some(had)) => consistent &= uv == had,
                }
                if !consistent {
                    break 'faces;
                }
            }
        }
        let mut attributes = Attributes::default();
        if consistent {
            let set = per_vertex
                .into_iter()
                .map(Option::unwrap_or_default)
                .collect();
            attributes.texcoords.push(set);
        }
        if !self.names.is_empty() {
            let default = self.materials.iter().any(Option::is_none);
            if default {
                self.names.push("default".into());
            }
            let fallback = self.names.len() as u32 - 1;
            attributes.materials = self
                .materials
                .iter()
                .map(|m| m.unwrap_or(fallback))
                .collect();
            attributes.material_names = self.names;
        }
        attributes
    }
}

/// Reads and parses one OBJ file.
pub(crate) fn read_obj(path: &Path) -> Result<ObjFrame> {
    parse_obj(&read_text(path)?, path)
}

/// UTF-8's byte-order mark, which some Windows editors put before the first line.
const BOM: &str = "\u{feff}";

/// The text of the file at `path`, invalid UTF-8 replaced and a leading byte-order mark removed
/// (left, it glued onto the first line's keyword and that `v` line was silently skipped; both
/// the full parse and the later frames' position-only read take their text from here).
pub(super) fn read_text(path: &Path) -> Result<String> {
    let mut bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    if bytes.starts_with(BOM.as_bytes()) {
        bytes.drain(..BOM.len());
    }
    // `from_utf8` checks ASCII a word at a time, the lossy decoder byte by byte: the fast check
    // first (an OBJ file is ASCII but for names and comments), the lossy one where it fails.
    Ok(match String::from_utf8(bytes) {
        Ok(text) => text,
        Err(e) => String::from_utf8_lossy(e.as_bytes()).into_owned(),
    })
}

/// Parses OBJ text (a leading byte-order mark skipped); `path` only names the file in error messages.
pub(crate) fn parse_obj(text: &str, path: &Path) -> Result<ObjFrame> {
    let text = text.strip_prefix(BOM).unwrap_or(text);
    let mut positions: Vec<Point> = Vec::new();
    // Corners keep the 1-based or negative OBJ index until all positions are known, because a face
    // may name a vertex defined further down.
    let mut triangles: Vec<[(i64, usize); 3]> = Vec::new();
    let mut corners: Vec<(i64, Option<i64>)> = Vec::new();
    let mut looks = Looks::default();
    for (line_no, line) in logical_lines(text) {
        let at = |what: String| line_error(path, line_no, what);
        // OBJ is ASCII: the ASCII split is the faster, and other spaces are no separators.
        let mut words = line.split_ascii_whitespace();
        match words.next() {
            Some("v") => positions.push(parse_vertex(words, positions.len()).map_err(at)?),
            Some("vt") => looks.texcoord(words).map_err(at)?,
            Some("usemtl") => looks.use_material(words.next().unwrap_or("")),
            Some("f") => {
                parse_face(words, positions.len(), &mut corners).map_err(at)?;
                for k in 1..corners.len() - 1 {
                    let fan = [corners[0], corners[k], corners[k + 1]];
                    triangles.push(fan.map(|(v, _)| (v, line_no)));
                    looks.corners.push(fan.map(|(_, vt)| vt));
                    looks.materials.push(looks.current);
                }
            }
            _ => {}
        }
    }
    if positions.is_empty() {
        return Err(Error::Mesh(format!("{}: no vertices", path.display())));
    }
    if triangles.is_empty() {
        return Err(Error::Mesh(format!(
            "{}: {} vertices but no faces (a triangle mesh is needed)",
            path.display(),
            positions.len()
        )));
    }
    let triangles = resolve_corners(triangles, positions.len(), path)?;
    let attributes = looks.attributes(&triangles, positions.len());
    Ok(ObjFrame {
        positions,
        triangles,
        attributes,
    })
}

/// An error on line `line` of the file at `path`.
pub(super) fn line_error(path: &Path, line: usize, what: String) -> Error {
    Error::Mesh(format!("{}: line {line}: {what}", path.display()))
}

/// The position of a `v` line (the words after `v`), divided by its homogeneous w if it has one;
/// `read` is the number of vertices before it.
pub(super) fn parse_vertex<'a>(
    mut words: impl Iterator<Item = &'a str>,
    read: usize,
) -> std::result::Result<Point, String> {
    let mut p = [0f32; 3];
    for c in &mut p {
        let word = words
            .next()
            .ok_or_else(|| "a vertex needs three coordinates".to_string())?;
        *c = word
            .parse()
            .map_err(|_| format!("`{word}` is not a number"))?;
    }
    // An optional fourth value is the homogeneous w (three more would be a colour).
    let rest: Vec<&str> = words.collect();
    if rest.len() == 1 {
        let w: f32 = rest[0]
            .parse()
            .map_err(|_| format!("`{}` is not a number", rest[0]))?;
        if w == 0.0 {
            return Err("vertex has w = 0".into());
        }
        p.iter_mut().for_each(|c| *c /= w);
    }
    if p.iter().any(|c| !c.is_finite()) {
        return Err(format!(
            "vertex {} has a coordinate that is not a finite number ({} {} {})",
            read + 1,
            p[0],
            p[1],
            p[2]
        ));
    }
    Ok(p)
}

/// The corners of an `f` line (the words after `f`) into `corners` as 1-based indices, negative
/// ones resolved against the `read` vertices so far, each with its `vt` reference if any; a face
/// needs at least three.
fn parse_face<'a>(
    words: impl Iterator<Item = &'a str>,
    read: usize,
    corners: &mut Vec<(i64, Option<i64>)>,
) -> std::result::Result<(), String> {
    corners.clear();
    for word in words {
        // `v`, `v/vt`, `v//vn` or `v/vt/vn`; cut by a byte search, as `split('/')` cost a tenth
        // of reading a frame.
        let (index, rest) = cut_at_slash(word);
        let texcoord = rest.and_then(|r| cut_at_slash(r).0.parse::<i64>().ok());
        let index: i64 = index
            .parse()
            .map_err(|_| format!("`{word}` is not a vertex reference"))?;
        if index == 0 {
            return Err("vertex index 0 (OBJ counts from 1)".into());
        }
        // A negative index counts back from the last vertex read so far.
        let index = if index < 0 {
            read as i64 + index + 1
        } else {
            index
        };
        corners.push((index, texcoord));
    }
    if corners.len() < 3 {
        return Err(format!(
            "a face needs at least 3 vertices, this one has {}",
            corners.len()
        ));
    }
    Ok(())
}

/// `word` before its first `/`, and what follows that `/` if there is one.
fn cut_at_slash(word: &str) -> (&str, Option<&str>) {
    match word.bytes().position(|b| b == b'/') {
        Some(i) => (&word[..i], Some(&word[i + 1..])),
        None => (word, None),
    }
}

/// The triangles' 1-based corners (each with its line number) as 0-based indices into the `v`
/// positions of the file.
fn resolve_corners(
    triangles: Vec<[(i64, usize); 3]>,
    v: usize,
    path: &Path,
) -> Result<Vec<Triangle>> {
    let v = v as i64;
    triangles
        .into_iter()
        .map(|tri| {
            let mut out = [0u32; 3];
            for (o, (index, line_no)) in out.iter_mut().zip(tri) {
                if index < 1 || index > v {
                    return Err(line_error(
                        path,
                        line_no,
                        format!("face refers to vertex {index}, but the file has {v} vertices"),
                    ));
                }
                *o = (index - 1) as u32;
            }
            Ok(out)
        })
        .collect()
}

/// Lines with their 1-based numbers, a trailing `\` joining a line to the next, comments removed.
pub(super) fn logical_lines(text: &str) -> impl Iterator<Item = (usize, Cow<'_, str>)> + '_ {
    let mut lines = physical_lines(text).enumerate();
    std::iter::from_fn(move || {
        let (i, first) = lines.next()?;
        let mut line = Cow::Borrowed(first);
        while line.ends_with('\\') {
            let joined = line.to_mut();
            joined.pop();
            joined.push(' ');
            match lines.next() {
                Some((_, next)) => joined.push_str(next),
                None => break,
            }
        }
        if let Some(hash) = line.bytes().position(|b| b == b'#') {
            line.to_mut().truncate(hash);
        }
        Some((i + 1, line))
    })
}

/// `str::lines`, by a plain byte loop: OBJ lines are a few dozen bytes, on which `lines`'
/// vectorised search spent more in set-up than in searching (a fifth of reading an OBJ frame).
/// Cutting at the ASCII `\n` keeps every piece valid UTF-8.
fn physical_lines(text: &str) -> impl Iterator<Item = &str> + '_ {
    let bytes = text.as_bytes();
    let mut at = 0;
    std::iter::from_fn(move || {
        if at >= bytes.len() {
            return None;
        }
        let start = at;
        let Some(n) = bytes[start..].iter().position(|&b| b == b'\n') else {
            at = bytes.len();
            return text.get(start..);
        };
        at = start + n + 1;
        // As `lines`: a `\r` goes with the `\n` after it, not alone at the end of the text.
        let line = text.get(start..start + n).unwrap_or("");
        Some(line.strip_suffix('\r').unwrap_or(line))
    })
}

/// Reads OBJ files as the frames of one animation; all must share vertex count and faces.
pub(crate) fn read_sequence(files: &[PathBuf]) -> Result<AnimatedMesh> {
    let (first_path, rest) = files
        .split_first()
        .ok_or_else(|| Error::Usage("no .obj files to read".into()))?;
    let (first, skeleton) = FirstObj::read(first_path)?;
    let rest = read_frames(rest, |path| skeleton.read_later(path))?;
    let frames = std::iter::once(first.positions).chain(rest).collect();
    AnimatedMesh::new(first.triangles, frames)?.with_attributes(first.attributes)
}

/// `read` of every file, on rayon's threads, in the files' order; the first file's error in that
/// order if any fails, whatever the threads did first.
pub(crate) fn read_frames<T: Send>(
    files: &[PathBuf],
    read: impl Fn(&Path) -> Result<T> + Sync,
) -> Result<Vec<T>> {
    use rayon::prelude::*;
    let read: Vec<Result<T>> = files.par_iter().map(|p| read(p)).collect();
    read.into_iter().collect()
}

/// The error naming `path` and the first way its mesh differs from the first frame's.
pub(super) fn check_same_mesh(
    triangles: &[Triangle],
    vertex_count: usize,
    first_path: &Path,
    frame: &ObjFrame,
    path: &Path,
) -> Result<()> {
    let differs = |what: String| {
        Error::Mesh(format!(
            "frame file {}: {what} (every frame must have the connectivity of the first, {})",
            path.display(),
            first_path.display()
        ))
    };
    if frame.positions.len() != vertex_count {
        return Err(differs(format!(
            "{} vertices, the first frame has {vertex_count}",
            frame.positions.len()
        )));
    }
    if frame.triangles.len() != triangles.len() {
        return Err(differs(format!(
            "{} triangles, the first frame has {}",
            frame.triangles.len(),
            triangles.len()
        )));
    }
    if let Some(t) = (0..triangles.len()).find(|&t| triangles[t] != frame.triangles[t]) {
        let one_based = |tri: Triangle| format!("{} {} {}", tri[0] + 1, tri[1] + 1, tri[2] + 1);
        return Err(differs(format!(
            "triangle {t} is `f {}`, in the first frame it is `f {}`",
            one_based(frame.triangles[t]),
            one_based(triangles[t])
        )));
    }
    Ok(())
}

/// One frame as OBJ text: `v` lines in vertex order (shortest text that reads back to the same
/// `f32`), the first texture-coordinate set as `vt` lines (one per vertex, `v` flipped back to
/// OBJ's upward axis), then `f` lines, `usemtl` before each run of one material.
pub(crate) fn obj_text(
    triangles: &[Triangle],
    positions: &[Point],
    attributes: &Attributes,
) -> String {
    use std::fmt::Write;
    let mut out = String::with_capacity(positions.len() * 40 + triangles.len() * 24);
    // Writing to a String cannot fail.
    for p in positions {
        let _ = writeln!(out, "v {} {} {}", p[0], p[1], p[2]);
    }
    let texcoords = attributes
        .texcoords
        .first()
        .filter(|s| s.len() == positions.len());
    for uv in texcoords.into_iter().flatten() {
        let _ = writeln!(out, "vt {} {}", uv[0], 1.0 - uv[1]);
    }
    let mut material = None;
    for (i, t) in triangles.iter().enumerate() {
        let m = attributes.materials.get(i).copied();
        if m != material {
            if let Some(name) = m.and_then(|m| attributes.material_names.get(m as usize)) {
                let _ = writeln!(out, "usemtl {name}");
            }
            material = m;
        }
        let [a, b, c] = t.map(|v| v + 1);
        match texcoords {
            Some(_) => writeln!(out, "f {a}/{a} {b}/{b} {c}/{c}"),
            None => writeln!(out, "f {a} {b} {c}"),
        }
        .unwrap_or_default();
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn physical_lines_are_str_lines() {
        for text in [
            "",
            "\n",
            "a",
            "a\n",
            "a\r\nb\n\nc",
            "x\r",
            "\r\n",
            "\n\n",
            "v 1 2\r\r\n",
        ] {
            let ours: Vec<&str> = physical_lines(text).collect();
            let std: Vec<&str> = text.lines().collect();
            assert_eq!(ours, std, "{text:?}");
        }
    }

    #[test]
    fn polygons_fan_and_unused_vertices_stay() {
        let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 9 9 9\ng a\nf 1/1/1 2/2 3//3 4\n";
        let frame = parse_obj(text, Path::new("t.obj")).unwrap();
        assert_eq!(frame.positions.len(), 5);
        assert_eq!(frame.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    }

    #[test]
    fn negative_and_forward_references() {
        let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nf -3 -2 -1\nf 1 3 4\nv 2 2 2\n";
        let frame = parse_obj(text, Path::new("t.obj")).unwrap();
        assert_eq!(frame.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        let bad = "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 7\n";
        let err = parse_obj(bad, Path::new("t.obj")).unwrap_err().to_string();
        assert!(err.contains("line 4") && err.contains("vertex 7"), "{err}");
    }
}
