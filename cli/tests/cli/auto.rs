//! `encode --predictor auto --segmentation auto` through the binary: the choice in `--json` and
//! in the text report, the stream's predictor in `inspect`.

use crate::common::{json, media_path, ok, run};

#[test]
fn auto_reports_its_candidates_and_keeps_the_smallest() {
    let dir = tempfile::tempdir().expect("temporary folder");
    let stream = dir.path().join("s.mcgv");
    let s = stream.to_str().expect("utf-8 path");
    let sample = media_path("RiggedSimple.glb");
    // --force: every run below writes the same file.
    let base = ["encode", sample.as_str(), "-o", s, "--force", "--quiet"];
    // The first frame at 12 bits: the size of the kept model's stream is then a candidate's.
    let auto = [
        "--predictor",
        "auto",
        "--segmentation",
        "auto",
        "--first-frame-bits",
        "12",
    ];
    let enc = json(&run(
        &[&base[..], &auto, &["--json", "--e0", "0.004"]].concat()
    ));
    let choice = &enc["choice"];
    let candidates = choice["candidates"].as_array().expect("candidates");
    // tdct's k-means at K and 1.5 K, decimation, each with both predictors; 2 K only when 1.5 K
    // beat K, which on this two-bone figure it does not.
    assert_eq!(candidates.len(), 6, "{enc}");
    let reason = choice["reason"].as_str().unwrap_or_default();
    assert!(
        reason.contains("K = 40 not tried: K = 30 did not beat K = 20"),
        "{enc}"
    );
    let smallest = candidates
        .iter()
        .min_by_key(|c| c["bytes"].as_u64().expect("bytes"))
        .expect("a candidate");
    // tdct codes every candidate whole: the kept one's size is the stream's.
    assert_eq!(smallest["bytes"], enc["bytes"], "{enc}");
    let chosen = format!(
        "{}+{}",
        smallest["predictor"].as_str().expect("predictor"),
        smallest["segmentation"].as_str().expect("segmentation")
    );
    assert_eq!(choice["chosen"], chosen.as_str(), "{enc}");
    assert!(choice["reason"].as_str().is_some_and(|r| !r.is_empty()));
    assert_eq!(enc["header"]["predictor"], smallest["predictor"]);
    assert_eq!(enc["segmentation"]["method"], smallest["segmentation"]);
    let info = json(&run(&["inspect", s, "--json"]));
    assert_eq!(info["predictor"], smallest["predictor"]);

    // auto is the default; the text report says what was kept; fixed flags choose nothing.
    let default = json(&run(&[&base[..], &["--json", "--e0", "0.004"]].concat()));
    assert_eq!(default["choice"]["chosen"], choice["chosen"], "{default}");
    // With the first frame's precision open too, the stream is the smallest of its trials.
    let trials = default["first_frame_trials"].as_array().expect("trials");
    assert_eq!(trials[0]["bytes"], enc["bytes"], "{default}");
    // A precision coded in full is compared by its bytes; one its estimate ruled out lists that
    // estimate (`estimated`), which was weighed against the kept one's estimate, not its bytes,
    // and ends the trials.
    let coded = |t: &&serde_json::Value| t["estimated"] == false;
    let least = trials
        .iter()
        .filter(coded)
        .filter_map(|t| t["bytes"].as_u64())
        .min();
    assert_eq!(default["bytes"].as_u64(), least, "{default}");
    let ruled_out = trials.iter().filter(|t| t["estimated"] == true).count();
    assert!(ruled_out <= 1, "{default}");
    assert!(ruled_out == 0 || trials.last().is_some_and(|t| t["estimated"] == true));
    let text = ok(&run(
        &[&base[..5], &auto[..4], &["--clusters", "5"]].concat()
    ));
    assert!(text.contains("auto: kept"), "{text}");
    assert!(text.contains("first frame: kept"), "{text}");
    let fixed = [
        "--predictor",
        "affine",
        "--segmentation",
        "kmeans",
        "--json",
    ];
    let fixed = json(&run(&[&base[..], &fixed].concat()));
    assert!(fixed["choice"].is_null(), "{fixed}");
}

#[test]
fn auto_flags_are_checked() {
    let dir = tempfile::tempdir().expect("temporary folder");
    let out = dir.path().join("s.mcgv");
    let o = out.to_str().expect("utf-8 path");
    let sample = media_path("RiggedSimple.glb");
    for (flag, value) in [("--predictor", "best"), ("--segmentation", "guess")] {
        let res = run(&["encode", &sample, "-o", o, "--quiet", flag, value]);
        assert_eq!(res.status.code(), Some(2), "{flag} {value}");
        assert!(String::from_utf8_lossy(&res.stderr).contains("auto"));
    }
    let res = run(&[
        "encode",
        &sample,
        "-o",
        o,
        "--quiet",
        "--segmentation",
        "auto",
        "--e0",
        "0",
    ]);
    assert_eq!(res.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&res.stderr).contains("--e0"));
    assert!(!out.exists());
}
