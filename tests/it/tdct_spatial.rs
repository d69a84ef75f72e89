//! Spatial prediction of the temporal-DCT levels (issue 18): measurements on the samples.

use crate::cloth::cloth;
use crate::common::{encode_bytes, read_media};
use mcgv_video::codec::tdct::coefficients::{forward, quantise, BandCoder, DEAD_ZONE};
use mcgv_video::codec::tdct::spatial::{Neighbourhood, Spatial};
use mcgv_video::codec::Codec;
use mcgv_video::encoder::analysis::{predict, segment};
use mcgv_video::encoder::weights_rd::WeightPlan;
use mcgv_video::encoder::{EncodeOptions, Segmentation};
use mcgv_video::first_frame::{self, FirstFrameOptions};
use mcgv_video::mesh::AnimatedMesh;
use mcgv_video::metrics::compare;
use mcgv_video::motion::PredictorKind;
use mcgv_video::stream::container::ContainerReader;
use mcgv_video::{DecodeOptions, Decoder};
use std::io::Cursor;
use std::sync::Arc;

/// The temporal-DCT coefficients the encoder computes for `mesh` with `opts` (band-major).
pub fn coefficients_of(mesh: &AnimatedMesh, opts: &EncodeOptions) -> Vec<Vec<f64>> {
    let ff = first_frame::encode(
        mesh.frame(0),
        mesh.triangles(),
        &FirstFrameOptions {
            bits: opts.first_frame_bits_or_default(),
            reorder: false,
        },
    )
    .unwrap();
    let (partition, _) = segment(mesh, Segmentation::KMeans, opts.clusters).unwrap();
    let plan = opts.plan(mesh.bbox_diagonal()).unwrap();
    let weights = WeightPlan::new(opts.weight_bits, plan.affine_precision, plan.codec);
    let steps = (plan.affine_step, weights);
    let residuals = predict(
        mesh,
        &ff.decoded_positions,
        &partition,
        steps,
        PredictorKind::Affine,
    )
    .unwrap()
    .residuals;
    forward(&residuals).unwrap()
}

/// Coefficient bytes with no spatial prediction, the one-ring mean in every band, and the better
/// of the two per band, over a sweep of steps.
/// `cargo test --release --test it measure_spatial -- --ignored --nocapture`.
#[test]
#[ignore = "measurement, not a check"]
fn measure_spatial() {
    let opts = EncodeOptions {
        codec: Codec::Tdct.into(),
        ..EncodeOptions::default()
    };
    let samples = [
        "CesiumMan.glb",
        "Fox.glb",
        "RiggedFigure.glb",
        "RiggedSimple.glb",
    ];
    let meshes = samples.map(|name| (name, read_media(name)));
    for (name, mesh) in meshes.into_iter().chain([("cloth", cloth(40, 90))]) {
        let coefficients = coefficients_of(&mesh, &opts);
        for fraction in [4e-4, 1e-3, 2.5e-3, 5e-3] {
            let levels =
                quantise(&coefficients, mesh.bbox_diagonal() * fraction, DEAD_ZONE).unwrap();
            let none = coefficient_bytes(&mesh, &levels, &[Spatial::None]);
            let mean = coefficient_bytes(&mesh, &levels, &[Spatial::Mean]);
            let best = coefficient_bytes(&mesh, &levels, &Spatial::ALL);
            println!("{name} step {fraction:e}: none {none} mean {mean} best {best} bytes");
        }
    }
}

fn coefficient_bytes(mesh: &AnimatedMesh, levels: &[Vec<i64>], candidates: &[Spatial]) -> usize {
    let neighbourhood = Neighbourhood::new(mesh.vertex_count(), mesh.triangles()).unwrap();
    let mut coder = BandCoder::new(Arc::new(neighbourhood));
    levels
        .iter()
        .enumerate()
        .map(|(k, l)| coder.encode_among(k, l, candidates).unwrap().len())
        .sum()
}

/// On a cloth, the one-ring mean wins bands, and what it codes decodes exactly: whole, band by
/// band and frame by frame.
#[test]
fn spatial_prediction_on_a_cloth_round_trips() {
    let mesh = cloth(24, 32);
    let opts = EncodeOptions {
        codec: Codec::Tdct.into(),
        quality: 50,
        ..EncodeOptions::default()
    };
    let coefficients = coefficients_of(&mesh, &opts);
    let levels = quantise(&coefficients, mesh.bbox_diagonal() * 5e-4, DEAD_ZONE).unwrap();
    let none = coefficient_bytes(&mesh, &levels, &[Spatial::None]);
    let best = coefficient_bytes(&mesh, &levels, &Spatial::ALL);
    assert!(best < none, "{best} bytes with prediction, {none} without");
    let bytes = encode_bytes(&mesh, &opts);
    let open = |bands| {
        let reader = ContainerReader::new(Cursor::new(bytes.clone())).unwrap();
        let options = DecodeOptions {
            max_bands: bands,
            ..DecodeOptions::default()
        };
        Decoder::from_container(reader, &options).unwrap()
    };
    let all = open(None).decode_all().unwrap();
    assert!(compare(&mesh, &all).unwrap().rmse < 1e-3);
    for bands in [None, Some(2)] {
        let whole = open(bands).decode_all().unwrap();
        let mut dec = open(bands);
        for f in [0, 11, 31] {
            for (p, q) in dec.decode_frame(f).unwrap().iter().zip(whole.frame(f)) {
                assert!((0..3).all(|a| (p[a] - q[a]).abs() <= 1e-6), "frame {f}");
            }
        }
    }
}
