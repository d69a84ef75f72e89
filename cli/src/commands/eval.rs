//! `mcgv-video eval`: the error measures of one animation against another.

use crate::args::EvalArgs;
use crate::progress;
use mcgv_video::decoder::Decoder;
use mcgv_video::error::{Error, Result};
use mcgv_video::first_frame::{self, FirstFrameOptions};
use mcgv_video::mesh::{AnimatedMesh, ReadOptions};
use mcgv_video::metrics::{compare, Measures};
use std::path::Path;

/// Runs `eval`.
pub fn run(args: &EvalArgs, quiet: bool) -> Result<()> {
    let opts: ReadOptions = (&args.input_args).into();
    let original = super::read_input(&args.original, &opts, quiet)?;
    let measures = if is_mcgv(&args.decoded) {
        let options = super::decode::decode_options(args.bands, args.input_args.max_positions);
        let path = Path::new(&args.decoded);
        let mut decoder =
            Decoder::open_with(path, &options).map_err(|e| super::in_file(path, e))?;
        super::decode::warn_if_truncated(&decoder);
        let bits = decoder.container().file_len() * 8;
        let pb = progress::bar(decoder.header().frames as u64, "decode", quiet);
        let decoded = decoder
            .decode_all_with_progress(&crate::progress::Reporter(&pb))
            .map_err(|e| super::in_file(path, e))?;
        pb.finish_and_clear();
        let decoded = match decoder.header().reorder {
            true => input_order(&original, decoded, decoder.header().first_frame_bits)?,
            false => decoded,
        };
        compare(&original, &decoded)?.with_bits(bits)
    } else {
        if args.bands.is_some() {
            return Err(Error::option(
                "max_bands",
                "applies to a .mcgv stream of codec tdct",
            ));
        }
        compare(&original, &super::read_input(&args.decoded, &opts, quiet)?)?
    };
    if args.json {
        let json = serde_json::to_string(&measures)
            .map_err(|e| Error::Usage(format!("cannot write the measures as JSON: {e}")))?;
        outln!("{json}")
    } else {
        out!("{}", report(&measures))
    }
}

/// A stream encoded with `--reorder` holds its vertices in the first-frame coder's traversal
/// order, and keeps no permutation (that is what saves its bits). The coder is deterministic, so
/// coding the original's first frame again gives the permutation, and the decoded animation is put
/// back in the input order: vertex RMSE and KG error then compare each vertex with itself.
fn input_order(original: &AnimatedMesh, decoded: AnimatedMesh, bits: u8) -> Result<AnimatedMesh> {
    let options = FirstFrameOptions {
        bits,
        reorder: true,
    };
    let coded = first_frame::encode(original.frame(0), original.triangles(), &options)?;
    let Some(permutation) = coded.permutation else {
        return Ok(decoded);
    };
    if permutation.len() != decoded.vertex_count() {
        return Ok(decoded);
    }
    // permutation[new] = old; the decoded mesh is in `new` order, so vertex `old` is at inverse[old].
    let mut inverse = vec![0u32; permutation.len()];
    for (new, &old) in permutation.iter().enumerate() {
        inverse[old as usize] = new as u32;
    }
    decoded.permuted(&inverse)
}

/// Whether a path names a `.mcgv` stream (compared after decoding, with its bpvf).
fn is_mcgv(input: &str) -> bool {
    Path::new(input)
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("mcgv"))
}

/// The human-readable lines `eval` prints.
pub fn report(m: &Measures) -> String {
    let mut s = String::new();
    s.push_str(&format!("vertices     {}\n", m.vertices));
    s.push_str(&format!("frames       {}\n", m.frames));
    s.push_str(&format!(
        "RMSE         {:.6e} of the bbox diagonal = {:.4} ×10⁻⁴\n",
        m.rmse,
        m.rmse * 1e4
    ));
    s.push_str(&format!(
        "Hausdorff    {:.6e} of the bbox diagonal = {:.4} ×10⁻⁴\n",
        m.hausdorff,
        m.hausdorff * 1e4
    ));
    match m.vertex_rmse {
        Some(v) => s.push_str(&format!(
            "vertex RMSE  {v:.6e} of the bbox diagonal = {:.4} ×10⁻⁴\n",
            v * 1e4
        )),
        None => s.push_str("vertex RMSE  n/a (the vertex counts differ)\n"),
    }
    match (m.kg_error, m.vertex_rmse) {
        (Some(kg), _) => s.push_str(&format!("KG error     {kg:.6} %\n")),
        (None, Some(_)) => {
            s.push_str("KG error     n/a (the original never leaves its centroid)\n")
        }
        (None, None) => s.push_str("KG error     n/a (the vertex counts differ)\n"),
    }
    if let Some(b) = m.bpvf {
        s.push_str(&format!("bpvf         {b:.4}\n"));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn report_gives_rmse_as_fraction_and_per_ten_thousand() {
        let m = Measures {
            rmse: 1.5e-4,
            vertex_rmse: None,
            kg_error: None,
            hausdorff: 2e-3,
            bpvf: Some(3.25),
            frames: 10,
            vertices: 100,
            frame_rmse: vec![],
        };
        let r = report(&m);
        assert!(
            r.contains("1.500000e-4") && r.contains("1.5000 ×10⁻⁴"),
            "{r}"
        );
        assert!(r.contains("vertex counts differ") && r.contains("bpvf         3.2500"));
    }

    #[test]
    fn mcgv_streams_are_recognised_by_extension() {
        assert!(!is_mcgv("frames/"));
        assert!(is_mcgv("out.MCGV"));
        assert!(!is_mcgv("walk.glb"));
    }
}
