//! `encode -o` never damages what is there: no half-written output, no overwritten input.

use crate::common::{media_path, run};
use std::path::Path;
use std::process::Output;

fn refused(out: &Output) {
    assert_eq!(out.status.code(), Some(1), "{out:?}");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("refusing to overwrite the input"), "{err}");
}

/// Names in `dir` that a failed write could have left: temporary files of `write_atomic`.
fn leftovers(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(".mcgv-partial-"))
        .collect()
}

/// Two OBJ frames of a square in `dir`.
/// Encodes the OBJ frames in `frames` (as [`obj_frames`] writes them) to `out`; must succeed.
fn encode_frames(frames: &Path, out: &Path) {
    let enc = run(&[
        "encode",
        "--codec",
        "jpeg",
        frames.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--lattice",
        "16x16",
        "--clusters",
        "1",
        "--quiet",
    ]);
    assert!(enc.status.success(), "{enc:?}");
}

fn obj_frames(dir: &Path) {
    std::fs::create_dir_all(dir).unwrap();
    for f in 0..2 {
        let text = format!(
            "v 0 0 0\nv 1 0 {}\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n",
            f as f32 * 0.1
        );
        std::fs::write(dir.join(format!("frame_{f}.obj")), text).unwrap();
    }
}

#[test]
fn no_input_file_can_be_the_output() {
    let d = tempfile::tempdir().unwrap();
    let frames = d.path().join("frames");
    obj_frames(&frames);
    let frame1 = frames.join("frame_1.obj");
    let before = std::fs::read(&frame1).unwrap();
    let dir = frames.to_str().unwrap();
    let pattern = format!("{dir}/*.obj");
    // A frame of the folder, named directly or through `..`, and of a glob.
    let sneaky = frames.join("../frames/./frame_1.obj");
    for (input, output) in [
        (dir, frame1.to_str().unwrap()),
        (dir, sneaky.to_str().unwrap()),
        (pattern.as_str(), frame1.to_str().unwrap()),
    ] {
        refused(&run(&[
            "encode", "--codec", "jpeg", input, "-o", output, "--quiet",
        ]));
    }
    assert_eq!(std::fs::read(&frame1).unwrap(), before);
    // The base OBJ of a PC2 cache.
    let pc2 = d.path().join("anim.pc2");
    let stream = d.path().join("s.mcgv");
    encode_frames(Path::new(dir), &stream);
    let ok = run(&[
        "decode",
        stream.to_str().unwrap(),
        "-o",
        pc2.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(ok.status.success(), "{ok:?}");
    let base = d.path().join("anim.obj");
    std::fs::copy(frames.join("frame_0.obj"), &base).unwrap();
    let base_before = std::fs::read(&base).unwrap();
    refused(&run(&[
        "encode",
        "--codec",
        "jpeg",
        pc2.to_str().unwrap(),
        "-o",
        base.to_str().unwrap(),
    ]));
    assert_eq!(std::fs::read(&base).unwrap(), base_before);
    assert!(leftovers(d.path()).is_empty());
}

#[test]
fn a_failing_encode_leaves_the_target_as_it_was() {
    let d = tempfile::tempdir().unwrap();
    // RiggedSimple has more vertices than a 16x16 lattice has pixels: the atlas fails after reading.
    // Once onto a new name (nothing may be created), once onto an old file (it must stay as it was).
    let old_bytes: &[u8] = b"the previous output";
    for (name, before) in [("fresh.mcgv", None), ("old.mcgv", Some(old_bytes))] {
        let target = d.path().join(name);
        if let Some(bytes) = before {
            std::fs::write(&target, bytes).unwrap();
        }
        let out = run(&[
            "encode",
            "--codec",
            "jpeg",
            &media_path("RiggedSimple.glb"),
            "-o",
            target.to_str().unwrap(),
            "--lattice",
            "16x16",
            "--quiet",
        ]);
        assert_eq!(out.status.code(), Some(1), "{out:?}");
        match before {
            None => assert!(!target.exists(), "a failed encode created its output"),
            Some(bytes) => assert_eq!(std::fs::read(&target).unwrap(), bytes),
        }
    }
    assert!(leftovers(d.path()).is_empty(), "{:?}", leftovers(d.path()));
}

#[cfg(unix)]
#[test]
fn outputs_get_ordinary_file_permissions() {
    use std::os::unix::fs::PermissionsExt;
    let d = tempfile::tempdir().unwrap();
    let frames = d.path().join("frames");
    obj_frames(&frames);
    let s = d.path().join("s.mcgv");
    encode_frames(&frames, &s);
    // A file written directly in the same folder gets the mode the umask allows.
    let plain = d.path().join("plain");
    std::fs::write(&plain, b"x").unwrap();
    let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
    assert_eq!(mode(&s), mode(&plain));
}

/// `decode -o like.glb --like like.glb --force` replaced the glTF it was told to copy the look
/// of, and `convert in.glb -o in.glb --force` its input: every input of a run is refused as an
/// output, as `encode` refuses its own.
#[test]
fn decode_and_convert_refuse_to_overwrite_what_they_read() {
    let d = tempfile::tempdir().unwrap();
    let frames = d.path().join("frames");
    obj_frames(&frames);
    let stream = d.path().join("s.mcgv");
    encode_frames(&frames, &stream);
    let like = d.path().join("like.glb");
    std::fs::copy(media_path("RiggedSimple.glb"), &like).unwrap();
    let before = std::fs::read(&like).unwrap();
    let (s, l) = (stream.to_str().unwrap(), like.to_str().unwrap());
    refused(&run(&["decode", s, "-o", l, "--like", l, "--force", "-q"]));
    let sneaky = d.path().join("frames/../like.glb");
    let sneaky = sneaky.to_str().unwrap();
    refused(&run(&[
        "decode", s, "-o", sneaky, "--like", l, "--force", "-q",
    ]));
    refused(&run(&["convert", l, "-o", sneaky, "--force", "-q"]));
    assert_eq!(std::fs::read(&like).unwrap(), before);
    assert!(leftovers(d.path()).is_empty());
}
