//! `--max-positions`: the commands that decode a stream or bake a glTF clip refuse one of more
//! positions (frames × vertices) than the limit, on stderr with the usage exit code, and accept one
//! at it.

use crate::common::{media_path, ok, run, tiny_stream};
use mcgv_video::codec::Codec;
use std::process::Output;

/// Asserts a refusal by the limit: exit code 2 and a message with every needle.
fn refused(out: &Output, needles: &[&str]) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    for n in needles {
        assert!(err.contains(n), "`{n}` not in: {err}");
    }
}

#[test]
fn decode_inspect_and_eval_refuse_a_stream_past_max_positions() {
    let dir = tempfile::tempdir().unwrap();
    let stream = dir.path().join("s.mcgv");
    std::fs::write(&stream, tiny_stream(Codec::Jpeg)).unwrap(); // 4 vertices × 2 frames
    let s = stream.to_str().unwrap();
    let out = dir.path().join("out.pc2");
    let o = out.to_str().unwrap();
    let decode = |limit: &str| run(&["decode", s, "-o", o, "--max-positions", limit, "--quiet"]);
    refused(
        &decode("7"),
        &[
            "--max-positions is 7",
            "4 vertices × 2 frames = 8 positions",
        ],
    );
    assert!(!out.exists(), "a refused decode wrote {o}");
    ok(&decode("8"));
    assert!(out.is_file());
    refused(
        &run(&["inspect", s, "--max-positions", "7"]),
        &["--max-positions is 7"],
    );
    ok(&run(&["inspect", s, "--max-positions", "8"]));
    refused(
        &run(&["eval", o, s, "--max-positions", "7"]),
        &["--max-positions is 7"],
    );
    let bad = run(&["decode", s, "-o", o, "--max-positions", "0"]);
    assert_eq!(
        bad.status.code(),
        Some(2),
        "a limit of 0 positions is no limit"
    );
}

#[test]
fn encode_refuses_a_gltf_clip_past_max_positions_naming_what_fits() {
    let dir = tempfile::tempdir().unwrap();
    let o = dir.path().join("s.mcgv");
    let out = run(&[
        "encode",
        &media_path("CesiumMan.glb"),
        "-o",
        o.to_str().unwrap(),
        "--fps",
        "48",
        "--max-positions",
        "163650",
        "--quiet",
    ]);
    // 95 frames of 3 273 vertices; 163 650 positions are 50 frames.
    refused(
        &out,
        &[
            "--fps 48 bakes",
            "95 frames of 3273 vertices",
            "limit of 163650",
            "at most 50 frames fit",
            "frames/s or lower",
        ],
    );
    assert!(!o.exists());
}
