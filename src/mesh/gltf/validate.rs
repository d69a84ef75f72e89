//! Checks of a glTF document before anything reads it: the GLB header, the indices gltf-json's own
//! validation would trip over, buffer file names, and every accessor's element type and extent.
//!
//! The gltf crate (1.4) panics, overflows or misreads on several kinds of malformed file (found by
//! the read_mesh fuzzer); each check here turns one of them into an error naming the culprit.

use crate::error::{Error, Result};
use gltf::accessor::{DataType, Dimensions};
use gltf::json::validation::Validate;
use std::path::Path;

/// Component types glTF allows for rotations and morph weights (floats or normalised integers).
pub(super) const NORMALISED: [DataType; 5] = [
    DataType::F32,
    DataType::I8,
    DataType::U8,
    DataType::I16,
    DataType::U16,
];

/// Parses glTF JSON or a GLB, after checking the GLB header's total length (gltf 1.4 subtracts
/// the header size from it unchecked, which overflows for lengths under 12).
pub(super) fn from_slice(bytes: &[u8], path: &Path) -> Result<gltf::Gltf> {
    let fail = |what: String| Error::Mesh(format!("{}: {what}", path.display()));
    check_glb_header(bytes).map_err(fail)?;
    let gltf = gltf::Gltf::from_slice_without_validation(bytes).map_err(|e| {
        // Neither the GLB magic nor a JSON object: say what the file is not, not where JSON failed.
        let text = bytes.iter().find(|b| !b.is_ascii_whitespace());
        if !bytes.starts_with(b"glTF") && text != Some(&b'{') {
            fail(format!(
                "not a glTF file (neither a GLB nor glTF JSON: {e})"
            ))
        } else {
            fail(e.to_string())
        }
    })?;
    let root = gltf.document.as_json();
    check_attribute_accessors(root).map_err(fail)?;
    check_channel_targets(root).map_err(fail)?;
    validate_json(root).map_err(fail)?;
    Ok(gltf)
}

/// A GLB's total length must cover its 12-byte header and not run past the file.
fn check_glb_header(bytes: &[u8]) -> Result<(), String> {
    if !bytes.starts_with(b"glTF") {
        return Ok(());
    }
    let length = bytes
        .get(8..12)
        .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]) as usize);
    match length {
        Some(n) if (12..=bytes.len()).contains(&n) => Ok(()),
        Some(n) => Err(format!(
            "GLB header gives a length of {n} bytes, the file has {} (at least 12 needed)",
            bytes.len()
        )),
        None => Err("GLB header is truncated".into()),
    }
}

/// gltf-json's validation looks up a primitive's POSITION accessor before checking the index (an
/// out-of-range one panics), so attribute indices are checked before it runs.
fn check_attribute_accessors(root: &gltf::json::Root) -> Result<(), String> {
    for (m, mesh) in root.meshes.iter().enumerate() {
        for primitive in &mesh.primitives {
            if let Some(bad) = primitive
                .attributes
                .values()
                .find(|a| a.value() >= root.accessors.len())
            {
                return Err(format!(
                    "mesh {m}: attribute accessor {} does not exist ({} accessors)",
                    bad.value(),
                    root.accessors.len()
                ));
            }
        }
    }
    Ok(())
}

/// Nor does the validation check an animation channel's target (gltf 1.4 unwraps an unknown `path`
/// and indexes the node unchecked; found by the read_mesh fuzzer).
fn check_channel_targets(root: &gltf::json::Root) -> Result<(), String> {
    for (a, animation) in root.animations.iter().enumerate() {
        for (c, channel) in animation.channels.iter().enumerate() {
            let target = &channel.target;
            if target.node.value() >= root.nodes.len() {
                return Err(format!(
                    "animation {a} channel {c}: target node {} does not exist ({} nodes)",
                    target.node.value(),
                    root.nodes.len()
                ));
            }
            if matches!(target.path, gltf::json::validation::Checked::Invalid) {
                return Err(format!("animation {a} channel {c}: unknown target path"));
            }
        }
    }
    Ok(())
}

/// gltf-json's own validation of the whole document; the error counts the problems and shows the first.
fn validate_json(root: &gltf::json::Root) -> Result<(), String> {
    let mut errors = Vec::new();
    root.validate(root, gltf::json::Path::new, &mut |path, error| {
        errors.push(format!("{}: {error}", path()))
    });
    match errors.first() {
        Some(first) => Err(format!(
            "invalid glTF ({} problems), first: {first}",
            errors.len()
        )),
        None => Ok(()),
    }
}

/// Every relative buffer URI must percent-decode to UTF-8 (see [`percent_decodes_to_utf8`]).
pub(super) fn check_buffer_uris(document: &gltf::Document) -> Result<(), String> {
    for buffer in document.buffers() {
        if let gltf::buffer::Source::Uri(uri) = buffer.source() {
            if !uri.contains(':') && !percent_decodes_to_utf8(uri) {
                return Err(format!(
                    "buffer {}: the file name {uri:?} is not valid percent-encoded UTF-8",
                    buffer.index()
                ));
            }
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

/// The gltf crate's readers take an accessor's element type from its use and only debug-assert (or
/// `unreachable!`) that the file agrees; a file that lies about it must be an error, not a panic or
/// a misread.
pub(super) fn check_accessor(
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
pub(super) fn check_extent(a: &gltf::Accessor, what: &str) -> Result<(), String> {
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
