//! Texture coordinates and materials through the stream: UVs come back within half a quantisation
//! step, material groups exactly, whatever order the first-frame coder puts triangles in.

use crate::common::{decode_all, encode_bytes, read_media};
use mcgv_video::mesh::{parse_obj, write_obj_sequence};
use mcgv_video::stream::attributes::{decode_attributes, encode_attributes};
use mcgv_video::{read_animation, AnimatedMesh, Attributes, Codec, EncodeOptions, ReadOptions};
use std::path::Path;

/// Largest UV error over every set, in units of the set's quantisation step at `bits`.
fn uv_error_in_steps(source: &Attributes, back: &Attributes, order: &[u32], bits: u8) -> f64 {
    assert_eq!(source.texcoords.len(), back.texcoords.len());
    let mut worst = 0.0f64;
    for (set, decoded) in source.texcoords.iter().zip(&back.texcoords) {
        for a in 0..2 {
            let lo = set.iter().map(|uv| uv[a]).fold(f32::INFINITY, f32::min);
            let hi = set.iter().map(|uv| uv[a]).fold(f32::NEG_INFINITY, f32::max);
            let step = f64::from(hi - lo) / f64::from((1u32 << bits) - 1);
            for (new, &old) in order.iter().enumerate() {
                let e = f64::from((decoded[new][a] - set[old as usize][a]).abs());
                worst = worst.max(e / step.max(f64::MIN_POSITIVE));
            }
        }
    }
    worst
}

/// Each triangle's material keyed by its (sorted) vertices, in the source's vertex numbering.
fn material_of(mesh: &AnimatedMesh, order: &[u32]) -> Vec<([u32; 3], String)> {
    let a = mesh.attributes();
    let mut out: Vec<_> = mesh
        .triangles()
        .iter()
        .zip(&a.materials)
        .map(|(t, &m)| {
            let mut k = t.map(|v| order[v as usize]);
            k.sort_unstable();
            (k, a.material_names[m as usize].clone())
        })
        .collect();
    out.sort();
    out
}

#[test]
fn the_samples_have_uvs_and_materials() {
    for name in ["CesiumMan.glb", "Fox.glb"] {
        let mesh = read_media(name);
        let a = mesh.attributes();
        assert_eq!(a.texcoords.len(), 1, "{name}");
        assert!(!a.materials.is_empty(), "{name}");
    }
}

#[test]
fn the_part_round_trips_within_half_a_step_at_every_bit_depth() {
    // CesiumMan shares vertices inside its charts; Fox splits every triangle (copies reuse).
    for name in ["CesiumMan.glb", "Fox.glb"] {
        let mesh = read_media(name);
        let identity: Vec<u32> = (0..mesh.vertex_count() as u32).collect();
        for bits in [8, 12, 16] {
            let (triangles, positions) = (mesh.triangles(), mesh.frame(0));
            let bytes = encode_attributes(mesh.attributes(), triangles, positions, bits).unwrap();
            let back = decode_attributes(&bytes, triangles, positions).unwrap();
            let steps = uv_error_in_steps(mesh.attributes(), &back, &identity, bits);
            assert!(steps <= 0.5 + 1e-3, "{name} {bits} bits: {steps} steps");
            assert_eq!(back.materials, mesh.attributes().materials, "{name}");
            assert_eq!(back.material_names, mesh.attributes().material_names);
        }
    }
}

#[test]
fn uvs_cost_less_than_draco_codes_them() {
    // DracoPy 2.2 (scripts/draco_uv.py: level 10, 12-bit UVs) spends 3 598 and 733 bytes on these UVs
    // (the size with UVs less the size without). The margin keeps the test about regressions.
    for (name, draco) in [("CesiumMan.glb", 3598), ("Fox.glb", 733)] {
        let mesh = read_media(name);
        let (triangles, positions) = (mesh.triangles(), mesh.frame(0));
        let bytes = encode_attributes(mesh.attributes(), triangles, positions, 12).unwrap();
        assert!(bytes.len() < draco * 3 / 2, "{name}: {} bytes", bytes.len());
    }
}

#[test]
fn a_stream_keeps_uvs_and_material_groups_with_and_without_reordering() {
    for (name, reorder) in [
        ("CesiumMan.glb", false),
        ("CesiumMan.glb", true),
        ("Fox.glb", true),
    ] {
        let mesh = read_media(name);
        let options = EncodeOptions {
            codec: Codec::Tdct.into(),
            reorder,
            ..EncodeOptions::default()
        };
        let encoded = mcgv_video::encode(&mesh, &options).unwrap();
        let order = encoded
            .report
            .permutation
            .clone()
            .unwrap_or_else(|| (0..mesh.vertex_count() as u32).collect());
        let back = decode_all(encoded.to_bytes()).unwrap();
        let steps = uv_error_in_steps(mesh.attributes(), back.attributes(), &order, 12);
        assert!(
            steps <= 0.5 + 1e-3,
            "{name} reorder {reorder}: {steps} steps"
        );
        let identity: Vec<u32> = (0..mesh.vertex_count() as u32).collect();
        assert_eq!(material_of(&back, &order), material_of(&mesh, &identity));
    }
}

#[test]
fn inputs_without_attributes_get_no_part_and_a_corrupt_part_is_an_error() {
    let mesh = read_media("CesiumMan.glb");
    let (triangles, frames) = mesh.clone().into_parts();
    let bare = AnimatedMesh::new(triangles, frames).unwrap();
    let options = EncodeOptions {
        codec: Codec::Tdct.into(),
        ..EncodeOptions::default()
    };
    let bytes = encode_bytes(&bare, &options);
    assert!(!crate::common::parts(&bytes)
        .iter()
        .any(|(t, _, _)| &t.0 == b"ATTR"));
    let (triangles, positions) = (mesh.triangles(), mesh.frame(0));
    let part = encode_attributes(mesh.attributes(), triangles, positions, 12).unwrap();
    for cut in [1, part.len() / 2, part.len() - 1] {
        assert!(decode_attributes(&part[..cut], triangles, positions).is_err());
    }
}

#[test]
fn obj_frames_carry_vt_and_usemtl_there_and_back() {
    let mesh = read_media("CesiumMan.glb");
    let (triangles, frames) = mesh.clone().into_parts();
    let two = AnimatedMesh::new(triangles, frames[..2].to_vec())
        .unwrap()
        .with_attributes(mesh.attributes().clone())
        .unwrap();
    let dir = tempfile::tempdir().unwrap();
    write_obj_sequence(&two, dir.path()).unwrap();
    let back = read_animation(&dir.path().display().to_string(), &ReadOptions::default()).unwrap();
    let (a, b) = (mesh.attributes(), back.attributes());
    assert_eq!(b.materials, a.materials);
    assert_eq!(b.material_names, a.material_names);
    assert_eq!(b.texcoords.len(), 1);
    // `vt` stores 1 - v (OBJ's v points up): one f32 rounding each way.
    for (p, q) in a.texcoords[0].iter().zip(&b.texcoords[0]) {
        assert!(
            (p[0] - q[0]).abs() <= 1e-6 && (p[1] - q[1]).abs() <= 1e-6,
            "{p:?} {q:?}"
        );
    }
}

#[test]
fn obj_vt_is_kept_only_when_each_vertex_has_one() {
    let name = Path::new("t.obj");
    let quad = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n";
    let one = parse_obj(
        &format!("{quad}usemtl a\nf 1/1 2/2 3/3\nusemtl b\nf 1/1 3/3 4/4\n"),
        name,
    );
    let one = one.unwrap();
    let a = one.attributes();
    assert_eq!(
        a.texcoords,
        vec![vec![[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]]]
    );
    assert_eq!(
        (a.materials.clone(), a.material_names.clone()),
        (vec![0, 1], vec!["a".into(), "b".into()])
    );
    // Vertex 1 with two coordinates (a seam the file does not split): no UVs rather than wrong ones.
    let seam = parse_obj(&format!("{quad}f 1/1 2/2 3/3\nf 1/2 3/3 4/4\n"), name).unwrap();
    assert!(seam.attributes().texcoords.is_empty());
    assert!(seam.attributes().is_empty());
}
