//! glTF output: what `write_gltf` writes reads back, through the crate's own glTF reader (which bakes
//! morph targets by the specification), as the same frames.

use crate::common::{base64, decode_all, encode_bytes, read_media};
use mcgv_video::codec::Codec;
use mcgv_video::encoder::EncodeOptions;
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

/// A square of two primitives that share their vertices and one material "skin"; a morph target
/// lifts one corner over one second.
fn two_primitives_one_material() -> String {
    let floats: [f32; 28] = [
        0., 0., 0., 1., 0., 0., 1., 1., 0., 0., 1., 0., // positions
        0., 0., 0., 0., 0., 0., 0., 0., 1., 0., 0., 0., // target 0 displacements
        0., 1., // key times
        0., 1., // weights at the keys
    ];
    let bytes: Vec<u8> = floats.iter().flat_map(|v| v.to_le_bytes()).collect();
    let indices: Vec<u8> = [0u16, 1, 2, 0, 2, 3]
        .iter()
        .flat_map(|i| i.to_le_bytes())
        .collect();
    let all = [bytes, indices].concat();
    format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],
        "nodes":[{{"mesh":0}}],"materials":[{{"name":"skin"}}],
        "meshes":[{{"primitives":[
            {{"attributes":{{"POSITION":0}},"indices":4,"material":0,"targets":[{{"POSITION":1}}]}},
            {{"attributes":{{"POSITION":0}},"indices":5,"material":0,"targets":[{{"POSITION":1}}]}}]}}],
        "animations":[{{"channels":[{{"sampler":0,"target":{{"node":0,"path":"weights"}}}}],
            "samplers":[{{"input":2,"output":3,"interpolation":"LINEAR"}}]}}],
        "accessors":[
            {{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},
            {{"bufferView":0,"byteOffset":48,"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[0,0,1]}},
            {{"bufferView":0,"byteOffset":96,"componentType":5126,"count":2,"type":"SCALAR","min":[0],"max":[1]}},
            {{"bufferView":0,"byteOffset":104,"componentType":5126,"count":2,"type":"SCALAR"}},
            {{"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}},
            {{"bufferView":1,"byteOffset":6,"componentType":5123,"count":3,"type":"SCALAR"}}],
        "bufferViews":[{{"buffer":0,"byteLength":112}},{{"buffer":0,"byteOffset":112,"byteLength":12}}],
        "buffers":[{{"byteLength":124,"uri":"data:application/octet-stream;base64,{}"}}]}}"#,
        base64(&all)
    )
}

/// Primitives that share a material stay primitives of their own through a stream: the decoded
/// glTF has one primitive per source primitive, and one material.
#[test]
fn primitives_sharing_a_material_come_back_apart() {
    let json = two_primitives_one_material();
    let mesh = parse_gltf(json.as_bytes(), Path::new("two.gltf"), Some(4.0), None).unwrap();
    assert_eq!(mesh.attributes().materials, [0, 1]);
    assert_eq!(mesh.attributes().material_names, ["skin", "skin"]);
    let opts = EncodeOptions {
        codec: Codec::Tdct.into(),
        clusters: 1,
        ..Default::default()
    };
    let decoded = decode_all(encode_bytes(&mesh, &opts)).unwrap();
    let attributes = decoded.attributes();
    let bytes = gltf_bytes(&decoded, Some(attributes), &GltfOptions::default(), true).unwrap();
    let (doc, _, _) = gltf::import_slice(&bytes).unwrap();
    let primitives: Vec<_> = doc.meshes().flat_map(|m| m.primitives()).collect();
    assert_eq!(primitives.len(), 2);
    for p in &primitives {
        assert_eq!(p.material().index(), Some(0));
        assert_eq!(p.indices().map(|a| a.count()), Some(3));
    }
    assert_eq!(doc.materials().count(), 1);
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
