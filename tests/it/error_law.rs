//! The error law of issue 15: `quality` sets one quantisation step for every frame of every codec;
//! residuals that do not fit the 8-bit pictures at that step are still decoded within it; and
//! streams of the format before it are refused clearly.

use crate::common::{animate, decode_all, decoder, encode_bytes, read_media, tiny_stream, tube};
use mcgv_video::codec::{target_step, Codec};
use mcgv_video::encoder::{EncodeOptions, Segmentation};
use mcgv_video::mesh::AnimatedMesh;
use mcgv_video::metrics::vertex_errors;
use mcgv_video::motion::PredictorKind;

fn image_codecs() -> Vec<Codec> {
    [Codec::Jpeg, Codec::Mpeg4]
        .into_iter()
        .filter(|c| c.available())
        .collect()
}

/// Vertex RMSE / diagonal and the stream, of `mesh` at `quality` (`clusters` motion clusters).
fn error_at(mesh: &AnimatedMesh, codec: Codec, quality: u8, clusters: usize) -> (f64, Vec<u8>) {
    let opts = EncodeOptions {
        codec: codec.into(),
        quality,
        clusters,
        predictor: PredictorKind::Affine.into(),
        segmentation: Segmentation::KMeans.into(),
        ..EncodeOptions::default()
    };
    let bytes = encode_bytes(mesh, &opts);
    let decoded = decode_all(bytes.clone()).expect("decodes");
    let e = vertex_errors(mesh, &decoded).expect("same sizes").rmse / mesh.bbox_diagonal();
    (e, bytes)
}

#[test]
fn a_higher_quality_never_gives_a_higher_error_or_the_same_stream() {
    let mesh = read_media("RiggedFigure.glb");
    for codec in image_codecs().into_iter().chain([Codec::Tdct]) {
        let runs: Vec<(u8, f64, Vec<u8>)> = [10u8, 50, 90]
            .into_iter()
            .map(|q| {
                let (e, bytes) = error_at(&mesh, codec, q, 20);
                (q, e, bytes)
            })
            .collect();
        for pair in runs.windows(2) {
            let ((q0, e0, b0), (q1, e1, b1)) = (&pair[0], &pair[1]);
            assert!(
                e1 < e0,
                "{codec:?}: quality {q1} error {e1:.3e} ≥ {q0}'s {e0:.3e}"
            );
            assert_ne!(
                b0, b1,
                "{codec:?}: qualities {q0} and {q1} give the same stream"
            );
        }
        // The law's error stays near its target step at the default quality.
        let (_, e50, _) = &runs[1];
        assert!(
            *e50 < 2.0 * target_step(50, 1.0),
            "{codec:?}: q50 error {e50:.3e}"
        );
    }
}

/// A bending tube whose vertex `spike` in frame `frame` jumps by `jump` along y.
fn tube_with_spike(spike: usize, frame: usize, jump: f32) -> AnimatedMesh {
    let (mut points, mut tris) = (Vec::new(), Vec::new());
    tube(&mut points, &mut tris, 0.0, 6.0, 24, 16);
    let frames = 12;
    animate(&points, tris, frames, |t, i, p| {
        let bend = 0.3 * t * (p[0] / 6.0).powi(2);
        let wave = 0.02 * (3.0 * p[0] + 6.0 * t).sin();
        let mut q = [p[0], p[1] + bend + wave, p[2]];
        if i == spike && (t * (frames - 1) as f32).round() as usize == frame {
            q[1] += jump;
        }
        q
    })
}

#[test]
fn a_residual_too_big_for_the_pictures_is_corrected_and_spoils_nothing_else() {
    let (spike, frame) = (200, 5);
    let mesh = tube_with_spike(spike, frame, 3.0);
    let diagonal = mesh.bbox_diagonal();
    let step = target_step(50, diagonal);
    for codec in image_codecs() {
        // One cluster: k-means would give the spike a cluster of its own and predict it.
        let (_, bytes) = error_at(&mesh, codec, 50, 1);
        let opened = decoder(bytes.clone()).expect("opens");
        let pictures = opened.describe().and_then(|d| d.pictures);
        let corrections = pictures.expect("an image codec").corrections;
        assert_eq!(corrections[frame], 1, "{codec:?}: the spike is corrected");
        let decoded = decode_all(bytes).expect("decodes");
        let rms = |f: usize, skip: Option<usize>| {
            let (a, b) = (mesh.frame(f), decoded.frame(f));
            let sum: f64 = (0..a.len())
                .filter(|&v| Some(v) != skip)
                .map(|v| {
                    (0..3)
                        .map(|k| f64::from(a[v][k] - b[v][k]).powi(2))
                        .sum::<f64>()
                })
                .sum();
            (sum / a.len() as f64).sqrt()
        };
        for f in 0..mesh.frame_count() {
            let e = rms(f, Some(spike));
            assert!(
                e < 2.0 * step,
                "{codec:?} frame {f}: RMS {e:.3e} (step {step:.3e})"
            );
        }
        let at_spike = (0..3)
            .map(|k| {
                f64::from(mesh.frame(frame)[spike][k] - decoded.frame(frame)[spike][k]).powi(2)
            })
            .sum::<f64>()
            .sqrt();
        assert!(
            at_spike < 2.0 * step,
            "{codec:?}: the spike decodes {at_spike:.3e} away"
        );
    }
}

#[test]
fn a_stream_of_the_format_before_the_error_law_is_refused_clearly() {
    let tdct = EncodeOptions {
        codec: Codec::Tdct.into(),
        clusters: 2,
        ..EncodeOptions::default()
    };
    let streams = [
        tiny_stream(Codec::Jpeg),
        encode_bytes(&tube_with_spike(0, 0, 0.0), &tdct),
    ];
    for mut bytes in streams {
        bytes[8..10].copy_from_slice(&1u16.to_le_bytes());
        let e = decode_all(bytes).unwrap_err().to_string();
        assert!(
            e.contains("older mcgv-video (stream version 1)") && e.contains("re-encode"),
            "{e}"
        );
    }
}
