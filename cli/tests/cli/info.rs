//! `mcgv-video info` through the real binary: text, `--json`, and failures.

use crate::common::{media_path, ok, run};

fn info(args: &[&str]) -> std::process::Output {
    run(&[&["info"], args].concat())
}

#[test]
fn json_has_the_agreed_keys() {
    let stdout = ok(&info(&["--json", &media_path("RiggedSimple.glb")]));
    assert_eq!(
        stdout.trim().lines().count(),
        1,
        "one JSON object on one line"
    );
    let v: serde_json::Value = serde_json::from_str(&stdout).expect("one JSON object");
    assert_eq!(v["vertices"], 160);
    assert_eq!(v["faces"], 188);
    assert_eq!(v["frames"], 49);
    assert_eq!(v["components"], 3);
    assert_eq!(v["manifold"], true);
    let diagonal = v["bbox_diagonal"].as_f64().unwrap();
    assert!((9.0..10.0).contains(&diagonal), "{diagonal}");
}

#[test]
fn text_names_every_figure() {
    let text = ok(&info(&["--fps", "12", &media_path("CesiumMan.glb")]));
    for expected in [
        "vertices (V)   3273",
        "frames (F)     24",
        "faces          4672",
        "components",
        "manifold       no",
        "diagonal",
    ] {
        assert!(text.contains(expected), "no `{expected}` in\n{text}");
    }
}

#[test]
fn a_bad_input_fails_with_its_name() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("broken.obj");
    std::fs::write(&bad, "v 0 0 0\nv 1 0 0\nv 0 1 nan\nf 1 2 3\n").unwrap();
    let out = info(&["--json", bad.to_str().unwrap()]);
    assert!(!out.status.success());
    assert!(out.stdout.is_empty());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("broken.obj") && stderr.contains("finite"),
        "{stderr}"
    );
    // A stream where an animation is expected: the commands that read streams are named.
    let stream = dir.path().join("x.mcgv");
    std::fs::write(&stream, b"MCGV").unwrap();
    let out = info(&[stream.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("mcgv-video inspect"), "{stderr}");
}
