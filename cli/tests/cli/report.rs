//! The `encode` report states what the user got: the error of the file written (as `eval`
//! measures it) and sizes that are the file's.

use crate::common::{json, media_path, ok, run};

#[test]
fn the_encode_report_gives_the_error_and_size_of_the_file_written() {
    let dir = tempfile::tempdir().expect("temporary folder");
    let stream = dir.path().join("s.mcgv");
    let s = stream.to_str().expect("utf-8 path");
    let sample = media_path("RiggedSimple.glb");
    // --reorder: the file decodes in its own vertex order, which the measure must undo.
    let base = ["encode", "--codec", "jpeg", &sample, "-o", s, "--reorder"];
    let enc = json(&run(&[&base[..], &["--json", "-q"]].concat()));
    let file = std::fs::metadata(&stream).expect("stream written").len();
    assert_eq!(enc["bytes"].as_u64(), Some(file), "{enc}");
    let achieved = &enc["achieved"];
    let rmse = achieved["vertex_rmse"].as_f64().expect("vertex_rmse");
    let max = achieved["max_error"].as_f64().expect("max_error");
    let eval = json(&run(&["eval", &sample, s, "--json"]));
    let want = eval["vertex_rmse"].as_f64().expect("eval's vertex_rmse");
    assert!(
        (rmse - want).abs() <= 1e-9 * want,
        "{rmse} vs eval's {want}"
    );
    assert!(max >= rmse && max > 0.0, "{achieved}");

    let text = ok(&run(&[&base[..], &["--force"]].concat()));
    let line = format!("error: vertex RMSE {:.4} ×10⁻⁴", want * 1e4);
    assert!(text.contains(&line), "{text}");
    // The automatic choice's sizes are its trials' (12 of 49 frames here): the file's is said.
    if let Some(auto) = text.lines().find(|l| l.starts_with("auto: ")) {
        let size = format!("{file} bytes");
        assert!(
            auto.contains(&size) || !text.contains("estimated"),
            "{text}"
        );
    }
}
