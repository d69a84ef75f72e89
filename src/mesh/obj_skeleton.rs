//! The later frames of an OBJ sequence, read by their positions alone when the rest of the file
//! is the first frame's.
//!
//! Every frame file repeats the first one's faces, and parsing them (then checking they are the
//! first frame's) was most of reading a frame: on pdance two thirds of the lines are faces. A
//! later file whose `f` and `vt` lines are the first file's, byte for byte and in the same places
//! among its `v` lines, has the first file's faces, vertex count and errors (none), so only its
//! `v` lines are parsed. Any other file — other spacing, another index form, another face — is
//! parsed in full and checked as before: the same positions and the same errors either way.

use super::obj::{check_same_mesh, logical_lines, parse_obj, parse_vertex, read_text};
use super::obj::{line_error, ObjFrame};
use super::{Point, Triangle};
use crate::error::Result;
use std::path::{Path, PathBuf};

/// The first frame of a sequence, as later frames are checked against it.
pub(crate) struct FirstObj {
    path: PathBuf,
    triangles: Vec<Triangle>,
    vertices: usize,
    /// The `f` and `vt` lines of the first file, each ending in `\n`, with `v\n` for each `v`
    /// line: what a later file must repeat to be read by its positions alone. Other lines (normals,
    /// groups, materials, comments) change nothing the parser keeps of a later frame.
    skeleton: Vec<u8>,
}

/// What a line is to the skeleton.
enum Role {
    Vertex,
    Kept,
    Ignored,
}

fn role(line: &str) -> Role {
    match line.split_ascii_whitespace().next() {
        Some("v") => Role::Vertex,
        Some("f") | Some("vt") => Role::Kept,
        _ => Role::Ignored,
    }
}

impl FirstObj {
    /// Reads the first frame's file: its frame and what later frames are checked against.
    pub(crate) fn read(path: &Path) -> Result<(ObjFrame, Self)> {
        let text = read_text(path)?;
        let frame = parse_obj(&text, path)?;
        let mut skeleton = Vec::new();
        for (_, line) in logical_lines(&text) {
            match role(&line) {
                Role::Vertex => skeleton.extend_from_slice(b"v\n"),
                Role::Kept => {
                    skeleton.extend_from_slice(line.as_bytes());
                    skeleton.push(b'\n');
                }
                Role::Ignored => {}
            }
        }
        let first = Self {
            path: path.to_path_buf(),
            triangles: frame.triangles.clone(),
            vertices: frame.positions.len(),
            skeleton,
        };
        Ok((frame, first))
    }

    /// The positions of a later frame's file, which must have the first frame's connectivity.
    pub(crate) fn read_later(&self, path: &Path) -> Result<Vec<Point>> {
        let text = read_text(path)?;
        if let Some(positions) = self.positions_if_alike(&text, path)? {
            return Ok(positions);
        }
        let frame = parse_obj(&text, path)?;
        check_same_mesh(&self.triangles, self.vertices, &self.path, &frame, path)?;
        Ok(frame.positions)
    }

    /// The positions of `text` when its skeleton is the first file's; `None` when it is not.
    fn positions_if_alike(&self, text: &str, path: &Path) -> Result<Option<Vec<Point>>> {
        let mut positions = Vec::with_capacity(self.vertices);
        let mut rest = &self.skeleton[..];
        for (line_no, line) in logical_lines(text) {
            let role = role(&line);
            let expected: &[u8] = match role {
                Role::Vertex => b"v",
                Role::Kept => line.as_bytes(),
                Role::Ignored => continue,
            };
            let after = rest.strip_prefix(expected);
            let Some(after) = after.and_then(|a| a.strip_prefix(b"\n")) else {
                return Ok(None);
            };
            rest = after;
            if let Role::Vertex = role {
                let mut words = line.split_ascii_whitespace();
                words.next();
                let p = parse_vertex(words, positions.len());
                positions.push(p.map_err(|what| line_error(path, line_no, what))?);
            }
        }
        Ok(rest.is_empty().then_some(positions))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn first(dir: &Path, text: &str) -> FirstObj {
        let path = dir.join("0.obj");
        std::fs::write(&path, text).unwrap();
        FirstObj::read(&path).unwrap().1
    }

    #[test]
    fn a_later_frame_is_read_alike_or_in_full_with_the_same_result() {
        let dir = tempfile::tempdir().unwrap();
        let first = first(
            dir.path(),
            "# first\nv 0 0 0\nv 1 0 0\nvn 0 0 1\nv 0 1 0\nf -3 -2 -1\nv 1 1 0\nf 2 3 4\n",
        );
        let later = |text: &str| {
            let path = dir.path().join("1.obj");
            std::fs::write(&path, text).unwrap();
            (
                first.positions_if_alike(text, &path).ok().flatten(),
                first.read_later(&path),
            )
        };
        let want = vec![
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 1.0],
            [0.0, 1.0, 1.0],
            [1.0, 1.0, 1.0],
        ];
        // Other normals and comments: alike.
        let (alike, read) =
            later("v 0 0 1\nv 1 0 1 # x\nvn 1 0 0\nv 0 1 1\nf -3 -2 -1\nv 1 1 1\nf 2 3 4\n");
        assert_eq!(alike.as_deref(), Some(&want[..]));
        assert_eq!(read.unwrap(), want);
        // Another spelling of the same faces: read in full, the same positions.
        let (alike, read) = later("v 0 0 1\nv 1 0 1\nv 0 1 1\nf 1  2 3\nv 1 1 1\nf 2 3 4\n");
        assert_eq!(alike, None);
        assert_eq!(read.unwrap(), want);
        // The last vertex moved before the first face: its negative indices name other
        // vertices, so the skeleton differs and the full read finds the other face.
        let (alike, read) = later("v 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\nf -3 -2 -1\nf 2 3 4\n");
        assert_eq!(alike, None);
        assert!(read.unwrap_err().to_string().contains("triangle 0"));
        // A missing vertex, and a bad coordinate with its line number.
        assert_eq!(
            later("v 0 0 1\nv 1 0 1\nv 0 1 1\nf -3 -2 -1\nf 2 3 4\n").0,
            None
        );
        let bad = later("v 0 0 1\nv 1 0 x\nv 0 1 1\nf -3 -2 -1\nv 1 1 1\nf 2 3 4\n").1;
        assert!(bad.unwrap_err().to_string().contains("line 2"));
    }
}
