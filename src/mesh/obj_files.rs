//! Which files make an OBJ sequence, in what order: a folder's `.obj` files, the ones a glob
//! pattern matches, or one file, ordered by the last number in their names (`frame_2` before
//! `frame_10`; docs/design.md, "Own OBJ parser").

use crate::error::{Error, Result};
use std::cmp::Ordering;
use std::path::{Path, PathBuf};

/// The frame files named by `input`: a folder's `.obj` files, the `.obj` files a glob pattern
/// matches, or one `.obj` file; several files are ordered by the last number in their names.
pub(crate) fn frame_files(input: &str) -> Result<Vec<PathBuf>> {
    let path = Path::new(input);
    let files: Vec<PathBuf> = if path.is_dir() {
        let entries = std::fs::read_dir(path).map_err(|e| Error::io(path, e))?;
        let mut files = Vec::new();
        for entry in entries {
            let entry = entry.map_err(|e| Error::io(path, e))?;
            let p = entry.path();
            if p.is_file() && has_obj_extension(&p) {
                files.push(p);
            }
        }
        if files.is_empty() {
            return Err(Error::Usage(format!("{input}: folder holds no .obj files")));
        }
        files
    } else if path.is_file() {
        if !has_obj_extension(path) {
            return Err(Error::Usage(format!(
                "{input}: not a form this tool reads (a folder or glob of .obj files, .obj, .pc2, .gltf, .glb)"
            )));
        }
        vec![path.to_path_buf()]
    } else if input.contains(['*', '?', '[']) {
        let pattern =
            glob::glob(input).map_err(|e| Error::Usage(format!("{input}: bad pattern: {e}")))?;
        let mut files = Vec::new();
        for p in pattern {
            let p = p.map_err(|e| Error::io(e.path().to_path_buf(), e.into()))?;
            if p.is_file() && has_obj_extension(&p) {
                files.push(p);
            }
        }
        if files.is_empty() {
            return Err(Error::Usage(format!("{input}: no .obj files match")));
        }
        files
    } else {
        return Err(Error::Usage(format!("{input}: no such file or folder")));
    };
    order_by_number(files)
}

fn has_obj_extension(p: &Path) -> bool {
    p.extension().is_some_and(|e| e.eq_ignore_ascii_case("obj"))
}

/// Sorts frame files by the last run of digits in their file stems (`frame_2` before `frame_10`).
/// Two files with the same number, or a file without one, make the order ambiguous: an error.
pub(crate) fn order_by_number(files: Vec<PathBuf>) -> Result<Vec<PathBuf>> {
    if files.len() < 2 {
        return Ok(files);
    }
    let mut keyed = files
        .into_iter()
        .map(|p| {
            let number = frame_number(&p).ok_or_else(|| {
                Error::Usage(format!(
                    "{}: no number in the file name to order the frames by",
                    p.display()
                ))
            })?;
            Ok((number, p))
        })
        .collect::<Result<Vec<_>>>()?;
    keyed.sort_by(|a, b| compare_numbers(&a.0, &b.0).then_with(|| a.1.cmp(&b.1)));
    if let Some(pair) = keyed
        .windows(2)
        .find(|w| compare_numbers(&w[0].0, &w[1].0) == Ordering::Equal)
    {
        return Err(Error::Usage(format!(
            "{} and {} have the same frame number",
            pair[0].1.display(),
            pair[1].1.display()
        )));
    }
    Ok(keyed.into_iter().map(|(_, p)| p).collect())
}

/// The last run of ASCII digits in the file stem, leading zeros removed (`"0"` for all zeros).
fn frame_number(path: &Path) -> Option<String> {
    let stem = path.file_stem()?.to_string_lossy();
    let end = stem.rfind(|c: char| c.is_ascii_digit())? + 1;
    let start = stem[..end]
        .rfind(|c: char| !c.is_ascii_digit())
        .map_or(0, |i| i + 1);
    let trimmed = stem[start..end].trim_start_matches('0');
    Some(if trimmed.is_empty() { "0" } else { trimmed }.to_owned())
}

/// Compares digit strings without leading zeros as numbers of any length.
fn compare_numbers(a: &str, b: &str) -> Ordering {
    a.len().cmp(&b.len()).then_with(|| a.cmp(b))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_order_like_numbers() {
        let names = ["frame_10.obj", "frame_2.obj", "frame_1.obj", "frame_0.obj"];
        let files = names.iter().map(PathBuf::from).collect();
        let ordered = order_by_number(files).unwrap();
        let got: Vec<_> = ordered
            .iter()
            .map(|p| p.to_string_lossy().into_owned())
            .collect();
        assert_eq!(
            got,
            ["frame_0.obj", "frame_1.obj", "frame_2.obj", "frame_10.obj"]
        );
    }

    #[test]
    fn last_number_counts_and_zeros_do_not() {
        assert_eq!(
            frame_number(Path::new("take3/mesh.007.obj")).as_deref(),
            Some("7")
        );
        assert_eq!(
            frame_number(Path::new("v2_frame_0000.obj")).as_deref(),
            Some("0")
        );
        assert_eq!(frame_number(Path::new("mesh.obj")), None);
        let dup = vec![PathBuf::from("a_01.obj"), PathBuf::from("b_1.obj")];
        assert!(order_by_number(dup).is_err());
    }
}
