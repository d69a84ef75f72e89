//! glTF output checked by the Khronos glTF-Validator: every sample in `media/`, encoded and decoded
//! to `.glb` (`--like` the sample), and converted to `.gltf`, must validate with no errors.
//!
//! The validator is npm's `gltf-validator`, installed by `make node-tools` (a step of `make test`)
//! into `scripts/node/`. A missing validator fails the test: a check that silently skips checks nothing.

use crate::common::{file_names, json, media_path, ok, repo_root, run};
use std::path::{Path, PathBuf};
use std::process::Command;

/// `node scripts/validate_gltf.mjs FILES…`, asserting the validator is installed.
fn validate(files: &[PathBuf]) -> std::process::Output {
    let root = repo_root();
    let installed = root.join("scripts/node/node_modules/gltf-validator");
    assert!(
        installed.is_dir(),
        "{} is missing: run `make node-tools` (or `make test`)",
        installed.display()
    );
    Command::new("node")
        .arg(root.join("scripts/validate_gltf.mjs"))
        .args(files)
        .output()
        .unwrap_or_else(|e| panic!("running node: {e}"))
}

fn samples() -> Vec<String> {
    let mut names = file_names(&repo_root().join("media"));
    names.retain(|n| n.ends_with(".glb") || n.ends_with(".gltf"));
    names
}

#[test]
fn decoded_and_converted_gltf_of_every_sample_validates() {
    let dir = tempfile::tempdir().unwrap();
    let mut files = Vec::new();
    for name in samples() {
        let stem = Path::new(&name)
            .file_stem()
            .unwrap()
            .to_string_lossy()
            .into_owned();
        let stream = dir.path().join(format!("{stem}.mcgv"));
        let glb = dir.path().join(format!("{stem}-decoded.glb"));
        let gltf = dir.path().join(format!("{stem}-converted.gltf"));
        let input = media_path(&name);
        let s = |p: &Path| p.display().to_string();
        ok(&run(&[
            "encode",
            &input,
            "-o",
            &s(&stream),
            "--codec",
            "tdct",
            "--quiet",
        ]));
        // With the source's materials and textures: the copied JSON and images validate too.
        let like = ["--like", &input, "--quiet"];
        ok(&run(
            &[&["decode", &s(&stream), "-o", &s(&glb)][..], &like].concat()
        ));
        ok(&run(&["convert", &input, "-o", &s(&gltf), "--quiet"]));
        files.extend([glb, gltf]);
    }
    assert!(files.len() >= 8, "media/ holds the four glTF samples");
    let out = validate(&files);
    let report = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "validator errors:\n{report}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for line in report.lines() {
        assert!(line.contains("\"errors\":0"), "{line}");
    }
}

#[test]
fn a_bad_frame_rate_for_gltf_output_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let stream = dir.path().join("s.mcgv");
    let s = stream.display().to_string();
    ok(&run(&[
        "encode",
        &media_path("RiggedSimple.glb"),
        "-o",
        &s,
        "--codec",
        "tdct",
        "--quiet",
    ]));
    let out_path = dir.path().join("x.glb").display().to_string();
    let out = run(&["decode", &s, "-o", &out_path, "--fps", "0", "--quiet"]);
    // A bad value is a usage error.
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("fps"));
}

/// The JSON chunk of a GLB file.
fn glb_json(path: &Path) -> serde_json::Value {
    let bytes = std::fs::read(path).unwrap();
    let length = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    serde_json::from_slice(&bytes[20..20 + length]).unwrap()
}

#[test]
fn decode_like_the_source_copies_its_materials_textures_and_node_name() {
    let dir = tempfile::tempdir().unwrap();
    let input = media_path("CesiumMan.glb");
    let stream = dir.path().join("s.mcgv").display().to_string();
    ok(&run(&["encode", &input, "-o", &stream, "--quiet"]));
    let glb = dir.path().join("like.glb");
    let like = ["--like", &input, "--quiet"];
    ok(&run(&[
        &["decode", &stream, "-o", &glb.display().to_string()][..],
        &like,
    ]
    .concat()));
    let (source, decoded) = (glb_json(Path::new(&input)), glb_json(&glb));
    // Copied through gltf-json, which may spell defaults out: compared by what renders.
    let count = |doc: &serde_json::Value, key: &str| doc[key].as_array().map_or(0, Vec::len);
    for key in ["materials", "textures", "samplers"] {
        assert_eq!(count(&decoded, key), count(&source, key), "{key}");
    }
    let texture = |doc: &serde_json::Value| {
        let m = &doc["materials"][0];
        (
            m["name"].clone(),
            m["pbrMetallicRoughness"]["baseColorTexture"]["index"].clone(),
        )
    };
    assert_eq!(texture(&decoded), texture(&source));
    assert_eq!(
        decoded["textures"][0]["source"],
        source["textures"][0]["source"]
    );
    let images = decoded["images"].as_array().expect("images");
    assert_eq!(images.len(), source["images"].as_array().unwrap().len());
    assert!(images.iter().all(|i| i["bufferView"].is_u64()));
    let mesh_node = |doc: &serde_json::Value| {
        let nodes = doc["nodes"].as_array().unwrap().clone();
        nodes.into_iter().find(|n| n.get("mesh").is_some()).unwrap()["name"].clone()
    };
    assert_eq!(mesh_node(&decoded), mesh_node(&source));
    let primitive = &decoded["meshes"][0]["primitives"][0];
    assert_eq!(primitive["material"], 0);
    assert!(primitive["attributes"]["TEXCOORD_0"].is_u64());
    // --like is for glTF outputs only.
    let obj = dir.path().join("f.obj").display().to_string();
    let out = run(&[&["decode", &stream, "-o", &obj, "--frame", "0"][..], &like].concat());
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn decode_frames_a_to_b_keeps_their_numbers() {
    let dir = tempfile::tempdir().unwrap();
    let input = media_path("RiggedSimple.glb");
    let stream = dir.path().join("s.mcgv").display().to_string();
    ok(&run(&["encode", &input, "-o", &stream, "--quiet"]));
    let folder = dir.path().join("frames");
    let out = folder.display().to_string() + "/";
    ok(&run(&[
        "decode", &stream, "-o", &out, "--frames", "2..5", "--quiet",
    ]));
    assert_eq!(
        file_names(&folder),
        ["frame_0002.obj", "frame_0003.obj", "frame_0004.obj"]
    );
    let glb = dir.path().join("part.glb");
    ok(&run(&[
        "decode",
        &stream,
        "-o",
        &glb.display().to_string(),
        "--frames",
        "2..5",
        "--quiet",
    ]));
    // Three frames: the base and two morph targets.
    let json = glb_json(&glb);
    assert_eq!(
        json["meshes"][0]["weights"].as_array().map(Vec::len),
        Some(2)
    );
    for bad in ["5..2", "0..100000", "x..3"] {
        let out = run(&["decode", &stream, "-o", &out, "--frames", bad, "--force"]);
        assert_eq!(out.status.code(), Some(2), "{bad}");
    }
}

/// The stream records a glTF source's frame rate, so the decoded glTF plays at it (CesiumMan: 24
/// fps) unless `--fps` says otherwise; an OBJ source's rate is unknown and the output gets 30.
#[test]
fn decoded_gltf_plays_at_the_source_frame_rate() {
    let dir = tempfile::tempdir().unwrap();
    let stream = dir.path().join("s.mcgv");
    let s = stream.to_str().unwrap();
    let source = media_path("CesiumMan.glb");
    ok(&run(&["encode", &source, "-o", s, "--quiet"]));
    let fps_of = |extra: &[&str]| {
        let out = dir.path().join("out.glb");
        let o = out.to_str().unwrap();
        let mut args = vec!["decode", s, "-o", o, "--quiet", "--force"];
        args.extend_from_slice(extra);
        ok(&run(&args));
        let info = crate::common::json(&run(&["info", o, "--json"]));
        info["clips"][0]["fps"]
            .as_f64()
            .expect("a clip with a rate")
    };
    assert_eq!(fps_of(&[]), 24.0);
    assert_eq!(fps_of(&["--fps", "12"]), 12.0);
    assert_eq!(fps_of(&["--frames", "0..10"]), 24.0);
}

#[test]
fn a_clip_baked_at_5_fps_reads_back_at_5_fps() {
    let dir = tempfile::tempdir().unwrap();
    let input = media_path("RiggedSimple.glb");
    let stream = dir.path().join("s.mcgv").display().to_string();
    let glb = dir.path().join("s.glb").display().to_string();
    ok(&run(&["encode", &input, "--fps", "5", "-o", &stream, "-q"]));
    ok(&run(&["decode", &stream, "-o", &glb, "-q"]));
    // The decoded file's STEP keys are its frames: 5 per second, 2 s of clip.
    let info = json(&run(&["info", &glb, "--json"]));
    let clip = &info["clips"][0];
    assert_eq!(clip["fps"], 5.0, "{info}");
    assert_eq!(clip["frames"], 11, "{info}");
    // Frame for frame against the source baked at that rate.
    let eval = json(&run(&["eval", &input, &glb, "--fps", "5", "--json"]));
    assert_eq!(eval["frames"], 11, "{eval}");
    assert!(
        eval["vertex_rmse"].as_f64().is_some_and(|e| e < 1e-3),
        "{eval}"
    );
}

#[test]
fn eval_clip_names_the_originals_clip() {
    let dir = tempfile::tempdir().unwrap();
    let fox = media_path("Fox.glb");
    let stream = dir.path().join("walk.mcgv").display().to_string();
    let glb = dir.path().join("walk.glb").display().to_string();
    // Fixed choices: the test is about names, not the encoder's search.
    let base = [
        "--codec",
        "jpeg",
        "--predictor",
        "affine",
        "--clusters",
        "5",
        "-q",
    ];
    ok(&run(&[
        &["encode", &fox, "--clip", "Walk", "-o", &stream][..],
        &base,
    ]
    .concat()));
    ok(&run(&["decode", &stream, "-o", &glb, "-q"]));
    // The decoded file's one clip is `frames`: --clip Walk is the original's.
    let eval = json(&run(&["eval", &fox, &glb, "--clip", "Walk", "--json"]));
    let info = json(&run(&["info", &fox, "--clip", "Walk", "--json"]));
    assert_eq!(eval["frames"], info["frames"], "{eval}");
}
