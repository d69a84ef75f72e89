//! `encode --target-size/--target-bpvf/--target-error/--target-max-error` through the binary: the
//! stream within the budget, the quality found and the encodes made in `--json` and the text
//! report, the quality found reproducing the stream, and the flags' usage errors.

use crate::common::{json, media_path, ok, run};

#[test]
fn target_size_reports_the_quality_found_which_codes_the_same_stream() {
    let dir = tempfile::tempdir().expect("temporary folder");
    let (a, b) = (dir.path().join("a.mcgv"), dir.path().join("b.mcgv"));
    let (a, b) = (a.to_str().expect("utf-8"), b.to_str().expect("utf-8"));
    let sample = media_path("RiggedFigure.glb");
    let fixed = ["--predictor", "affine", "--segmentation", "kmeans"];
    let base = [
        "encode",
        sample.as_str(),
        "--quiet",
        "--first-frame-bits",
        "12",
    ];
    let enc = json(&run(&[
        &base[..],
        &fixed,
        &["-o", a, "--json", "--target-size", "4000"],
    ]
    .concat()));
    let budget = &enc["budget"];
    let bytes = enc["bytes"].as_u64().expect("bytes");
    assert!((3920..=4000).contains(&bytes), "{enc}");
    assert_eq!(std::fs::metadata(a).expect("written").len(), bytes);
    let encodes = budget["encodes"].as_u64().expect("encodes");
    assert!(encodes >= 1 && encodes as usize == budget["trials"].as_array().expect("trials").len());
    let quality = budget["quality"].as_f64().expect("quality");
    assert!(
        budget["within_tolerance"].as_bool().expect("a flag"),
        "{enc}"
    );
    // The quality found, given back, codes the same stream.
    let q = quality.to_string();
    ok(&run(&[
        &base[..],
        &fixed,
        &["-o", b, "--quality", q.as_str()],
    ]
    .concat()));
    assert_eq!(std::fs::read(a).ok(), std::fs::read(b).ok(), "quality {q}");

    // The text report says the quality and the encodes (over the first stream: --force).
    let text = ok(&run(&[
        "encode",
        sample.as_str(),
        "-o",
        a,
        "--force",
        "--target-error",
        "4e-4",
    ]));
    assert!(
        text.contains("budget: vertex RMSE") && text.contains("encodes"),
        "{text}"
    );
}

#[test]
fn budget_flags_exclude_each_other_and_the_step() {
    let sample = media_path("RiggedSimple.glb");
    let base = ["encode", sample.as_str(), "-o", "-", "--quiet"];
    for extra in [
        &["--target-size", "1000", "--target-error", "1e-3"][..],
        &["--target-bpvf", "2", "--step", "0.001"],
        &["--target-error", "-1"],
        &["--quality", "100.5"],
    ] {
        let out = run(&[&base[..], extra].concat());
        assert_eq!(out.status.code(), Some(2), "{extra:?}");
    }
}
