//! Segmentation and prediction on real sequences, one row per segmentation method: k-means (K = 20)
//! and decimation (K found from E0 = 0.003). Each row gives K, residual energy against raw motion
//! energy, largest residual and the time of each stage for the piecewise affine predictor, then the
//! skinning predictor fitted to the same partition (follow-up paper eq. 7–10; its per-frame mean and
//! max residual energy against the affine one's, and the bits of its coded weights).
//!
//! `cargo bench --bench motion [-- INPUT ...]` (any input `read_animation` takes); with no arguments,
//! every sequence found under
//! `bench-out/media` (where `make bench` unpacks the OBJ sequences) and `$MCGV_SHARED_MEDIA`
//! (default `../shared/media`), relative to the repository; those missing are skipped. The environment
//! variables `REFINE`, `FEATURE_FRAMES`, `KMEANS_ITERATIONS` and `CLUSTERS` override the matching
//! `SegmentOptions`, `E0` and `DECIMATE_REFINE` decimation's threshold and border refinement rounds,
//! and `SEGMENTATION=kmeans|decimation` runs one method only; `SKIN_RIDGE` and `SKIN_BITS` set the
//! relative ridge and bits per weight of the skinning fits. (A partition's picture: encode, then
//! `mcgv-video inspect STREAM --png DIR` writes `segmentation.png`.)
//! The `E_l` column is decimation's RMS affine-fit error per vertex and frame over the bbox diagonal;
//! `K0` is the K its collapses alone left, before border refinement (NaN and 0 on k-means rows).

use mcgv_video::mesh::{read_animation, ReadOptions};
use mcgv_video::motion::{
    decimate, energy, residuals, segment, AffineTrack, DecimateOptions, Partition, SegmentOptions,
    SkinningWeights, DEFAULT_AFFINE_PRECISION, DEFAULT_RIDGE, MIN_AFFINE_STEP, WEIGHT_BITS,
};
use mcgv_video::stream::side_info::encode_weights;
use mcgv_video::AnimatedMesh;
use std::path::{Path, PathBuf};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .collect();
    let inputs: Vec<PathBuf> = if args.is_empty() {
        default_inputs()
    } else {
        args.iter().map(PathBuf::from).collect()
    };
    println!(
        "{:<22} {:<10} {:>6} {:>5} {:>4} {:>4} {:>8} {:>12} {:>10} {:>11} {:>9} {:>9} {:>12} {:>10} {:>9} {:>9} {:>10} {:>7} {:>7}",
        "sequence",
        "method",
        "V",
        "F",
        "K",
        "K0",
        "E_l",
        "resid/motion",
        "max % diag",
        "quant % diag",
        "segment s",
        "predict s",
        "skin r/m",
        "skin max %",
        "Δmean E_f",
        "Δmax E_f",
        "weight bits",
        "w bpvf",
        "skin s"
    );
    for input in inputs {
        // Sequences are named by their folder: `pdance`, `walking_cat/OBJ` → walking_cat, `…/Fox/headA.glb` → the folder.
        let folder = if input.is_file() || input.ends_with("OBJ") {
            input.parent().unwrap_or(&input)
        } else {
            &input
        };
        let name = folder.file_name().map_or_else(
            || input.display().to_string(),
            |n| n.to_string_lossy().into(),
        );
        let which = std::env::var("SEGMENTATION").unwrap_or_default();
        match load(&input) {
            Ok(mesh) => {
                if which.is_empty() || which == "kmeans" {
                    measure(&name, &mesh, Method::KMeans);
                }
                if which.is_empty() || which == "decimation" {
                    measure(&name, &mesh, Method::Decimation);
                }
            }
            Err(e) => println!("{name:<22} skipped: {e}"),
        }
    }
}

fn default_inputs() -> Vec<PathBuf> {
    let unpacked = Path::new("bench-out/media");
    let mut inputs: Vec<PathBuf> = [
        "chickenCrossing",
        "pcow",
        "pdance",
        "horse-gallop",
        "horse-collapse",
    ]
    .iter()
    .map(|n| unpacked.join(n))
    .collect();
    let shared =
        PathBuf::from(std::env::var_os("MCGV_SHARED_MEDIA").unwrap_or("../shared/media".into()));
    inputs.push(shared.join("walking_cat/OBJ"));
    for glb in [
        "khronos_RiggedSimple/robeA.glb",
        "khronos_RiggedFigure/bodyC.glb",
        "khronos_Fox/headA.glb",
        "khronos_CesiumMan/bodyA.glb",
        "khronos_BrainStem/BrainStem.glb",
        "threejs_Horse/Horse.glb",
        "threejs_Flamingo/Flamingo.glb",
        "threejs_Parrot/Parrot.glb",
        "threejs_Stork/Stork.glb",
    ] {
        inputs.push(shared.join(glb));
    }
    inputs.into_iter().filter(|p| p.exists()).collect()
}

/// A segmentation option overridden from the environment.
fn knob<T: std::str::FromStr>(name: &str) -> Option<T> {
    std::env::var(name).ok().and_then(|v| v.parse().ok())
}

#[derive(Clone, Copy)]
enum Method {
    KMeans,
    Decimation,
}

/// The partition of one method, with decimation's E_l and K before refinement (NaN, 0 for k-means).
fn partition_by(
    mesh: &AnimatedMesh,
    method: Method,
) -> mcgv_video::Result<(Partition, f64, usize)> {
    match method {
        Method::KMeans => {
            let defaults = SegmentOptions::default();
            let opts = SegmentOptions {
                clusters: knob("CLUSTERS").unwrap_or(defaults.clusters),
                refine_passes: knob("REFINE").unwrap_or(defaults.refine_passes),
                feature_frames: knob("FEATURE_FRAMES").unwrap_or(defaults.feature_frames),
                max_iterations: knob("KMEANS_ITERATIONS").unwrap_or(defaults.max_iterations),
                ..defaults
            };
            Ok((segment(mesh, &opts)?, f64::NAN, 0))
        }
        Method::Decimation => {
            let defaults = DecimateOptions::default();
            let opts = DecimateOptions {
                e0: knob("E0").unwrap_or(defaults.e0),
                refine_passes: knob("DECIMATE_REFINE").unwrap_or(defaults.refine_passes),
                ..defaults
            };
            let d = decimate(mesh, &opts)?;
            Ok((d.partition, d.error, d.decimated_clusters))
        }
    }
}

fn measure(name: &str, mesh: &AnimatedMesh, method: Method) {
    let label = match method {
        Method::KMeans => "kmeans",
        Method::Decimation => "decimation",
    };
    let start = Instant::now();
    let (partition, fit_error, plain_k) = match partition_by(mesh, method) {
        Ok(p) => p,
        Err(e) => return println!("{name:<22} {label:<10} segmentation failed: {e}"),
    };
    let segment_time = start.elapsed().as_secs_f64();

    // The reference is the original frame 0: the decoded one is not available to this stage alone.
    let start = Instant::now();
    let reference = mesh.frame(0);
    // The affine step of a default-quality encoding.
    let step = mcgv_video::codec::target_step(mcgv_video::encoder::DEFAULT_QUALITY, 1.0)
        * DEFAULT_AFFINE_PRECISION;
    let track = match AffineTrack::fit(mesh.frames(), reference, &partition, step) {
        Ok(t) => t,
        Err(e) => return println!("{name:<22} {label:<10} prediction failed: {e}"),
    };
    let mut residual_energy = 0.0;
    let mut motion_energy = 0.0;
    let mut largest = 0f64;
    let mut affine_frames = Vec::with_capacity(mesh.frame_count());
    for f in 0..mesh.frame_count() {
        let predicted = track.predict(f, reference, &partition);
        let e = residuals(mesh.frame(f), &predicted);
        affine_frames.push(energy(&e));
        residual_energy += energy(&e);
        motion_energy += energy(&residuals(mesh.frame(f), reference));
        largest = largest.max(longest(&e));
    }
    let predict_time = start.elapsed().as_secs_f64();
    // What quantisation alone costs: the default-quality prediction against a (nearly) unquantised one.
    let quantisation = AffineTrack::fit(mesh.frames(), reference, &partition, MIN_AFFINE_STEP)
        .map_or(f64::NAN, |fine| {
            (0..mesh.frame_count())
                .map(|f| {
                    longest(&residuals(
                        &track.predict(f, reference, &partition),
                        &fine.predict(f, reference, &partition),
                    ))
                })
                .fold(0.0, f64::max)
        });

    // Skinning: weights fitted to the same (quantised) maps, predictions from the quantised weights.
    let start = Instant::now();
    let weights = match SkinningWeights::fit_with(
        mesh.frames(),
        reference,
        &partition,
        mesh.triangles(),
        &track,
        knob("SKIN_RIDGE").unwrap_or(DEFAULT_RIDGE),
        knob("SKIN_BITS").unwrap_or(WEIGHT_BITS),
    ) {
        Ok(w) => w,
        Err(e) => return println!("{name:<22} {label:<10} skinning failed: {e}"),
    };
    let mut skin_frames = Vec::with_capacity(mesh.frame_count());
    let mut skin_largest = 0f64;
    for f in 0..mesh.frame_count() {
        let predicted = match weights.try_predict(f, &track, reference, &partition) {
            Ok(p) => p,
            Err(e) => return println!("{name:<22} {label:<10} skinning failed: {e}"),
        };
        let e = residuals(mesh.frame(f), &predicted);
        skin_frames.push(energy(&e));
        skin_largest = skin_largest.max(longest(&e));
    }
    let skin_time = start.elapsed().as_secs_f64();
    let weight_bits = encode_weights(&weights, &partition, (mesh.triangles(), reference))
        .map_or(f64::NAN, |b| 8.0 * b.len() as f64);
    let mean = |e: &[f64]| e.iter().sum::<f64>() / e.len().max(1) as f64;
    let max = |e: &[f64]| e.iter().copied().fold(0f64, f64::max);
    let change = |skin: f64, affine: f64| 100.0 * (skin / affine.max(f64::MIN_POSITIVE) - 1.0);
    println!(
        "{name:<22} {label:<10} {:>6} {:>5} {:>4} {:>4} {:>8.5} {:>12.4e} {:>10.3} {:>11.5} {:>9.3} {:>9.3} {:>12.5} {:>10.3} {:>8.1}% {:>8.1}% {:>10.0} {:>7.3} {:>7.2}",
        mesh.vertex_count(),
        mesh.frame_count(),
        partition.clusters(),
        plain_k,
        fit_error,
        residual_energy / motion_energy.max(f64::MIN_POSITIVE),
        100.0 * largest / mesh.bbox_diagonal(),
        100.0 * quantisation / mesh.bbox_diagonal(),
        segment_time,
        predict_time,
        skin_frames.iter().sum::<f64>() / motion_energy.max(f64::MIN_POSITIVE),
        100.0 * skin_largest / mesh.bbox_diagonal(),
        change(mean(&skin_frames), mean(&affine_frames)),
        change(max(&skin_frames), max(&affine_frames)),
        weight_bits,
        weight_bits / (mesh.vertex_count() * mesh.frame_count()) as f64,
        skin_time
    );
}

/// The length of the longest residual vector.
fn longest(e: &[[f32; 3]]) -> f64 {
    e.iter()
        .map(|d| d.iter().map(|&c| (c as f64).powi(2)).sum::<f64>().sqrt())
        .fold(0.0, f64::max)
}

fn load(input: &Path) -> mcgv_video::Result<AnimatedMesh> {
    read_animation(&input.to_string_lossy(), &ReadOptions::default())
}
