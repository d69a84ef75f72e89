//! `mcgv-video eval` end to end: the binary on files, its JSON and human output, its errors.

use crate::common::{json, media_path, ok, run};
use std::fmt::Write as _;
use std::path::Path;
use std::process::Output;

fn eval(args: &[&str]) -> Output {
    run(&[&["eval"], args].concat())
}

fn number(v: &serde_json::Value, key: &str) -> f64 {
    v.get(key)
        .and_then(|x| x.as_f64())
        .unwrap_or_else(|| panic!("no number {key} in {v}"))
}

/// The faces of an `n`×`n` grid of vertices numbered row by row from 1, two per square.
fn grid_faces(s: &mut String, n: usize) {
    for i in 0..n - 1 {
        for j in 0..n - 1 {
            let v = i * n + j + 1;
            let _ = writeln!(s, "f {} {} {}", v, v + 1, v + n);
            let _ = writeln!(s, "f {} {} {}", v + 1, v + n + 1, v + n);
        }
    }
}

/// A 6×6 grid sheet in the z = `z` plane, `frames` frames swaying in x, as an OBJ sequence.
fn write_sheet(dir: &Path, frames: usize, z: f32) {
    std::fs::create_dir_all(dir).unwrap_or_else(|e| panic!("{e}"));
    for f in 0..frames {
        let mut s = String::new();
        for v in 0..36 {
            let (x, y) = ((v % 6) as f32, (v / 6) as f32);
            let _ = writeln!(s, "v {} {y} {z}", x + 0.1 * f as f32 * y);
        }
        grid_faces(&mut s, 6);
        std::fs::write(dir.join(format!("frame_{f}.obj")), s).unwrap_or_else(|e| panic!("{e}"));
    }
}

#[test]
fn a_sample_against_itself_has_zero_error() {
    let sample = media_path("RiggedSimple.glb");
    let v = json(&eval(&[&sample, &sample, "--json"]));
    for key in ["rmse", "hausdorff", "vertex_rmse", "kg_error"] {
        assert_eq!(number(&v, key), 0.0, "{key} in {v}");
    }
    assert!(number(&v, "vertices") > 0.0 && number(&v, "frames") > 1.0);
    assert!(v.get("bpvf").is_none(), "no file, so no bpvf: {v}");
}

#[test]
fn a_lifted_copy_is_off_by_the_lift_in_both_outputs() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    write_sheet(&a, 3, 0.0);
    write_sheet(&b, 3, 0.05);
    let (a, b) = (a.to_string_lossy(), b.to_string_lossy());
    let v = json(&eval(&[&a, &b, "--json"]));
    // Frame 0 spans 5 × 5 in x, y: diagonal 5√2; a sheet lifted along its normal is 0.05 away.
    let want = 0.05 / (50f64).sqrt();
    for key in ["rmse", "hausdorff", "vertex_rmse"] {
        let got = number(&v, key);
        assert!(
            (got - want).abs() < 1e-6 * want.max(got),
            "{key}: {got} vs {want}"
        );
    }
    assert_eq!((number(&v, "frames"), number(&v, "vertices")), (3.0, 36.0));
    let text = ok(&eval(&[&a, &b]));
    assert!(
        text.contains(&format!("{:.4} ×10⁻⁴", want * 1e4)) && text.contains("RMSE"),
        "{text}"
    );
}

#[test]
fn a_missing_mcgv_fails_naming_it() {
    let out = eval(&[&media_path("Fox.glb"), "no/such/decoded.mcgv"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("no/such/decoded.mcgv"), "{err}");
}

#[test]
fn a_missing_input_fails_naming_it() {
    let out = eval(&["no/such/animation.glb", &media_path("Fox.glb")]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no/such/animation.glb"));
}

#[test]
fn fast_gives_the_vertex_measures_alone_and_alike() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    write_sheet(&a, 3, 0.0);
    write_sheet(&b, 3, 0.05);
    let (a_s, b_s) = (a.to_string_lossy(), b.to_string_lossy());
    let full = json(&eval(&[&a_s, &b_s, "--json"]));
    let fast = json(&eval(&[&a_s, &b_s, "--json", "--fast"]));
    for key in ["vertex_rmse", "kg_error", "frames", "vertices"] {
        assert_eq!(
            number(&fast, key),
            number(&full, key),
            "{key}: {fast} {full}"
        );
    }
    assert!(
        fast.get("rmse").is_none() && fast.get("hausdorff").is_none(),
        "{fast}"
    );
    let text = ok(&eval(&[&a_s, &b_s, "--fast"]));
    assert!(
        text.contains("not measured (--fast)") && text.contains("vertex RMSE"),
        "{text}"
    );
    // One more vertex in every decoded frame: vertices no longer correspond.
    for f in 0..3 {
        let path = b.join(format!("frame_{f}.obj"));
        let s = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{e}"));
        std::fs::write(&path, format!("v 9 9 9\n{s}")).unwrap_or_else(|e| panic!("{e}"));
    }
    let out = eval(&[&a_s, &b_s, "--fast"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--fast") && err.contains("36"), "{err}");
}

/// A 12×12 sheet over `frames` frames, each vertex pushed off by `jitter` (varying by vertex and
/// frame) as a codec's error would, as an OBJ sequence.
fn write_jittered_sheet(dir: &Path, frames: usize, jitter: f32) {
    std::fs::create_dir_all(dir).unwrap_or_else(|e| panic!("{e}"));
    for f in 0..frames {
        let mut s = String::new();
        for v in 0..144 {
            let (x, y) = ((v % 12) as f32, (v / 12) as f32);
            let off = |k: f32| jitter * (v as f32 * 12.99 + f as f32 * 0.37 + k).sin();
            let z = (0.5 * x + 0.3 * f as f32).sin() * y * 0.2;
            let _ = writeln!(s, "v {} {} {}", x + off(0.0), y + off(1.3), z + off(2.9));
        }
        grid_faces(&mut s, 12);
        std::fs::write(dir.join(format!("frame_{f:03}.obj")), s).unwrap_or_else(|e| panic!("{e}"));
    }
}

#[test]
fn a_long_clip_is_sampled_unless_every_frame_is_asked() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    write_jittered_sheet(&a, 64, 0.0);
    write_jittered_sheet(&b, 64, 0.02);
    let (a, b) = (a.to_string_lossy(), b.to_string_lossy());
    let sampled = json(&eval(&[&a, &b, "--json"]));
    let every = json(&eval(&[&a, &b, "--json", "--every-frame"]));
    assert_eq!(number(&every, "surface_frames"), 64.0, "{every}");
    let measured = number(&sampled, "surface_frames");
    assert!(measured < 64.0, "{sampled}");
    let off = number(&sampled, "rmse") / number(&every, "rmse") - 1.0;
    assert!(off.abs() < 0.01, "{off}: {sampled} {every}");
    for key in ["hausdorff", "vertex_rmse", "kg_error", "frames"] {
        assert_eq!(number(&sampled, key), number(&every, key), "{key}");
    }
    let text = ok(&eval(&[&a, &b]));
    assert!(
        text.contains(&format!(
            "from {measured} of the 64 frames measured in full"
        )),
        "{text}"
    );
    let both = eval(&[&a, &b, "--fast", "--every-frame"]);
    assert!(!both.status.success());
}
