//! Temporal segments from the command line (issue 20): `--segment-frames`, random access into a
//! segment, `inspect` and `eval` of a segmented stream, and a PC2 input read a segment at a time.

use crate::common::{json, ok, run};
use std::fmt::Write as _;
use std::path::Path;

/// A 5×5 grid sheet waving for `frames` frames: an OBJ base and a PC2 cache beside it.
fn write_pc2_sheet(dir: &Path, frames: usize) -> String {
    std::fs::create_dir_all(dir).unwrap_or_else(|e| panic!("{e}"));
    let position = |v: usize, f: usize| {
        let (x, y) = ((v % 5) as f32, (v / 5) as f32);
        [x, y, 0.3 * (0.4 * f as f32 + x).sin() * y]
    };
    let mut obj = String::new();
    for v in 0..25 {
        let [x, y, z] = position(v, 0);
        let _ = writeln!(obj, "v {x} {y} {z}");
    }
    for i in 0..4 {
        for j in 0..4 {
            let v = i * 5 + j + 1;
            let _ = writeln!(obj, "f {} {} {}", v, v + 1, v + 5);
            let _ = writeln!(obj, "f {} {} {}", v + 1, v + 6, v + 5);
        }
    }
    std::fs::write(dir.join("sheet.obj"), obj).unwrap_or_else(|e| panic!("{e}"));
    let mut pc2 = b"POINTCACHE2\0".to_vec();
    for word in [
        1i32.to_le_bytes(),
        25i32.to_le_bytes(),
        0f32.to_le_bytes(),
        1f32.to_le_bytes(),
    ] {
        pc2.extend_from_slice(&word);
    }
    pc2.extend_from_slice(&(frames as i32).to_le_bytes());
    for f in 0..frames {
        for v in 0..25 {
            for c in position(v, f) {
                pc2.extend_from_slice(&c.to_le_bytes());
            }
        }
    }
    let path = dir.join("sheet.pc2");
    std::fs::write(&path, pc2).unwrap_or_else(|e| panic!("{e}"));
    path.to_string_lossy().into_owned()
}

#[test]
fn a_segmented_stream_round_trips_through_every_command() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let input = write_pc2_sheet(dir.path(), 20);
    let stream = dir.path().join("s.mcgv");
    let stream = stream.to_str().unwrap_or_default();
    let out = run(&[
        "encode",
        &input,
        "-o",
        stream,
        "--clusters",
        "2",
        "--segment-frames",
        "8",
    ]);
    let report = ok(&out);
    assert!(report.contains("segments: 3"), "{report}");
    let inspect = json(&run(&["inspect", stream, "--json"]));
    assert_eq!(inspect["segments"], 3, "{inspect}");
    assert_eq!(inspect["frames"], 20, "{inspect}");
    // All frames as OBJ files, then one frame of the last segment alone: the same file.
    let all = dir.path().join("all");
    ok(&run(&[
        "decode",
        stream,
        "-o",
        &format!("{}/", all.display()),
        "--quiet",
    ]));
    let one = dir.path().join("one");
    let one_dir = format!("{}/", one.display());
    ok(&run(&[
        "decode", stream, "-o", &one_dir, "--frame", "17", "--quiet",
    ]));
    let read = |p: &Path| std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        read(&all.join("frame_0017.obj")),
        read(&one.join("frame_0017.obj"))
    );
    assert_eq!(std::fs::read_dir(&all).map(|d| d.count()).unwrap_or(0), 20);
    let measures = json(&run(&["eval", &input, stream, "--json"]));
    let rmse = measures["vertex_rmse"].as_f64().unwrap_or(1.0);
    assert!(rmse < 2e-3, "{measures}");
    assert_eq!(measures["frames"], 20);
    // Decoded to a PC2 cache a segment at a time: the same animation eval measured.
    let pc2 = dir.path().join("decoded.pc2");
    ok(&run(&[
        "decode",
        stream,
        "-o",
        pc2.to_str().unwrap_or_default(),
        "--quiet",
    ]));
    assert!(pc2.with_extension("obj").is_file());
    let again = json(&run(&[
        "eval",
        &input,
        pc2.to_str().unwrap_or_default(),
        "--json",
    ]));
    assert_eq!(again["vertex_rmse"], measures["vertex_rmse"], "{again}");
    // One segment for the whole clip: no segment line, a version-3 stream.
    let whole = dir.path().join("w.mcgv");
    let whole = whole.to_str().unwrap_or_default();
    let out = run(&[
        "encode",
        &input,
        "-o",
        whole,
        "--clusters",
        "2",
        "--segment-frames",
        "0",
    ]);
    assert!(!ok(&out).contains("segments:"));
    assert_eq!(json(&run(&["inspect", whole, "--json"]))["segments"], 1);
}
