//! Same input and options, same bytes: every codec, whatever `--threads` says and whatever the
//! heap holds.

use crate::common::{media_path, ok};
use std::process::Command;

/// Encodes RiggedFigure with `codec` (groups of 10 pictures: several groups share a thread
/// with `--threads 1`, each on a heap its forerunners used) and returns the stream's bytes;
/// `threads` is `--threads` (none: the default), `perturb` sets glibc's `MALLOC_PERTURB_`, which
/// fills every new allocation with a fixed byte, so memory a coder reads without writing it
/// changes its output.
fn encode(codec: &str, threads: Option<&str>, perturb: bool) -> Vec<u8> {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("s.mcgv");
    let mut command = Command::new(env!("CARGO_BIN_EXE_mcgv-video"));
    if let Some(n) = threads {
        command.args(["--threads", n]);
    }
    let input = media_path("RiggedFigure.glb");
    command.args([
        "encode",
        &input,
        "-o",
        out.to_str().unwrap(),
        "--codec",
        codec,
        "-q",
    ]);
    if codec != "tdct" && codec != "jpeg" {
        command.args(["--gop", "10"]);
    }
    if perturb {
        command.env("MALLOC_PERTURB_", "85");
    }
    ok(&command.output().unwrap());
    std::fs::read(&out).unwrap()
}

#[test]
fn every_codec_gives_the_same_bytes_on_every_run_and_thread_count() {
    for codec in ["tdct", "jpeg", "mpeg4", "hevc", "av1"] {
        let first = encode(codec, Some("1"), false);
        for (threads, perturb) in [(Some("1"), true), (Some("2"), false), (None, false)] {
            let again = encode(codec, threads, perturb);
            assert!(
                again == first,
                "{codec} --threads {threads:?} (heap filled: {perturb}): {} bytes, not the {} of --threads 1",
                again.len(),
                first.len()
            );
        }
    }
}
