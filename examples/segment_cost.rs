//! The bits cost of temporal segments (issue 20): per input, codec and segment length, the stream's
//! bpvf and vertex RMSE (RMS vertex displacement / first frame's bbox diagonal), against the same
//! encoding as one segment. `make bench` runs it on the media sequences; the default
//! `--segment-frames` is the smallest length that costs at most 2 % more bits at equal error.
//!
//! ```text
//! cargo run --release --example segment_cost -- OUT.csv INPUT...
//! ```
//! env (space-separated lists): LENGTHS (segment lengths; default 32 64 128 256), CODECS (default
//! tdct mpeg4), QUALITY (default the encoder's). A length the clip does not exceed is skipped (the
//! stream would be the one-segment stream). "at_equal_error" is the bits ratio moved to the one-
//! segment RMSE along the codecs' measured slope (bits ∝ RMSE^-1/2, as the automatic choice uses).

use mcgv_video::{encode, read_animation, Codec, Decoder, EncodeOptions, ReadOptions};
use std::error::Error;
use std::io::Write;

type Res<T> = Result<T, Box<dyn Error>>;

fn list(var: &str, default: &str) -> Vec<String> {
    std::env::var(var)
        .unwrap_or_else(|_| default.to_string())
        .split_whitespace()
        .map(str::to_string)
        .collect()
}

/// Bytes and vertex RMSE / diagonal of one encoding.
fn measure(mesh: &mcgv_video::AnimatedMesh, opts: &EncodeOptions) -> Res<(usize, f64)> {
    let bytes = encode(mesh, opts)?.to_bytes();
    let decoded = Decoder::new(&bytes)?.decode_all()?;
    let errors = mcgv_video::metrics::vertex_errors(mesh, &decoded).ok_or("size mismatch")?;
    Ok((bytes.len(), errors.rmse / mesh.bbox_diagonal()))
}

fn main() -> Res<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [out, inputs @ ..] = args.as_slice() else {
        return Err("usage: segment_cost OUT.csv INPUT...".into());
    };
    let lengths: Vec<usize> = list("LENGTHS", "32 64 128 256")
        .iter()
        .map(|s| s.parse())
        .collect::<Result<_, _>>()?;
    let quality: Option<u8> = std::env::var("QUALITY")
        .ok()
        .map(|q| q.parse())
        .transpose()?;
    let mut file = std::fs::File::create(out)?;
    writeln!(
        file,
        "input,codec,segment_frames,frames,bytes,vertex_rmse,bytes_ratio,rmse_ratio,at_equal_error"
    )?;
    for input in inputs {
        let mesh = read_animation(input, &ReadOptions::default())?;
        let name = std::path::Path::new(input.trim_end_matches('/'))
            .file_stem()
            .map_or(input.clone(), |s| s.to_string_lossy().into_owned());
        for codec in list("CODECS", "tdct mpeg4") {
            let codec = Codec::ALL
                .into_iter()
                .find(|c| c.name() == codec)
                .ok_or(format!("unknown codec {codec}"))?;
            let opts = |segment_frames| EncodeOptions {
                codec: codec.into(),
                quality: quality.unwrap_or(mcgv_video::encoder::DEFAULT_QUALITY),
                segment_frames,
                ..EncodeOptions::default()
            };
            let (one_bytes, one_rmse) = measure(&mesh, &opts(None))?;
            let mut row = |length: usize, bytes: usize, rmse: f64| {
                let (b, r) = (bytes as f64 / one_bytes as f64, rmse / one_rmse);
                let equal = b * r.sqrt();
                let line = format!(
                    "{name},{},{length},{},{bytes},{rmse:.6e},{b:.4},{r:.4},{equal:.4}",
                    codec.name(),
                    mesh.frame_count()
                );
                eprintln!("{line}");
                writeln!(file, "{line}")
            };
            row(0, one_bytes, one_rmse)?;
            for &length in lengths.iter().filter(|&&n| n < mesh.frame_count()) {
                let (bytes, rmse) = measure(&mesh, &opts(Some(length)))?;
                row(length, bytes, rmse)?;
            }
        }
    }
    Ok(())
}
