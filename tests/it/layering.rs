//! The library's modules depend downwards only, and the CLI uses only the public API: each rule
//! names a folder and the paths its code may not name (comments aside).

use std::path::{Path, PathBuf};

/// Every `.rs` file under `dir`.
fn sources(dir: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).expect("a source folder") {
            let path = entry.expect("a folder entry").path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                files.push(path);
            }
        }
    }
    files
}

/// The lines of the files under `folder` (of the repository) whose code names one of `paths`; a
/// file's unit tests (from its `#[cfg(test)]` on, at the end by convention) may name anything.
fn offences(folder: &str, paths: &[&str]) -> Vec<String> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join(folder);
    let mut found = Vec::new();
    for file in sources(&root) {
        let text = std::fs::read_to_string(&file).expect("a readable source");
        let code_lines = text.lines().take_while(|l| !l.starts_with("#[cfg(test)]"));
        for (n, line) in code_lines.enumerate() {
            let code = line.split("//").next().unwrap_or_default();
            if paths.iter().any(|p| code.contains(p)) {
                found.push(format!("{}:{}: {}", file.display(), n + 1, line.trim()));
            }
        }
    }
    found
}

#[test]
fn modules_depend_downwards_only() {
    let rules: [(&str, &[&str]); 6] = [
        (
            "src/stream",
            &["crate::codec", "crate::encoder", "crate::decoder"],
        ),
        (
            "src/codec",
            &["crate::encoder", "crate::decoder", "crate::inspect"],
        ),
        ("src/geometry_image", &["crate::codec", "crate::encoder"]),
        (
            "src/first_frame",
            &["crate::codec", "crate::encoder", "crate::motion"],
        ),
        (
            "src/motion",
            &["crate::codec", "crate::encoder", "crate::stream"],
        ),
        (
            "src/mesh",
            &[
                "crate::metrics",
                "crate::codec",
                "crate::motion",
                "crate::stream",
            ],
        ),
    ];
    for (folder, forbidden) in rules {
        let found = offences(folder, forbidden);
        assert!(
            found.is_empty(),
            "{folder} reaches up:\n{}",
            found.join("\n")
        );
    }
}

#[test]
fn the_cli_uses_only_the_public_api() {
    let internals = [
        "mcgv_video::stream",
        "mcgv_video::geometry_image",
        "mcgv_video::first_frame",
        "mcgv_video::motion",
        "mcgv_video::limits",
        "mcgv_video::output",
        "padding::",
    ];
    let found = offences("cli/src", &internals);
    assert!(
        found.is_empty(),
        "the CLI reaches past the API:\n{}",
        found.join("\n")
    );
}
