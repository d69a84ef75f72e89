//! The sweep behind the error law of `codec::quality` (issue 15): per sequence, JPEG and MPEG-4
//! over pixel step × the picture codec's own quantiser, HEVC (issue 16) over its own pixel steps
//! × QP, and tdct over `--quality`, one CSV row per
//! encoding with its bpvf and vertex RMSE (RMS vertex displacement / first frame's bbox diagonal).
//! `scripts/error_law_fit.py` reads the rows, keeps each codec's lower convex hull and prints, per
//! quality, the hull point at tdct's error.
//!
//! ```text
//! cargo run --release --example error_law_sweep -- OUT.csv INPUT...
//! ```
//! env (space-separated lists): STEPS (pixel steps, fractions of the diagonal), JPEG_QUALITIES,
//! QSCALES, TDCT_QUALITIES, HEVC_STEPS, HEVC_QPS (default none), BIT_DEPTH (10 or 12, HEVC),
//! HEVC_GOP (HEVC's gop, 1 for all-intra); EXTRA_PREDICTOR=skinning for the skinning predictor.
//! The mesh is read and the rows appended once per input; encodings run in this one process.

use mcgv_video::codec::{CodecConfig, DeepConfig, JpegConfig, Mpeg4Config};
use mcgv_video::{encode, read_animation, Codec, Decoder, EncodeOptions, ReadOptions};
use std::error::Error;
use std::io::Write;

type Res<T> = Result<T, Box<dyn Error>>;

fn list<T: std::str::FromStr>(var: &str, default: &str) -> Res<Vec<T>> {
    std::env::var(var)
        .unwrap_or_else(|_| default.to_string())
        .split_whitespace()
        .map(|s| {
            s.parse::<T>()
                .map_err(|_| format!("{var}: bad value {s}").into())
        })
        .collect()
}

/// bpvf and vertex RMSE / diagonal of one encoding.
fn measure(mesh: &mcgv_video::AnimatedMesh, opts: &EncodeOptions) -> Res<(f64, f64)> {
    let bytes = encode(mesh, opts)?.to_bytes();
    let decoded = Decoder::new(&bytes)?.decode_all()?;
    let errors = mcgv_video::metrics::vertex_errors(mesh, &decoded).ok_or("size mismatch")?;
    let bpvf = 8.0 * bytes.len() as f64 / (mesh.vertex_count() * mesh.frame_count()) as f64;
    Ok((bpvf, errors.rmse / mesh.bbox_diagonal()))
}

fn main() -> Res<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (out, inputs) = args.split_first().ok_or("usage: OUT.csv INPUT...")?;
    let steps: Vec<f64> = list("STEPS", "0.00005 0.0001 0.0002 0.0004 0.0008 0.0016")?;
    let jpeg: Vec<u8> = list("JPEG_QUALITIES", "50 75 90 97")?;
    let qscales: Vec<u8> = list("QSCALES", "1 2 4 8")?;
    let tdct: Vec<u8> = list("TDCT_QUALITIES", "10 30 50 75 90 97")?;
    let hevc_steps: Vec<f64> = list("HEVC_STEPS", "0.0000125 0.000025 0.00005 0.0001 0.0002")?;
    let hevc_qps: Vec<u8> = list("HEVC_QPS", "")?;
    let bit_depth: Option<u8> = list("BIT_DEPTH", "")?.first().copied();
    let hevc_gop: Option<usize> = list("HEVC_GOP", "")?.first().copied();
    let skinning = std::env::var("EXTRA_PREDICTOR").is_ok_and(|p| p == "skinning");
    let fresh = !std::path::Path::new(out).exists();
    let mut file = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(out)?;
    if fresh {
        writeln!(
            file,
            "sequence,codec,step,quantiser,quality,bpvf,vertex_rmse"
        )?;
    }
    for input in inputs {
        let mesh = read_animation(input, &ReadOptions::default())?;
        let name = std::path::Path::new(input.trim_end_matches('/'))
            .file_stem()
            .map_or("?".into(), |s| s.to_string_lossy().to_string());
        let base = EncodeOptions {
            predictor: if skinning {
                mcgv_video::PredictorKind::Skinning.into()
            } else {
                mcgv_video::PredictorKind::Affine.into()
            },
            ..EncodeOptions::default()
        };
        let mut runs: Vec<(EncodeOptions, String)> = Vec::new();
        for &q in &tdct {
            let o = EncodeOptions {
                codec: Codec::Tdct.into(),
                quality: q,
                ..base.clone()
            };
            runs.push((o, format!("tdct,,,{q}")));
        }
        for &s in &steps {
            for &j in &jpeg {
                let o = EncodeOptions {
                    codec: CodecConfig::Jpeg(JpegConfig {
                        quality: Some(j),
                        ..JpegConfig::default()
                    }),
                    step: Some(s),
                    ..base.clone()
                };
                runs.push((o, format!("jpeg,{s},{j},")));
            }
            for &q in &qscales {
                let o = EncodeOptions {
                    codec: CodecConfig::Mpeg4(Mpeg4Config {
                        qscale: Some(q),
                        ..Mpeg4Config::default()
                    }),
                    step: Some(s),
                    ..base.clone()
                };
                runs.push((o, format!("mpeg4,{s},{q},")));
            }
        }
        for &s in &hevc_steps {
            for &q in &hevc_qps {
                let o = EncodeOptions {
                    codec: CodecConfig::Hevc(DeepConfig {
                        qp: Some(q),
                        bit_depth,
                        gop: hevc_gop.unwrap_or(mcgv_video::codec::DEFAULT_GOP),
                        ..DeepConfig::default()
                    }),
                    step: Some(s),
                    ..base.clone()
                };
                runs.push((o, format!("hevc,{s},{q},")));
            }
        }
        for (opts, label) in runs {
            let (bpvf, rmse) = measure(&mesh, &opts)?;
            let row = format!("{name},{label},{bpvf:.4},{rmse:.4e}");
            println!("{row}");
            writeln!(file, "{row}")?;
        }
    }
    Ok(())
}
