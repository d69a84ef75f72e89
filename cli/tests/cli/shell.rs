//! The shell completions complete options and their values, and every page the man page names
//! exists and is installed.

use crate::common::{ok, repo_root, run};
use std::process::Command;

/// What bash completes for the words `line` (the last one being completed), with the script
/// `mcgv-video completions bash` prints sourced.
fn bash_completes(line: &[&str]) -> Vec<String> {
    let d = tempfile::tempdir().unwrap();
    let script = d.path().join("mcgv-video.bash");
    std::fs::write(&script, ok(&run(&["completions", "bash"]))).unwrap();
    let words: Vec<String> = line.iter().map(|w| format!("'{w}'")).collect();
    let cword = line.len() - 1;
    let (cur, prev) = (line[cword], line[cword - 1]);
    let program = format!(
        "source '{}'; COMP_WORDS=({}); COMP_CWORD={cword}; \
         _mcgv__video mcgv-video '{cur}' '{prev}'; printf '%s\\n' \"${{COMPREPLY[@]}}\"",
        script.display(),
        words.join(" ")
    );
    let out = Command::new("bash")
        .args(["--noprofile", "--norc", "-c", &program])
        .output()
        .expect("bash runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(str::to_string)
        .collect()
}

#[test]
fn bash_completes_options_and_their_values() {
    let codecs = bash_completes(&["mcgv-video", "encode", "x", "--codec", ""]);
    assert_eq!(codecs, ["jpeg", "mpeg4", "tdct", "hevc", "av1"]);
    let padding = bash_completes(&["mcgv-video", "encode", "x", "--padding", ""]);
    assert!(padding.contains(&"biharmonic".to_string()), "{padding:?}");
    assert_eq!(
        padding.len(),
        mcgv_video::PaddingMethod::NAMES.len(),
        "{padding:?}"
    );
    let some = bash_completes(&["mcgv-video", "encode", "x", "--pa"]);
    assert_eq!(some, ["--padding"]);
    // Every option offered is one `--help` shows: nothing hidden or retired.
    for command in ["encode", "decode", "inspect", "eval", "info", "convert"] {
        let help = ok(&run(&[command, "--help"]));
        let offered = bash_completes(&["mcgv-video", command, "x", "--"]);
        assert!(offered.len() > 3, "{command}: {offered:?}");
        for flag in offered {
            assert!(
                help.contains(&flag),
                "{command} offers {flag}, which --help does not show"
            );
        }
    }
}

#[test]
fn every_page_the_man_page_names_exists_and_is_installed() {
    let main = ok(&run(&["man"]));
    let makefile = std::fs::read_to_string(repo_root().join("Makefile")).unwrap();
    let installed = makefile
        .lines()
        .find_map(|l| l.strip_prefix("MAN_PAGES := "))
        .expect("the Makefile lists the man pages it installs");
    let installed: Vec<&str> = installed.split_whitespace().collect();
    let named: Vec<&str> = main
        .split("mcgv\\-video\\-")
        .skip(1)
        .filter_map(|rest| rest.split_once("(1)").map(|(name, _)| name))
        .filter(|name| name.chars().all(|c| c.is_ascii_lowercase()))
        .collect();
    assert!(!named.is_empty(), "{main}");
    for name in &named {
        assert!(
            installed.contains(name),
            "mcgv-video-{name}(1) is named but not installed"
        );
    }
    for name in installed {
        let page = ok(&run(&["man", name]));
        assert!(page.contains(&format!(".TH mcgv-video-{name} 1")), "{page}");
        // The global options are on every page.
        assert!(page.contains("\\-\\-quiet"), "{name}");
    }
    let encode = ok(&run(&["man", "encode"]));
    for option in [
        "\\-\\-codec",
        "\\-\\-quality",
        "\\-\\-force",
        "\\-\\-padding",
    ] {
        assert!(encode.contains(option), "{option}");
    }
}
