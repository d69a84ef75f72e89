//! Cross-check of the surface distances against an outside reference: PyMeshLab's Hausdorff filter
//! (Metro), on a real mesh and perturbed copies of it.
//!
//! Runs only when `MCGV_PYTHON` names a python that can `import pymeshlab` (the Makefile points it at
//! its virtualenv); otherwise it says it is skipped and passes.

use mcgv_video::mesh::{Point, Triangle};
use mcgv_video::metrics::sampling::sample_spacing;
use mcgv_video::metrics::{frame_distance, OneSided, Surface};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Agreement asked of every figure.
const TOLERANCE: f64 = 0.02;

/// Monte Carlo face samples per direction on the Metro side: enough for its RMS to sit well inside
/// the tolerance (1 000 000 moved no figure by more than 0.1 %).
const METRO_SAMPLES: &str = "500000";

fn manifest_path(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

/// The Python with pymeshlab that `make test` installs (`MCGV_PYTHON`, else the repository's
/// `.venv`). A missing tool fails the test: a reference check that silently skips checks nothing.
fn python_with_pymeshlab() -> PathBuf {
    let py = std::env::var_os("MCGV_PYTHON")
        .map(PathBuf::from)
        .unwrap_or_else(|| manifest_path(".venv/bin/python"));
    let ok = Command::new(&py)
        .args(["-c", "import pymeshlab"])
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false);
    assert!(
        ok,
        "{} cannot import pymeshlab: run `make test` (it makes .venv) or set MCGV_PYTHON",
        py.display()
    );
    py
}

/// Frame 0 (the rest pose) of every primitive in a glTF file, concatenated.
fn read_rest_pose(path: &Path) -> (Vec<Triangle>, Vec<Point>) {
    let (doc, buffers, _) =
        gltf::import(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let (mut triangles, mut positions) = (Vec::new(), Vec::<Point>::new());
    for mesh in doc.meshes() {
        for prim in mesh.primitives() {
            let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
            let base = positions.len() as u32;
            let Some(p) = reader.read_positions() else {
                continue;
            };
            positions.extend(p);
            let indices: Vec<u32> = match reader.read_indices() {
                Some(i) => i.into_u32().collect(),
                None => (0..positions.len() as u32 - base).collect(),
            };
            triangles.extend(
                indices
                    .chunks_exact(3)
                    .map(|t| [base + t[0], base + t[1], base + t[2]]),
            );
        }
    }
    assert!(!triangles.is_empty(), "{}: no triangles", path.display());
    (triangles, positions)
}

fn write_obj(path: &Path, triangles: &[Triangle], positions: &[Point]) {
    let mut s = String::new();
    for p in positions {
        let _ = writeln!(s, "v {} {} {}", p[0], p[1], p[2]);
    }
    for t in triangles {
        let _ = writeln!(s, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    std::fs::write(path, s).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
}

fn diagonal(positions: &[Point]) -> f64 {
    let (lo, hi) = mcgv_video::mesh::bounding_box(positions);
    (0..3)
        .map(|a| ((hi[a] - lo[a]) as f64).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// A deterministic value in [-1, 1] for (vertex, axis): SplitMix64 of the pair.
fn noise(i: usize, axis: usize) -> f32 {
    let mut z = (i as u64 * 3 + axis as u64).wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    ((z >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
}

/// Every vertex jittered independently by up to `amp` per axis: a rough, crack-opening error.
fn jittered(positions: &[Point], amp: f32) -> Vec<Point> {
    positions
        .iter()
        .enumerate()
        .map(|(i, p)| [0, 1, 2].map(|a| p[a] + amp * noise(i, a)))
        .collect()
}

/// A smooth wave of amplitude `amp` along each axis: a low-frequency error, like a lossy codec's.
fn waved(positions: &[Point], amp: f32, wavelength: f32) -> Vec<Point> {
    let k = std::f32::consts::TAU / wavelength;
    positions
        .iter()
        .map(|p| {
            [
                p[0] + amp * (k * p[1]).sin(),
                p[1] + amp * (k * p[2]).cos(),
                p[2] + amp * (k * p[0]).sin(),
            ]
        })
        .collect()
}

fn metro(py: &Path, a: &Path, b: &Path) -> serde_json::Value {
    let out = Command::new(py)
        .arg(manifest_path("scripts/metro_reference.py"))
        .args([a.as_os_str(), b.as_os_str()])
        .arg(METRO_SAMPLES)
        .output()
        .unwrap_or_else(|e| panic!("running {}: {e}", py.display()));
    assert!(
        out.status.success(),
        "metro_reference.py failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("metro output: {e}"))
}

fn figure(v: &serde_json::Value, dir: &str, key: &str) -> f64 {
    v.get(dir)
        .and_then(|d| d.get(key))
        .and_then(|x| x.as_f64())
        .unwrap_or_else(|| panic!("no {dir}.{key} in {v}"))
}

fn check(case: &str, ours: &OneSided, theirs: &serde_json::Value, dir: &str, diag: f64) {
    // For information: Metro's maximum when it also samples along the edges (not like with like:
    // our samples on an edge are its ends and midpoint only).
    let edges = figure(theirs, dir, "max_with_edges");
    eprintln!(
        "{case:>8} {dir:>8}  max with Metro's edge samples {:.6e} of diag ({:+.3} % from ours)",
        edges / diag,
        100.0 * (edges - ours.max) / ours.max
    );
    for (key, mine) in [("rms", ours.rms), ("mean", ours.mean), ("max", ours.max)] {
        let reference = figure(theirs, dir, key);
        let rel = (mine - reference).abs() / reference;
        eprintln!(
            "{case:>8} {dir:>8} {key:>4}: ours {:.6e}  metro {:.6e}  (of diag; {} samples ours) \
             relative difference {:.3} %",
            mine / diag,
            reference / diag,
            ours.samples,
            100.0 * rel
        );
        assert!(
            rel <= TOLERANCE,
            "{case} {dir} {key}: ours {mine} vs Metro {reference}"
        );
    }
}

#[test]
fn surface_distances_agree_with_metro() {
    let py = python_with_pymeshlab();
    let (triangles, original) = read_rest_pose(&manifest_path("media/CesiumMan.glb"));
    let diag = diagonal(&original);
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let a_path = dir.path().join("original.obj");
    write_obj(&a_path, &triangles, &original);
    let d = diag as f32;
    for (case, perturbed) in [
        ("jitter", jittered(&original, 0.002 * d)),
        ("wave", waved(&original, 0.004 * d, 0.3 * d)),
    ] {
        let b_path = dir.path().join(format!("{case}.obj"));
        write_obj(&b_path, &triangles, &perturbed);
        let theirs = metro(&py, &a_path, &b_path);
        let ours = frame_distance(
            Surface {
                triangles: &triangles,
                positions: &original,
            },
            Surface {
                triangles: &triangles,
                positions: &perturbed,
            },
            sample_spacing(diag),
        )
        .unwrap_or_else(|e| panic!("{e}"));
        let their_diag = figure(
            &serde_json::json!({ "d": { "x": theirs["diag"] } }),
            "d",
            "x",
        );
        assert!(
            (their_diag - diag).abs() < 1e-4 * diag,
            "bbox diagonals differ"
        );
        check(case, &ours.forward, &theirs, "forward", diag);
        check(case, &ours.backward, &theirs, "backward", diag);
    }
}
