//! The skinning predictor through the command line.

use crate::common::{json, media_path, ok, run};
use std::path::Path;

#[test]
fn cli_records_the_predictor_and_inspect_reports_the_weights() {
    let dir = tempfile::tempdir().unwrap();
    let sample = media_path("RiggedSimple.glb");
    let mut bits = Vec::new();
    // --weight-bits is the most: the encoder takes fewer where the maps' step allows (9 here at
    // 16), so the cap of 6 is below what it would take.
    for (predictor, weight_bits) in [("affine", "16"), ("skinning", "16"), ("skinning", "6")] {
        let path = dir.path().join(format!("{predictor}{weight_bits}.mcgv"));
        let s = path.to_str().unwrap();
        ok(&run(&[
            "encode",
            "--codec",
            "jpeg",
            &sample,
            "-o",
            s,
            "--predictor",
            predictor,
            "--weight-bits",
            weight_bits,
            "--padding",
            "cg",
            "--quiet",
        ]));
        let info = json(&run(&["inspect", s, "--json"]));
        assert_eq!(info["predictor"], predictor);
        if predictor == "skinning" {
            let most: u64 = weight_bits.parse().unwrap();
            let used = info["weight_bits"].as_u64().expect("weight bits");
            assert!(used <= most && used >= 2, "{used} bits for at most {most}");
            if most == 6 {
                assert_eq!(used, 6);
            }
        } else {
            assert!(info["weight_bits"].is_null());
        }
        bits.push(info["parts"]["skinning weights"].as_u64());
    }
    assert_eq!(bits[0], None);
    assert!(bits[1].is_some_and(|b| b > 0), "{bits:?}");
    // Coarser weights take fewer bits.
    assert!(
        bits[2].is_some_and(|b| bits[1].is_some_and(|full| b < full)),
        "{bits:?}"
    );
    let bad = run(&[
        "encode",
        "--codec",
        "jpeg",
        &sample,
        "-o",
        "x.mcgv",
        "--predictor",
        "bones",
    ]);
    assert_eq!(bad.status.code(), Some(2));
}

/// `--affine-precision` scales the affine step (finer maps, more bytes); an out-of-range one and
/// the retired `--affine-bits` (now unknown) are usage errors naming the flag.
#[test]
fn affine_precision_sets_the_maps_step_and_affine_bits_is_retired() {
    let dir = tempfile::tempdir().unwrap();
    let sample = media_path("RiggedSimple.glb");
    let mut sizes = Vec::new();
    for precision in ["0.0625", "1"] {
        let path = dir.path().join(format!("p{precision}.mcgv"));
        let s = path.to_str().unwrap();
        ok(&run(&[
            "encode",
            &sample,
            "-o",
            s,
            "--affine-precision",
            precision,
            "--quiet",
        ]));
        let info = json(&run(&["inspect", s, "--json"]));
        sizes.push(info["parts"]["affine coefficients"].as_u64().unwrap());
    }
    assert!(sizes[0] > sizes[1], "{sizes:?}");
    for (flag, value) in [("--affine-bits", "17"), ("--affine-precision", "100")] {
        let out = run(&["encode", &sample, "-o", "x.mcgv", flag, value]);
        assert_eq!(out.status.code(), Some(2), "{flag} {value}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("affine"), "{err}");
    }
    let retired = run(&["encode", &sample, "-o", "x.mcgv", "--affine-bits", "17"]);
    let err = String::from_utf8_lossy(&retired.stderr);
    assert!(err.contains("unexpected argument '--affine-bits'"), "{err}");
    assert!(!Path::new("x.mcgv").exists());
}
