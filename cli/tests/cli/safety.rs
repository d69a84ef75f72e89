//! Nothing lost: no command deletes or overwrites a file that exists without `--force` (`-y`),
//! `--force` replaces only the files the run writes, an output that cannot be written is found
//! before any work, and a failed run leaves nothing behind.

use crate::common::{media_path, run, tiny_stream};
use mcgv_video::Codec;
use std::collections::BTreeMap;
use std::path::Path;
use std::process::Output;

/// Every file under `dir` (relative name → bytes), hidden staging files included.
fn snapshot(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut files = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(at) = stack.pop() {
        for entry in std::fs::read_dir(&at).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else {
                let name = path
                    .strip_prefix(dir)
                    .unwrap()
                    .to_string_lossy()
                    .into_owned();
                files.insert(name, std::fs::read(&path).unwrap());
            }
        }
    }
    files
}

/// Asserts a run failed with `code` and a message holding every one of `words`.
fn fails(out: &Output, code: i32, words: &[&str]) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(code), "{err}");
    for word in words {
        assert!(err.contains(word), "`{word}` missing from: {err}");
    }
}

fn succeeds(out: &Output) -> String {
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "{err}");
    err
}

/// A two-frame JPEG stream of a square at `dir/s.mcgv`.
fn stream(dir: &Path) -> String {
    let path = dir.join("s.mcgv");
    std::fs::write(&path, tiny_stream(Codec::Jpeg)).unwrap();
    path.to_string_lossy().into_owned()
}

/// `count` source frames `frame_0000.obj` … (a Blender export's names) and a `notes.txt`.
fn foreign_folder(dir: &Path, count: usize) {
    std::fs::create_dir_all(dir).unwrap();
    for f in 0..count {
        let text = format!("# source frame {f}\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
        std::fs::write(dir.join(format!("frame_{f:04}.obj")), text).unwrap();
    }
    std::fs::write(dir.join("notes.txt"), "my notes").unwrap();
}

#[test]
fn a_folder_of_foreign_files_is_refused_and_with_force_keeps_what_the_run_does_not_write() {
    let d = tempfile::tempdir().unwrap();
    let s = stream(d.path());
    let dir = d.path().join("c2");
    foreign_folder(&dir, 10);
    let before = snapshot(&dir);
    let o = dir.to_str().unwrap();
    for output in [o.to_string(), format!("{o}/")] {
        let out = run(&["decode", &s, "--frames", "0..1", "-o", &output]);
        fails(&out, 1, &["holds 11 files", "--force"]);
        assert_eq!(snapshot(&dir), before);
    }
    let err = succeeds(&run(&[
        "decode", &s, "--frames", "0..1", "-o", o, "--force",
    ]));
    assert!(err.contains("left 10 other files"), "{err}");
    let after = snapshot(&dir);
    assert_eq!(after.len(), 11, "{:?}", after.keys());
    assert_ne!(after["frame_0000.obj"], before["frame_0000.obj"]);
    for (name, bytes) in &before {
        if name != "frame_0000.obj" {
            assert_eq!(&after[name], bytes, "{name} changed");
        }
    }
    // `convert` and `inspect --png` follow the same rules.
    let out = run(&["convert", &media_path("RiggedSimple.glb"), "-o", o]);
    fails(&out, 1, &["holds 11 files"]);
    let png = d.path().join("png");
    foreign_folder(&png, 1);
    let p = png.to_str().unwrap();
    fails(&run(&["inspect", &s, "--png", p]), 1, &["holds 2 files"]);
    succeeds(&run(&["inspect", &s, "--png", p, "-y", "-q"]));
    assert_eq!(
        std::fs::read_to_string(png.join("notes.txt")).unwrap(),
        "my notes"
    );
    assert!(png.join("frame_0000.obj").is_file() && png.join("atlas.png").is_file());
}

#[test]
fn existing_files_are_replaced_only_with_force() {
    let d = tempfile::tempdir().unwrap();
    let s = stream(d.path());
    let old: &[u8] = b"the user's own file";
    let path = |name: &str| d.path().join(name).to_string_lossy().into_owned();
    let runs: Vec<(Vec<String>, Vec<&str>)> = vec![
        (
            vec!["decode".into(), s.clone(), "--frame".into(), "1".into()],
            vec!["one.obj"],
        ),
        (vec!["decode".into(), s.clone()], vec!["cache.pc2"]),
        (
            vec!["decode".into(), s.clone()],
            vec!["base.pc2", "base.obj"],
        ),
        (vec!["decode".into(), s.clone()], vec!["anim.glb"]),
        (
            vec!["convert".into(), media_path("RiggedSimple.glb")],
            vec!["conv.pc2"],
        ),
        (
            vec![
                "encode".into(),
                media_path("RiggedSimple.glb"),
                "--codec".into(),
                "jpeg".into(),
            ],
            vec!["e.mcgv"],
        ),
    ];
    for (args, names) in runs {
        // The file the run names with -o is the first; an existing later one (the PC2's base
        // OBJ) is refused as well.
        let existing = names.last().unwrap();
        std::fs::write(path(existing), old).unwrap();
        let mut argv: Vec<String> = args.clone();
        argv.extend(["-o".to_string(), path(names[0]), "-q".to_string()]);
        let refs: Vec<&str> = argv.iter().map(String::as_str).collect();
        fails(&run(&refs), 1, &[existing, "exists", "--force"]);
        assert_eq!(std::fs::read(path(existing)).unwrap(), old, "{argv:?}");
        for name in &names[..names.len() - 1] {
            assert!(!Path::new(&path(name)).exists(), "{argv:?} wrote {name}");
        }
        let mut forced = refs.clone();
        forced.push("--force");
        succeeds(&run(&forced));
        assert_ne!(std::fs::read(path(existing)).unwrap(), old, "{argv:?}");
    }
}

/// `--force` onto a FIFO or a symbolic link replaced it with a regular file (the stream was
/// written to a temporary file renamed over the path): a FIFO is written through, a link's
/// target is written and the link stays.
#[cfg(unix)]
#[test]
fn force_writes_through_a_fifo_and_a_symbolic_link() {
    use std::os::unix::fs::FileTypeExt;
    let d = tempfile::tempdir().unwrap();
    let s = stream(d.path());
    let (fifo, link, target) = (
        d.path().join("pipe.glb"),
        d.path().join("link.glb"),
        d.path().join("target.glb"),
    );
    assert!(std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    // The reader hands over what it read, and the test fails rather than hangs should nothing
    // ever open the FIFO for writing (the path replaced by a regular file).
    let (sent, read) = std::sync::mpsc::channel();
    let reader = fifo.clone();
    std::thread::spawn(move || sent.send(std::fs::read(reader).unwrap()));
    let out = |o: &Path| run(&["decode", &s, "-o", o.to_str().unwrap(), "-q", "--force"]);
    succeeds(&out(&fifo));
    assert!(read
        .recv_timeout(std::time::Duration::from_secs(20))
        .expect("nothing written to the FIFO")
        .starts_with(b"glTF"));
    assert!(std::fs::symlink_metadata(&fifo)
        .unwrap()
        .file_type()
        .is_fifo());
    std::fs::write(&target, b"old").unwrap();
    std::os::unix::fs::symlink("target.glb", &link).unwrap();
    succeeds(&out(&link));
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    assert!(std::fs::read(&target).unwrap().starts_with(b"glTF"));
}

#[test]
fn an_output_that_cannot_be_written_is_found_before_any_work() {
    let d = tempfile::tempdir().unwrap();
    let s = stream(d.path());
    let file = d.path().join("plain");
    std::fs::write(&file, "a file, not a folder").unwrap();
    let inside = file.join("x.mcgv");
    let o = inside.to_str().unwrap();
    // The input does not exist either: the output is checked first, so the message names it.
    fails(
        &run(&["encode", "missing.glb", "-o", o]),
        1,
        &["plain is a file, not a folder"],
    );
    let frames = file.join("frames/");
    let f = frames.to_str().unwrap();
    fails(
        &run(&["decode", &s, "-o", f]),
        1,
        &["is a file, not a folder"],
    );
    let png = file.join("png");
    fails(
        &run(&["inspect", &s, "--png", png.to_str().unwrap()]),
        1,
        &["is a file"],
    );
    #[cfg(unix)]
    read_only_folder(d.path());
}

/// A folder without write permission, when the permission holds (not for root).
#[cfg(unix)]
fn read_only_folder(dir: &Path) {
    use std::os::unix::fs::PermissionsExt;
    let ro = dir.join("ro");
    std::fs::create_dir(&ro).unwrap();
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o555)).unwrap();
    let probe = ro.join("probe");
    if std::fs::write(&probe, b"").is_ok() {
        // Root writes anywhere: nothing to check here.
        let _ = std::fs::remove_file(&probe);
    } else {
        let start = std::time::Instant::now();
        let target = ro.join("x.mcgv");
        let cesium = media_path("CesiumMan.glb");
        let out = run(&[
            "encode",
            &cesium,
            "-o",
            target.to_str().unwrap(),
            "--codec",
            "mpeg4",
        ]);
        fails(&out, 1, &["does not take new files"]);
        // Encoding CesiumMan takes seconds; the refusal comes before the input is read.
        assert!(start.elapsed().as_secs_f64() < 2.0, "{:?}", start.elapsed());
    }
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o755)).unwrap();
}

#[test]
fn a_failed_run_leaves_nothing_behind() {
    let d = tempfile::tempdir().unwrap();
    let s = stream(d.path());
    // inspect: the original cannot be read after the atlas and a frame were drawn.
    let png = d.path().join("png");
    let p = png.to_str().unwrap();
    let out = run(&["inspect", &s, "--png", p, "--original", "missing.glb"]);
    fails(&out, 1, &["missing.glb"]);
    assert!(!png.exists(), "a failed inspect left {:?}", snapshot(&png));
    // decode: the stream's last frame is damaged, so decoding fails after the first.
    let mut bytes = std::fs::read(&s).unwrap();
    let end = bytes.len() - 3;
    bytes[end] ^= 0xff;
    let damaged = d.path().join("damaged.mcgv");
    std::fs::write(&damaged, bytes).unwrap();
    let bad = damaged.to_str().unwrap();
    let before = snapshot(d.path());
    // A PC2 or glTF in new folders left the folders behind; so did an option refused only as
    // the glTF was written (a rate of 0, a --like that is not glTF).
    let like = ["--like", bad];
    let runs: [(&str, &[&str], i32); 7] = [
        ("new/frames/", &[], 1),
        ("cache.pc2", &[], 1),
        ("anim.glb", &[], 1),
        ("new/sub/cache.pc2", &[], 1),
        ("new/sub/anim.glb", &[], 1),
        ("new/sub/rate.glb", &["--fps", "0"], 2),
        ("new/sub/like.glb", &like, 1),
    ];
    for (name, extra, code) in runs {
        let target = d.path().join(name);
        let input = if extra.is_empty() { bad } else { s.as_str() };
        let args = [
            &["decode", input, "-o", target.to_str().unwrap(), "-q"],
            extra,
        ]
        .concat();
        let out = run(&args);
        assert_eq!(out.status.code(), Some(code), "{name}: {out:?}");
        assert_eq!(snapshot(d.path()), before, "{name}");
        assert!(!d.path().join("new").exists(), "{name}");
    }
    // Into a folder that holds files, with --force: none is touched, none is added.
    let dir = d.path().join("c2");
    foreign_folder(&dir, 3);
    let before = snapshot(&dir);
    let out = run(&["decode", bad, "-o", dir.to_str().unwrap(), "-y", "-q"]);
    assert_eq!(out.status.code(), Some(1), "{out:?}");
    assert_eq!(snapshot(&dir), before);
}

#[cfg(unix)]
#[test]
fn a_new_folder_gets_ordinary_permissions() {
    use std::os::unix::fs::PermissionsExt;
    let d = tempfile::tempdir().unwrap();
    let s = stream(d.path());
    let frames = d.path().join("frames");
    succeeds(&run(&["decode", &s, "-o", frames.to_str().unwrap(), "-q"]));
    let plain = d.path().join("plain");
    std::fs::create_dir(&plain).unwrap();
    let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
    assert_eq!(mode(&frames), mode(&plain));
}
