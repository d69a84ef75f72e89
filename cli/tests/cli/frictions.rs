//! Issue 21, a command line a user can trust: one test per friction a new user met, each doing what
//! the user did and checking that it now behaves (exit codes, messages, files on disk).

use crate::common::{file_names, json, media_path, ok, run};
use std::path::Path;
use std::process::{Command, Output, Stdio};

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// Exit code and stderr must be as given (the message containing every needle).
fn fails(out: &Output, code: i32, needles: &[&str]) {
    let err = stderr(out);
    assert_eq!(out.status.code(), Some(code), "{err}");
    for n in needles {
        assert!(err.contains(n), "`{n}` not in: {err}");
    }
}

/// A small tdct stream of RiggedSimple in `dir`.
fn stream(dir: &Path, extra: &[&str]) -> String {
    let s = dir.join("s.mcgv").to_str().unwrap().to_string();
    let mut args = vec!["encode", "", "-o", &s, "--quiet"];
    let sample = media_path("RiggedSimple.glb");
    args[1] = &sample;
    args.extend_from_slice(extra);
    ok(&run(&args));
    s
}

#[test]
fn f1_the_default_codec_is_the_smallest() {
    let d = tempfile::tempdir().unwrap();
    let s = stream(d.path(), &[]);
    let info = json(&run(&["inspect", &s, "--json"]));
    assert_eq!(info["codec"], "tdct");
    let jpeg = d.path().join("j.mcgv");
    let sample = media_path("RiggedSimple.glb");
    ok(&run(&[
        "encode",
        &sample,
        "-o",
        jpeg.to_str().unwrap(),
        "--codec",
        "jpeg",
        "--quiet",
    ]));
    let size = |p: &str| std::fs::metadata(p).unwrap().len();
    assert!(size(&s) < size(jpeg.to_str().unwrap()));
}

#[test]
fn f2_outputs_mean_what_their_names_say() {
    let d = tempfile::tempdir().unwrap();
    let s = stream(d.path(), &[]);
    let p = |n: &str| d.path().join(n).to_str().unwrap().to_string();
    // .glb: a glTF file (binary: it starts with the GLB magic), not a folder.
    ok(&run(&["decode", &s, "-o", &p("out.glb"), "--quiet"]));
    let glb = std::fs::read(p("out.glb")).expect("a file, not a folder");
    assert_eq!(&glb[..4], b"glTF");
    let sample = media_path("RiggedSimple.glb");
    ok(&run(&["convert", &sample, "-o", &p("cm.glb"), "--quiet"]));
    assert!(Path::new(&p("cm.glb")).is_file());
    // --frame with .obj: that one file.
    ok(&run(&[
        "decode",
        &s,
        "--frame",
        "3",
        "-o",
        &p("frame3.obj"),
        "-q",
    ]));
    assert!(Path::new(&p("frame3.obj")).is_file());
    // A name of no animation format: the choices.
    fails(
        &run(&["decode", &s, "-o", &p("x.txt")]),
        2,
        &["DIR/", ".pc2"],
    );
    // `-` is stdout for encode: the stream's bytes, no file named `-`.
    let out = run(&["encode", &sample, "-o", "-", "-q"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(out.stdout.starts_with(&std::fs::read(&s).unwrap()[..4]));
    assert!(!Path::new("-").exists());
    fails(&run(&["decode", &s, "-o", "-"]), 2, &["stdout"]);
}

#[test]
fn f3_decoding_into_a_folder_of_old_frames_is_refused_or_leaves_them() {
    let d = tempfile::tempdir().unwrap();
    let s = stream(d.path(), &[]);
    let dir = d.path().join("frames");
    std::fs::create_dir(&dir).unwrap();
    let stale = dir.join("frame_0999.obj");
    std::fs::write(&stale, "v 0 0 0\n").unwrap();
    let o = dir.to_str().unwrap();
    fails(
        &run(&["decode", &s, "-o", o]),
        1,
        &["holds 1 files", "--force"],
    );
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
    let out = run(&["decode", &s, "-o", o, "--force"]);
    ok(&out);
    // --force replaces only what the run writes: the stale frame stays, and the run says so.
    assert!(stale.exists(), "the stale frame was deleted");
    assert!(
        stderr(&out).contains("left 1 other file there"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn f4_a_closed_pipe_ends_quietly() {
    let d = tempfile::tempdir().unwrap();
    let s = stream(d.path(), &[]);
    let sample = media_path("RiggedSimple.glb");
    for args in [
        vec!["inspect", s.as_str()],
        vec!["inspect", s.as_str(), "--json"],
        vec!["info", sample.as_str()],
        vec!["completions", "bash"],
    ] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_mcgv-video"))
            .args(&args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        drop(child.stdout.take()); // the reader goes away at once, like `| true`
        let out = child.wait_with_output().unwrap();
        let code = out.status.code();
        assert!(
            matches!(code, Some(0) | Some(141) | None),
            "{args:?}: {code:?}"
        );
        assert!(
            !stderr(&out).contains("panicked"),
            "{args:?}: {}",
            stderr(&out)
        );
    }
}

#[test]
fn f5_glb_clips_are_listed_and_chosen_aloud() {
    let fox = media_path("Fox.glb");
    let info = json(&run(&["info", &fox, "--json"]));
    let clips = info["clips"].as_array().unwrap();
    let names: Vec<&str> = clips.iter().map(|c| c["name"].as_str().unwrap()).collect();
    assert_eq!(names, ["Survey", "Walk", "Run"]);
    assert!(clips.iter().all(|c| c["frames"].as_u64().unwrap() > 1));
    assert!(ok(&run(&["info", &fox])).contains("`Walk`: 18 frames at 24 fps"));
    let d = tempfile::tempdir().unwrap();
    let o = d.path().join("fox.mcgv");
    let out = run(&["encode", &fox, "-o", o.to_str().unwrap(), "--fps", "4"]);
    assert!(out.status.success());
    assert!(
        stderr(&out).contains("took clip 0 `Survey`"),
        "{}",
        stderr(&out)
    );
    let all = run(&[
        "encode",
        &fox,
        "--clip",
        "all",
        "-o",
        o.to_str().unwrap(),
        "--fps",
        "4",
        "-q",
    ]);
    assert!(all.status.success(), "{}", stderr(&all));
    for clip in ["Survey", "Walk", "Run"] {
        assert!(
            d.path().join(format!("fox-{clip}.mcgv")).is_file(),
            "{clip}"
        );
    }
}

/// `RiggedSimple.glb` with its clip five times over: unnamed, unnamed, `a/b`, `a_b` and `1`.
fn clashing_clips(path: &Path) {
    let glb = std::fs::read(media_path("RiggedSimple.glb")).unwrap();
    let length = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    let mut gltf: serde_json::Value = serde_json::from_slice(&glb[20..20 + length]).unwrap();
    let mut clip = gltf["animations"][0].clone();
    clip.as_object_mut().unwrap().remove("name");
    let clips: Vec<serde_json::Value> = [None, None, Some("a/b"), Some("a_b"), Some("1")]
        .iter()
        .map(|name| {
            let mut c = clip.clone();
            if let Some(name) = name {
                c["name"] = (*name).into();
            }
            c
        })
        .collect();
    gltf["animations"] = clips.into();
    let mut text = serde_json::to_vec(&gltf).unwrap();
    text.resize(text.len().div_ceil(4) * 4, b' ');
    let rest = &glb[20 + length..];
    let mut out = glb[..8].to_vec();
    out.extend(((20 + text.len() + rest.len()) as u32).to_le_bytes());
    out.extend((text.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(text);
    out.extend(rest);
    std::fs::write(path, out).unwrap();
}

#[test]
fn f5_clips_whose_names_clash_get_distinct_files() {
    let d = tempfile::tempdir().unwrap();
    let glb = d.path().join("clips.glb");
    clashing_clips(&glb);
    let o = d.path().join("out").join("r.mcgv");
    let args = ["--clip", "all", "--fps", "4", "-q", "--codec", "jpeg"];
    let all = run(&[
        &["encode", glb.to_str().unwrap(), "-o", o.to_str().unwrap()],
        &args[..],
    ]
    .concat());
    assert!(all.status.success(), "{}", stderr(&all));
    assert_eq!(
        file_names(&d.path().join("out")),
        [
            "r-0.mcgv",
            "r-1-4.mcgv",
            "r-1.mcgv",
            "r-a_b-3.mcgv",
            "r-a_b.mcgv"
        ]
    );
}

#[test]
fn f6_a_decoded_pc2_reads_back() {
    let d = tempfile::tempdir().unwrap();
    let s = stream(d.path(), &[]);
    let pc2 = d.path().join("x.pc2");
    ok(&run(&["decode", &s, "-o", pc2.to_str().unwrap(), "-q"]));
    assert!(d.path().join("x.obj").is_file());
    let info = json(&run(&["info", pc2.to_str().unwrap(), "--json"]));
    assert_eq!(
        info["vertices"],
        json(&run(&["inspect", &s, "--json"]))["vertices"]
    );
}

#[test]
fn f7_eval_of_a_reordered_stream_compares_vertex_with_vertex() {
    let d = tempfile::tempdir().unwrap();
    let sample = media_path("RiggedSimple.glb");
    let s = stream(d.path(), &["--reorder"]);
    let m = json(&run(&["eval", &sample, &s, "--json", "-q"]));
    let (v, rmse) = (
        m["vertex_rmse"].as_f64().unwrap(),
        m["rmse"].as_f64().unwrap(),
    );
    // Before: 0.35 of the diagonal. Now of the order of the surface RMSE.
    assert!(
        v < 0.01 && v < 10.0 * rmse.max(1e-6),
        "vertex RMSE {v}, RMSE {rmse}"
    );
    let dec = run(&["decode", &s, "-o", d.path().join("f/").to_str().unwrap()]);
    assert!(stderr(&dec).contains("--reorder"), "{}", stderr(&dec));
}

#[test]
fn f8_options_of_another_codec_are_usage_errors() {
    let d = tempfile::tempdir().unwrap();
    let sample = media_path("RiggedSimple.glb");
    let o = d.path().join("x.mcgv");
    let o = o.to_str().unwrap();
    for (extra, needles) in [
        (vec!["--qscale", "3"], vec!["--qscale", "mpeg4", "tdct"]),
        (
            vec!["--codec", "jpeg", "--gop", "5"],
            vec!["--gop", "mpeg4", "jpeg"],
        ),
        (
            vec!["--codec", "mpeg4", "--jpeg-quality", "80"],
            vec!["--jpeg-quality", "jpeg"],
        ),
        (vec!["--padding", "cg"], vec!["--padding", "jpeg and mpeg4"]),
        (
            vec!["--codec", "jpeg", "--padding", "foo"],
            vec!["possible values: snap"],
        ),
    ] {
        let mut args = vec!["encode", sample.as_str(), "-o", o];
        args.extend(extra);
        fails(&run(&args), 2, &needles);
        assert!(!Path::new(o).exists());
    }
    let help = ok(&run(&["encode", "--help"]));
    assert!(
        !help.contains("Image codec") && help.contains("Examples:"),
        "{help}"
    );
    assert!(
        help.contains("[possible values: snap, biharmonic"),
        "{help}"
    );
    for cmd in [
        "decode",
        "inspect",
        "eval",
        "info",
        "convert",
        "completions",
        "man",
    ] {
        assert!(
            ok(&run(&[cmd, "--help"])).contains("Examples:\n  mcgv-video"),
            "{cmd}"
        );
    }
}

/// `--clip` was silently ignored for OBJ frames (another animation than asked for was encoded),
/// and `decode --frames ..0` said "the animation has no frames" (exit 1) where `10..5` is a usage
/// error: both are usage errors now (exit 2).
#[test]
fn f8_a_clip_of_obj_frames_and_an_empty_frame_range_are_usage_errors() {
    let d = tempfile::tempdir().unwrap();
    let frames = d.path().join("frames");
    std::fs::create_dir(&frames).unwrap();
    for f in 0..2 {
        let text = format!("v 0 0 0\nv 1 0 {f}\nv 0 1 0\nf 1 2 3\n");
        std::fs::write(frames.join(format!("f_{f}.obj")), text).unwrap();
    }
    let (input, o) = (frames.to_str().unwrap(), d.path().join("x.mcgv"));
    let o = o.to_str().unwrap();
    fails(
        &run(&["encode", input, "-o", o, "--clip", "3"]),
        2,
        &["--clip", "glTF"],
    );
    let pc2 = d.path().join("x.pc2");
    let convert = run(&["convert", input, "-o", pc2.to_str().unwrap(), "--clip", "0"]);
    fails(&convert, 2, &["--clip", "glTF"]);
    assert!(!Path::new(o).exists() && !pc2.exists());
    let s = stream(d.path(), &[]);
    let out = d.path().join("f0");
    for empty in ["..0", "10..5"] {
        let args = ["decode", &s, "--frames", empty, "-o", out.to_str().unwrap()];
        fails(&run(&args), 2, &[empty, "empty"]);
    }
    assert!(!out.exists());
}

#[test]
fn f9_messages_name_the_file_and_the_fix() {
    let d = tempfile::tempdir().unwrap();
    let sample = media_path("RiggedSimple.glb");
    // Missing folders are created, for encode as for decode: no temporary names anywhere.
    let nested = d.path().join("nodir/sub/x.mcgv");
    let out = run(&["encode", &sample, "-o", nested.to_str().unwrap(), "-q"]);
    assert!(out.status.success() && nested.is_file(), "{}", stderr(&out));
    std::fs::write(d.path().join("file"), "x").unwrap();
    let blocked = d.path().join("file/x.mcgv");
    let out = run(&["encode", &sample, "-o", blocked.to_str().unwrap(), "-q"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(!stderr(&out).contains(".mcgv-partial-"), "{}", stderr(&out));
    // A text file named .glb.
    let fake = d.path().join("fake.glb");
    std::fs::write(&fake, "hello\n").unwrap();
    fails(
        &run(&["info", fake.to_str().unwrap()]),
        1,
        &["not a glTF file", "fake.glb"],
    );
    // A damaged stream names its file (its header here: a damaged temporal-DCT band only ends
    // decoding there, with a warning).
    let s = stream(d.path(), &[]);
    let mut bytes = std::fs::read(&s).unwrap();
    bytes[40] ^= 0xff;
    std::fs::write(&s, bytes).unwrap();
    let out = run(&["decode", &s, "-o", d.path().join("o/").to_str().unwrap()]);
    fails(&out, 1, &["corrupt stream", "s.mcgv"]);
    // An unquoted glob: a hint to quote it.
    let out = run(&["encode", &sample, &media_path("Fox.glb"), "-o", "x.mcgv"]);
    fails(&out, 2, &["unexpected argument", "quote it"]);
}

#[test]
fn f10_inspect_pictures_are_labelled() {
    let d = tempfile::tempdir().unwrap();
    let s = stream(d.path(), &["--codec", "jpeg"]);
    let png = d.path().join("png");
    ok(&run(&["inspect", &s, "--png", png.to_str().unwrap(), "-q"]));
    let info = json(&run(&["inspect", &s, "--json"]));
    let w = info["lattice"][0].as_u64().unwrap() as u32;
    let h = info["lattice"][1].as_u64().unwrap() as u32;
    let decoded = image::open(png.join("frame_0000_decoded.png"))
        .unwrap()
        .to_rgb8();
    // Three panels with gaps, a title and axis line above, the scale bar and its numbers below.
    assert!(
        decoded.width() > 3 * w && decoded.height() > h + 40,
        "{:?}",
        decoded.dimensions()
    );
    assert!(
        decoded.pixels().any(|p| p.0 == [220, 30, 30]),
        "no zero mark"
    );
    for name in ["atlas.png", "segmentation.png"] {
        let picture = image::open(png.join(name)).unwrap().to_rgb8();
        let bottom = picture.height() - 12;
        // The legend rows at the bottom hold coloured swatches.
        let coloured = (0..picture.width()).any(|x| {
            let [r, g, b] = picture.get_pixel(x, bottom + 2).0;
            r.max(g).max(b) - r.min(g).min(b) > 60
        });
        assert!(coloured, "{name} has no legend");
    }
    assert!(std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/reading-inspect-pictures.md")
    )
    .unwrap()
    .contains("model units"));
}

#[test]
fn f11_encode_to_a_mesh_name_or_a_folder_is_refused_before_any_work() {
    let d = tempfile::tempdir().unwrap();
    let sample = media_path("RiggedSimple.glb");
    for name in ["walk.glb", "walk.OBJ", "walk.pc2", "walk.gltf"] {
        let out_path = d.path().join(name);
        let out = run(&["encode", &sample, "-o", out_path.to_str().unwrap(), "-q"]);
        fails(
            &out,
            2,
            &["encode writes an .mcgv stream", "walk.mcgv", "decode"],
        );
        assert!(!out_path.exists(), "{name} was written");
    }
    let folder = format!("{}/", d.path().join("frames").display());
    let out = run(&["encode", &sample, "-o", &folder, "-q"]);
    fails(&out, 2, &["names a folder", "walk.mcgv"]);
    assert_eq!(file_names(d.path()), Vec::<String>::new());
}
