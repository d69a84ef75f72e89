//! glTF output: what `write_gltf` writes reads back, through the crate's own glTF reader (which bakes
//! morph targets by the specification), as the same frames.

use crate::common::read_media;
use mcgv_video::mesh::gltf_write::gltf_bytes;
use mcgv_video::mesh::{parse_gltf, GltfOptions};
use mcgv_video::{AnimatedMesh, Attributes};
use std::path::Path;

fn max_difference(a: &AnimatedMesh, b: &AnimatedMesh) -> f32 {
    a.frames()
        .iter()
        .flatten()
        .zip(b.frames().iter().flatten())
        .flat_map(|(p, q)| (0..3).map(move |k| (p[k] - q[k]).abs()))
        .fold(0.0, f32::max)
}

#[test]
fn glb_and_gltf_read_back_as_the_same_frames() {
    let mesh = read_media("RiggedSimple.glb");
    for binary in [true, false] {
        let bytes = gltf_bytes(&mesh, None, &GltfOptions::default(), binary).unwrap();
        let name = if binary { "out.glb" } else { "out.gltf" };
        let back = parse_gltf(&bytes, Path::new(name), Some(30.0), None).unwrap();
        assert_eq!(back.frame_count(), mesh.frame_count());
        assert_eq!(back.triangles(), mesh.triangles());
        let scale = mesh.bbox_diagonal() as f32;
        let d = max_difference(&back, &mesh);
        assert!(d <= 1e-5 * scale, "{name}: {d} of {scale}");
    }
}

#[test]
fn material_groups_become_primitives_that_keep_every_triangle() {
    let mesh = read_media("RiggedSimple.glb");
    let t = mesh.triangles().len();
    let attributes = Attributes {
        texcoords: vec![vec![[0.25, 0.5]; mesh.vertex_count()]],
        materials: (0..t as u32).map(|i| i % 2).collect(),
        material_names: vec!["a".into(), "b".into()],
    };
    let bytes = gltf_bytes(&mesh, Some(&attributes), &GltfOptions::default(), true).unwrap();
    let back = parse_gltf(&bytes, Path::new("out.glb"), Some(30.0), None).unwrap();
    let mut got: Vec<_> = back.triangles().to_vec();
    let mut want: Vec<_> = mesh.triangles().to_vec();
    got.sort();
    want.sort();
    assert_eq!(got, want);
    let (doc, _, _) = gltf::import_slice(&bytes).unwrap();
    let primitives: Vec<_> = doc.meshes().flat_map(|m| m.primitives()).collect();
    assert_eq!(primitives.len(), 2);
    assert!(primitives[0].get(&gltf::Semantic::TexCoords(0)).is_some());
}

#[test]
fn bad_attributes_and_rates_are_errors() {
    let mesh = read_media("RiggedSimple.glb");
    let short = Attributes {
        texcoords: vec![vec![[0.0, 0.0]; 3]],
        ..Attributes::default()
    };
    let err = gltf_bytes(&mesh, Some(&short), &GltfOptions::default(), true).unwrap_err();
    assert!(
        err.to_string().contains("texture coordinate set 0"),
        "{err}"
    );
    let options = GltfOptions {
        fps: 0.0,
        ..GltfOptions::default()
    };
    let err = gltf_bytes(&mesh, None, &options, true).unwrap_err();
    assert!(err.to_string().contains("fps"), "{err}");
}
