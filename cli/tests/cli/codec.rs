//! The encode / decode / inspect / eval commands through the binary, as a user runs them.

use crate::common::{json, media_path, ok, run};
use std::path::Path;

#[test]
fn encode_inspect_decode_eval_a_sample() {
    let dir = tempfile::tempdir().unwrap();
    let stream = dir.path().join("fig.mcgv");
    let s = stream.to_str().unwrap();
    let sample = media_path("RiggedFigure.glb");
    let enc = json(&run(&[
        "encode", &sample, "-o", s, "--codec", "mpeg4", "--quiet", "--json",
    ]));
    assert_eq!(enc["vertices"], 370);

    let info = json(&run(&["inspect", s, "--json"]));
    for key in [
        "vertices",
        "frames",
        "codec",
        "clusters",
        "charts",
        "lattice",
        "packing_efficiency",
        "bpvf",
        "parts",
    ] {
        assert!(
            info.get(key).is_some(),
            "inspect --json lacks {key}: {info}"
        );
    }
    assert_eq!(info["codec"], "mpeg4");
    let bits: u64 = info["parts"]
        .as_object()
        .unwrap()
        .values()
        .map(|v| v.as_u64().unwrap())
        .sum();
    assert_eq!(
        bits,
        8 * std::fs::metadata(&stream).unwrap().len(),
        "parts add up to the file"
    );

    let frames = dir.path().join("frames");
    ok(&run(&[
        "decode",
        s,
        "-o",
        frames.to_str().unwrap(),
        "--quiet",
    ]));
    assert!(frames.join("frame_0000.obj").exists() && frames.join("frame_0037.obj").exists());
    let one = dir.path().join("one");
    ok(&run(&[
        "decode",
        s,
        "-o",
        one.to_str().unwrap(),
        "--frame",
        "5",
        "--quiet",
    ]));
    assert_eq!(
        std::fs::read(one.join("frame_0005.obj")).unwrap(),
        std::fs::read(frames.join("frame_0005.obj")).unwrap(),
        "a frame decoded alone equals the same frame of the full decode"
    );

    let m = json(&run(&["eval", &sample, s, "--json", "--quiet"]));
    assert!(m["rmse"].as_f64().unwrap() < 1e-3, "{m}");
    assert!((m["bpvf"].as_f64().unwrap() - info["bpvf"].as_f64().unwrap()).abs() < 1e-9);
    let same = json(&run(&["eval", &sample, frames.to_str().unwrap(), "--json"]));
    assert!(
        (same["rmse"].as_f64().unwrap() - m["rmse"].as_f64().unwrap()).abs() < 1e-6,
        "{same} vs {m}"
    );
}

#[test]
fn inspect_writes_pngs_a_user_can_open() {
    let dir = tempfile::tempdir().unwrap();
    let stream = dir.path().join("s.mcgv");
    let s = stream.to_str().unwrap();
    let sample = media_path("RiggedSimple.glb");
    ok(&run(&[
        "encode",
        "--codec",
        "jpeg",
        &sample,
        "-o",
        s,
        "--quiet",
        "--padding",
        "cg",
    ]));
    let info = json(&run(&["inspect", s, "--json"]));
    let lattice = [0, 1].map(|i| info["lattice"][i].as_u64().unwrap() as u32);
    // The automatic lattice of a 160-vertex mesh is far below the papers' 256x256.
    assert!(lattice[0] < 256 && lattice[0] >= 32, "{info}");
    let png = dir.path().join("png");
    let p = png.to_str().unwrap();
    ok(&run(&[
        "inspect",
        s,
        "--png",
        p,
        "--frames",
        "0,3",
        "--original",
        &sample,
    ]));
    for name in [
        "atlas.png",
        "segmentation.png",
        "frame_0003_raw.png",
        "frame_0003_padded.png",
        "frame_0003_decoded.png",
    ] {
        let img = image::open(png.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(
            img.width() >= lattice[0] && img.height() >= lattice[1],
            "{name} is {}x{}, the lattice {lattice:?}",
            img.width(),
            img.height()
        );
    }
}

#[test]
fn bad_input_and_outputs_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // Not a stream.
    let junk = d.join("junk.mcgv");
    std::fs::write(&junk, b"this is not a stream").unwrap();
    let out = run(&[
        "decode",
        junk.to_str().unwrap(),
        "-o",
        d.join("x").to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("not a .mcgv file"));
    // A frame that does not exist.
    let stream = d.join("s.mcgv");
    let s = stream.to_str().unwrap();
    ok(&run(&[
        "encode",
        "--codec",
        "jpeg",
        &media_path("RiggedSimple.glb"),
        "-o",
        s,
        "--quiet",
        "--padding",
        "cg",
    ]));
    let out = run(&[
        "decode",
        s,
        "-o",
        d.join("y").to_str().unwrap(),
        "--frame",
        "9999",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--frame 9999"));
    // Overwriting the input is refused and the input is untouched.
    let copy = d.join("in.glb");
    std::fs::copy(media_path("RiggedSimple.glb"), &copy).unwrap();
    let before = std::fs::read(&copy).unwrap();
    let out = run(&[
        "encode",
        "--codec",
        "jpeg",
        copy.to_str().unwrap(),
        "-o",
        copy.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("refusing to overwrite"));
    assert_eq!(std::fs::read(&copy).unwrap(), before);
    // An unwritable output (its "folder" is a file) leaves nothing behind.
    std::fs::write(d.join("afile"), b"x").unwrap();
    let missing = d.join("afile/out.mcgv");
    let out = run(&[
        "encode",
        "--codec",
        "jpeg",
        &media_path("RiggedSimple.glb"),
        "-o",
        missing.to_str().unwrap(),
        "--quiet",
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(!Path::new(&missing).exists());
    // Nonsense options.
    let out = run(&[
        "encode",
        "--codec",
        "jpeg",
        &media_path("RiggedSimple.glb"),
        "-o",
        s,
        "--lattice",
        "100x100",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("multiples of 16"));
    let out = run(&[
        "encode",
        "--codec",
        "jpeg",
        &media_path("RiggedSimple.glb"),
        "-o",
        s,
        "--padding",
        "magic",
    ]);
    // A malformed command line: clap lists the methods.
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("possible values: snap"));
}

/// `--codec tdct` through the binary: encode, inspect (band table, no PNGs), decode, eval, a
/// `--bands` preview, and a truncated stream that decodes with a warning on stderr.
#[test]
fn tdct_encode_inspect_decode_eval_and_truncation() {
    let dir = tempfile::tempdir().unwrap();
    let stream = dir.path().join("fig.mcgv");
    let s = stream.to_str().unwrap();
    let sample = media_path("RiggedFigure.glb");
    let enc = json(&run(&[
        "encode",
        &sample,
        "-o",
        s,
        "--codec",
        "tdct",
        "--quality",
        "90",
        "--quiet",
        "--json",
    ]));
    assert_eq!(enc["codec"], "tdct");
    assert_eq!(enc["charts"], 0);

    let info = json(&run(&["inspect", s, "--json"]));
    assert_eq!(info["codec"], "tdct");
    let bands = info["band_bytes"].as_array().expect("band byte lengths");
    assert_eq!(bands.len(), 38);
    assert!(info["parts"]["temporal DCT coefficients"].as_u64().unwrap() > 0);
    let text = ok(&run(&["inspect", s]));
    assert!(
        text.contains("temporal DCT: 38 bands") && text.contains("% of the bytes"),
        "{text}"
    );
    // The parts' table is aligned: each row's bytes end where the heading's do, however long
    // the part's name ("temporal DCT coefficients").
    let rows: Vec<&str> = (text.lines())
        .skip_while(|l| !l.starts_with("part "))
        .take_while(|l| !l.starts_with("temporal DCT:"))
        .collect();
    assert!(rows.len() > 3, "{text}");
    let end = rows[0].find("bytes").map_or(0, |i| i + "bytes".len());
    for row in &rows[1..] {
        let (last, next) = (row.as_bytes().get(end - 1), row.as_bytes().get(end));
        assert!(
            last.is_some_and(u8::is_ascii_digit) && next == Some(&b' '),
            "{row:?} in {text}"
        );
    }
    let png = run(&[
        "inspect",
        s,
        "--png",
        dir.path().join("png").to_str().unwrap(),
    ]);
    assert!(!png.status.success());
    assert!(String::from_utf8_lossy(&png.stderr)
        .contains("applies to streams of geometry images: a tdct stream has none"));

    let frames = dir.path().join("frames");
    ok(&run(&[
        "decode",
        s,
        "-o",
        frames.to_str().unwrap(),
        "--quiet",
    ]));
    assert!(frames.join("frame_0037.obj").exists());
    let full = json(&run(&["eval", &sample, s, "--json", "--quiet"]));
    let preview = json(&run(&[
        "eval", &sample, s, "--json", "--quiet", "--bands", "1",
    ]));
    assert!(preview["rmse"].as_f64().unwrap() > full["rmse"].as_f64().unwrap());

    // Cut inside the coefficients part: decodes, coarser, with a warning on stderr.
    let bytes = std::fs::read(&stream).unwrap();
    let coefficients = bands.iter().map(|b| b.as_u64().unwrap()).sum::<u64>() as usize;
    let cut = dir.path().join("cut.mcgv");
    std::fs::write(&cut, &bytes[..bytes.len() - coefficients / 2]).unwrap();
    let out = run(&[
        "decode",
        cut.to_str().unwrap(),
        "-o",
        dir.path().join("cut.pc2").to_str().unwrap(),
        "--quiet",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("stream truncated: decoded") && stderr.contains("of 38 temporal-DCT bands"),
        "{stderr}"
    );
    let out = run(&["eval", &sample, cut.to_str().unwrap(), "--json", "--quiet"]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("stream truncated"));
    let coarse = json(&out);
    assert!(coarse["rmse"].as_f64().unwrap() > full["rmse"].as_f64().unwrap());
    // A damaged band where the cut was: the bands before it decode, as with the cut, with a warning.
    let mut damaged = bytes.clone();
    damaged[bytes.len() - coefficients / 2] ^= 0x10;
    let bad = dir.path().join("bad.mcgv");
    std::fs::write(&bad, &damaged).unwrap();
    let out = run(&["eval", &sample, bad.to_str().unwrap(), "--json", "--quiet"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("is damaged: decoded the bands before it"),
        "{stderr}"
    );
    assert!(json(&out)["rmse"].as_f64().unwrap() > full["rmse"].as_f64().unwrap());
    // A preview's bpvf counts the bands it read only.
    assert!(preview["bpvf"].as_f64().unwrap() < full["bpvf"].as_f64().unwrap());

    // --bands belongs to tdct; --range-floor, retired with stream version 2, is gone: a usage error.
    let jpeg = dir.path().join("fig_jpeg.mcgv");
    let out = run(&[
        "encode",
        "--codec",
        "jpeg",
        &sample,
        "-o",
        jpeg.to_str().unwrap(),
        "--range-floor",
        "0.5",
        "--quiet",
    ]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("unexpected argument '--range-floor'"),
        "{stderr}"
    );
    ok(&run(&[
        "encode",
        "--codec",
        "jpeg",
        &sample,
        "-o",
        jpeg.to_str().unwrap(),
        "--padding",
        "cg",
        "--quiet",
    ]));
    let out = run(&[
        "decode",
        jpeg.to_str().unwrap(),
        "-o",
        frames.to_str().unwrap(),
        "--bands",
        "2",
    ]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--bands applies to tdct"));
}

/// `--codec hevc` and `--codec av1` with their own flags: --qp, --bit-depth, --gop 1 (all-intra);
/// the header and the set-up carry what decode needs, random access gives the full decode's frame,
/// and the flags are refused for other codecs and out of each codec's range.
#[test]
fn deep_codec_flags_encode_decode_and_random_access() {
    let dir = tempfile::tempdir().unwrap();
    let sample = media_path("RiggedFigure.glb");
    for codec in ["hevc", "av1"] {
        for (name, extra) in [
            ("p.mcgv", vec!["--bit-depth", "12", "--gop", "8"]),
            ("i.mcgv", vec!["--qp", "20", "--gop", "1"]),
        ] {
            let stream = dir.path().join(format!("{codec}-{name}"));
            let s = stream.to_str().unwrap();
            let mut args = vec!["encode", &sample, "-o", s, "--codec", codec, "--quiet"];
            args.extend(extra.iter().copied());
            ok(&run(&args));
            let info = json(&run(&["inspect", s, "--json"]));
            assert_eq!(info["codec"], codec);
            let depth = if name == "p.mcgv" { 12 } else { 10 };
            assert_eq!(info["bit_depth"], depth);
            if name == "i.mcgv" {
                assert_eq!(info["qp"], 20);
                assert_eq!(info["gop"], 1);
            }
            let all = dir.path().join(format!("{codec}-{depth}-all/"));
            let one = dir.path().join(format!("{codec}-{depth}-one/"));
            ok(&run(&["decode", s, "-o", all.to_str().unwrap(), "--quiet"]));
            ok(&run(&[
                "decode",
                s,
                "-o",
                one.to_str().unwrap(),
                "--frame",
                "11",
                "--quiet",
            ]));
            assert_eq!(
                std::fs::read(one.join("frame_0011.obj")).unwrap(),
                std::fs::read(all.join("frame_0011.obj")).unwrap(),
            );
            let m = json(&run(&["eval", &sample, s, "--json", "--quiet"]));
            assert!(m["rmse"].as_f64().unwrap() < 1e-3, "{codec}: {m}");
        }
    }
    // The automatic depth, as the reports say it: HEVC at 12 bits from quality 65.
    let auto = dir.path().join("auto.mcgv");
    let a = auto.to_str().unwrap();
    for (quality, depth) in [("60", 10), ("70", 12)] {
        let args = [
            "encode",
            &sample,
            "-o",
            a,
            "--codec",
            "hevc",
            "--quality",
            quality,
        ];
        let text = run(&[&args[..], &["--force"]].concat());
        ok(&text);
        let said = format!("{depth}-bit pictures");
        assert!(
            String::from_utf8_lossy(&text.stdout).contains(&said),
            "{quality}"
        );
        let report = json(&run(
            &[&args[..], &["--force", "--json", "--quiet"]].concat()
        ));
        assert_eq!(report["picture_depth"], depth, "{quality}");
    }
    let o = dir.path().join("x.mcgv");
    let o = o.to_str().unwrap();
    for extra in [
        vec!["--codec", "mpeg4", "--bit-depth", "10"],
        vec!["--codec", "jpeg", "--qp", "20"],
        vec!["--codec", "hevc", "--qscale", "3"],
        vec!["--codec", "hevc", "--bit-depth", "11"],
        vec!["--codec", "hevc", "--qp", "52"],
        vec!["--codec", "av1", "--qp", "64"],
        vec!["--codec", "av1", "--qscale", "3"],
    ] {
        let mut args = vec!["encode", sample.as_str(), "-o", o];
        args.extend(extra.iter().copied());
        let out = run(&args);
        assert_eq!(out.status.code(), Some(2), "{extra:?}");
        assert!(!Path::new(o).exists());
    }
}
