//! `encode --segmentation decimation` through the binary: the report, the stream, `inspect`, and
//! the options that do not belong together; `--clusters K` alone is k-means with K.

use crate::common::{grey, json, media_path, ok, run};

#[test]
fn decimation_reports_k_and_time_and_inspect_uses_the_streams_clusters() {
    let dir = tempfile::tempdir().expect("temporary folder");
    let stream = dir.path().join("s.mcgv");
    let s = stream.to_str().expect("utf-8 path");
    let sample = media_path("RiggedSimple.glb");
    let enc = json(&run(&[
        "encode",
        "--codec",
        "jpeg",
        &sample,
        "-o",
        s,
        "--quiet",
        "--json",
        "--padding",
        "cg",
        "--segmentation",
        "decimation",
        "--e0",
        "0.003",
    ]));
    let seg = &enc["segmentation"];
    assert_eq!(seg["method"], "decimation", "{enc}");
    let k = seg["clusters"].as_u64().expect("clusters");
    assert_eq!(enc["header"]["clusters"].as_u64(), Some(k));
    assert!(k >= seg["components"].as_u64().expect("components"));
    assert!(seg["seconds"].as_f64().expect("seconds") >= 0.0);
    assert!(seg["error"].as_f64().expect("error") <= 0.003);
    let stages = enc["stage_seconds"].as_array().expect("stages");
    // "segmentation", or "segmentation (decimation)" beside the automatic predictor's trials.
    let named =
        |s: &serde_json::Value| s[0].as_str().is_some_and(|n| n.starts_with("segmentation"));
    assert!(stages.iter().any(named), "{enc}");

    let info = json(&run(&["inspect", s, "--json"]));
    assert_eq!(info["clusters"].as_u64(), Some(k));

    // inspect re-runs the analysis with the stream's own partition: the padded images it derives
    // are what was coded, so they match the decoded ones up to JPEG loss (a different partition
    // would give a different atlas and images nothing alike: 49.5 levels apart when inspect re-ran
    // k-means).
    let png = dir.path().join("png");
    let p = png.to_str().expect("utf-8 path");
    ok(&run(&["inspect", s, "--png", p, "--original", &sample]));
    let padded = grey(&png.join("frame_0000_padded.png"));
    let decoded = grey(&png.join("frame_0000_decoded.png"));
    assert_eq!(padded.len(), decoded.len());
    let mean = padded
        .iter()
        .zip(&decoded)
        .map(|(&a, &b)| (a as f64 - b as f64).abs())
        .sum::<f64>()
        / padded.len() as f64;
    // 3.2 levels measured on RiggedSimple's 80x80 automatic lattice at the default quality.
    assert!(
        mean < 8.0,
        "padded vs decoded differ by {mean} levels on average"
    );
}

#[test]
fn options_of_the_other_segmentation_are_refused() {
    let dir = tempfile::tempdir().expect("temporary folder");
    let out = dir.path().join("s.mcgv");
    let o = out.to_str().expect("utf-8 path");
    let sample = media_path("RiggedSimple.glb");
    for (args, needle) in [
        (
            vec!["--segmentation", "decimation", "--clusters", "5"],
            "--clusters",
        ),
        (vec!["--segmentation", "kmeans", "--e0", "0.01"], "--e0"),
        (vec!["--segmentation", "decimation", "--e0", "0"], "--e0"),
        (vec!["--segmentation", "decimation", "--e0=-1"], "--e0"),
    ] {
        let mut all = vec![
            "encode",
            "--codec",
            "jpeg",
            sample.as_str(),
            "-o",
            o,
            "--quiet",
        ];
        all.extend(args.iter().copied());
        let res = run(&all);
        assert_eq!(res.status.code(), Some(2), "{all:?} should fail");
        let err = String::from_utf8_lossy(&res.stderr);
        assert!(err.contains(needle), "{all:?}: {err}");
        assert!(!out.exists(), "{all:?} left a file");
    }
}

#[test]
fn clusters_alone_means_k_means_with_that_k() {
    let dir = tempfile::tempdir().expect("temporary folder");
    let out = dir.path().join("s.mcgv");
    let o = out.to_str().expect("utf-8 path");
    let sample = media_path("RiggedSimple.glb");
    let encode = |extra: &[&str]| {
        let base = ["encode", "--codec", "jpeg", &sample, "-o", o, "--quiet"];
        json(&run(&[&base[..], &["--json", "--force"], extra].concat()))
    };
    // The automatic choice compares k-means with decimation, whose K is its own.
    let auto = encode(&[]);
    let tried: Vec<&str> = auto["choice"]["candidates"]
        .as_array()
        .expect("candidates")
        .iter()
        .filter_map(|c| c["segmentation"].as_str())
        .collect();
    assert!(tried.contains(&"decimation"), "{auto}");
    // --clusters K alone: every candidate (the predictors) is k-means, and the stream has K.
    let named = encode(&["--clusters", "3"]);
    assert_eq!(named["segmentation"]["method"], "kmeans", "{named}");
    assert_eq!(named["header"]["clusters"], 3, "{named}");
    for c in named["choice"]["candidates"]
        .as_array()
        .into_iter()
        .flatten()
    {
        assert_eq!(c["segmentation"], "kmeans", "{named}");
    }
    // Naming --e0 as well names both candidates: the automatic choice between them stays.
    let both = encode(&["--clusters", "3", "--e0", "0.004"]);
    assert!(both["choice"]["candidates"].as_array().is_some(), "{both}");
}

/// A grid of 4 × 4 vertices moving over 6 frames, one vertex of frame 3 at `far`.
fn grid_with_a_far_vertex(dir: &std::path::Path, far: &str) {
    std::fs::create_dir_all(dir).expect("folder");
    for f in 0..6 {
        let mut lines: Vec<String> = (0..16)
            .map(|i| format!("v {} {} {}", i % 4, i / 4, 0.05 * f as f64 * (i % 4) as f64))
            .collect();
        if f == 3 {
            lines[0] = format!("v {far} 0 0");
        }
        for a in (1..=11).filter(|a| a % 4 != 0) {
            lines.push(format!(
                "f {a} {} {}\nf {a} {} {}",
                a + 1,
                a + 5,
                a + 5,
                a + 4
            ));
        }
        std::fs::write(
            dir.join(format!("frame_{f:03}.obj")),
            lines.join("\n") + "\n",
        )
        .expect("frame");
    }
}

#[test]
fn a_huge_coordinate_is_a_clear_error_not_a_panic_in_kmeans() {
    let dir = tempfile::tempdir().expect("temporary folder");
    let frames = dir.path().join("frames");
    grid_with_a_far_vertex(&frames, "1e30");
    let out = dir.path().join("s.mcgv");
    let run_on = |codec: &str| {
        run(&[
            "encode",
            frames.to_str().expect("utf-8 path"),
            "-o",
            out.to_str().expect("utf-8 path"),
            "--quiet",
            "--codec",
            codec,
            "--segmentation",
            "kmeans",
        ])
    };
    for codec in ["tdct", "jpeg"] {
        let failed = run_on(codec);
        let err = String::from_utf8_lossy(&failed.stderr);
        assert_eq!(failed.status.code(), Some(1), "{err}");
        assert!(
            err.contains("frame 3, vertex 0") && !err.contains("panicked"),
            "{err}"
        );
    }
    assert!(!out.exists());
}

/// The help promised "k-means with exactly K", but clusters too small for an affine map merge
/// and emptied ones vanish (RiggedSimple asked for 10 keeps 8): it says at most K, often fewer.
#[test]
fn clusters_help_says_at_most_k_are_kept() {
    let help = ok(&run(&["encode", "--help"]));
    let clusters = help
        .split("--clusters <CLUSTERS>")
        .nth(1)
        .and_then(|h| h.split("\n      --").next())
        .expect("--clusters in the help");
    assert!(!clusters.contains("exactly"), "{clusters}");
    assert!(
        clusters.contains("At most K are kept, often fewer"),
        "{clusters}"
    );
}
