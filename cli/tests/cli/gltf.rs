//! glTF output checked by the Khronos glTF-Validator: every sample in `media/`, encoded and decoded
//! to `.glb`, and converted to `.gltf`, must validate with no errors.
//!
//! The validator is npm's `gltf-validator`, installed by `make node-tools` (a step of `make test`)
//! into `scripts/node/`. A missing validator fails the test: a check that silently skips checks nothing.

use crate::common::{media_path, ok, repo_root, run};
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
    let mut names: Vec<String> = std::fs::read_dir(repo_root().join("media"))
        .expect("media/ lists")
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".glb") || n.ends_with(".gltf"))
        .collect();
    names.sort();
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
        ok(&run(&["decode", &s(&stream), "-o", &s(&glb), "--quiet"]));
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
