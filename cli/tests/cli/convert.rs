//! `mcgv-video convert` through the real binary: the converted animation is the input, exactly.

use crate::common::{json, media_path, ok, run};

fn eval_json(original: &str, other: &str) -> serde_json::Value {
    json(&run(&["eval", "--json", "--quiet", original, other]))
}

#[test]
fn glb_to_pc2_and_obj_folder_is_lossless() {
    let input = media_path("RiggedSimple.glb");
    let dir = tempfile::tempdir().unwrap();
    let pc2 = dir.path().join("rs.pc2");
    ok(&run(&[
        "convert",
        "--quiet",
        &input,
        "-o",
        pc2.to_str().unwrap(),
    ]));
    assert!(
        dir.path().join("rs.obj").is_file(),
        "base OBJ beside the PC2"
    );
    let v = eval_json(&input, pc2.to_str().unwrap());
    assert_eq!(v["frames"], 49);
    assert_eq!(v["vertex_rmse"].as_f64().unwrap(), 0.0, "{v}");
    let objs = dir.path().join("objs");
    ok(&run(&[
        "convert",
        "--quiet",
        &input,
        "-o",
        objs.to_str().unwrap(),
    ]));
    let v = eval_json(&input, objs.to_str().unwrap());
    assert_eq!(v["vertex_rmse"].as_f64().unwrap(), 0.0, "{v}");
}
