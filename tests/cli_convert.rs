//! `mcgv-video convert` through the real binary: the converted animation is the input, exactly.

use std::process::Command;

fn run(args: &[&str]) -> std::process::Output {
    let out = Command::new(env!("CARGO_BIN_EXE_mcgv-video"))
        .args(args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn eval_json(original: &str, other: &str) -> serde_json::Value {
    let out = run(&["eval", "--json", "--quiet", original, other]);
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn glb_to_pc2_and_obj_folder_is_lossless() {
    let input = format!("{}/media/RiggedSimple.glb", env!("CARGO_MANIFEST_DIR"));
    let dir = tempfile::tempdir().unwrap();
    let pc2 = dir.path().join("rs.pc2");
    run(&["convert", "--quiet", &input, "-o", pc2.to_str().unwrap()]);
    assert!(
        dir.path().join("rs.obj").is_file(),
        "base OBJ beside the PC2"
    );
    let v = eval_json(&input, pc2.to_str().unwrap());
    assert_eq!(v["frames"], 49);
    assert_eq!(v["vertex_rmse"].as_f64().unwrap(), 0.0, "{v}");
    let objs = dir.path().join("objs");
    run(&["convert", "--quiet", &input, "-o", objs.to_str().unwrap()]);
    let v = eval_json(&input, objs.to_str().unwrap());
    assert_eq!(v["vertex_rmse"].as_f64().unwrap(), 0.0, "{v}");
}
