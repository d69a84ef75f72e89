//! Experiment: for each candidate of tdct's automatic choice, its actual bytes against cheap
//! estimates. `cargo run --release --example choice_estimates -- QUALITY INPUT...`

use mcgv_video::codec::tdct::coefficients::{forward, quantise, BandCoder, Rounding, DEAD_ZONE};
use mcgv_video::codec::tdct::spatial::{Neighbourhood, Spatial};
use mcgv_video::encoder::analysis::{self, Segmenter};
use mcgv_video::encoder::weights_rd::WeightPlan;
use mcgv_video::encoder::{analysis_frames, EncodeOptions};
use mcgv_video::first_frame::{self, FirstFrameOptions};
use mcgv_video::mesh::{read_animation, AnimatedMesh, ReadOptions};
use mcgv_video::stream::side_info;
use std::sync::Arc;
use std::time::Instant;

fn bands_actual(res: &[Vec<[f32; 3]>], tris: &[[u32; 3]], step: f64) -> usize {
    let c = forward(res).unwrap();
    let levels = quantise(&c, step, 0.0).unwrap();
    let mut coder = BandCoder::new(Arc::new(Neighbourhood::new(res[0].len(), tris).unwrap()));
    let mut total = 0;
    for (k, (band, values)) in levels.iter().zip(&c).enumerate() {
        let scaled: Vec<f64> = values.iter().map(|x| x / step).collect();
        let r = Rounding {
            scaled: &scaled,
            lambda: 0.1,
        };
        total += coder
            .encode_rounded(k, band, &r, &Spatial::ALL)
            .unwrap()
            .0
            .len();
    }
    total
}

fn bands_plain(res: &[Vec<[f32; 3]>], tris: &[[u32; 3]], step: f64, modes: &[Spatial]) -> usize {
    let c = forward(res).unwrap();
    let levels = quantise(&c, step, DEAD_ZONE).unwrap();
    let mut coder = BandCoder::new(Arc::new(Neighbourhood::new(res[0].len(), tris).unwrap()));
    let mut total = 0;
    for (k, band) in levels.iter().enumerate() {
        total += coder.encode_among(k, band, modes).unwrap().len();
    }
    total
}

/// Order-0 entropy of min(|level|, 15) per frequency class, escape and sign bits, in bytes.
fn bands_entropy(res: &[Vec<[f32; 3]>], step: f64) -> usize {
    let c = forward(res).unwrap();
    let levels = quantise(&c, step, DEAD_ZONE).unwrap();
    let mut bits = 0.0;
    let classes = 8;
    let mut hist = vec![[0u64; 17]; classes];
    let mut extra = 0.0;
    for (k, band) in levels.iter().enumerate() {
        let class = ((usize::BITS - (k + 1).leading_zeros() - 1) as usize).min(classes - 1);
        for &l in band {
            let m = l.unsigned_abs();
            hist[class][m.min(16) as usize] += 1;
            if m > 0 {
                extra += 1.0;
            }
            if m >= 16 {
                extra += 2.0 * (64 - m.leading_zeros()) as f64;
            }
        }
    }
    for h in &hist {
        let n: u64 = h.iter().sum();
        if n == 0 {
            continue;
        }
        for &c in h {
            if c > 0 {
                bits += c as f64 * -(c as f64 / n as f64).log2();
            }
        }
    }
    ((bits + extra) / 8.0) as usize
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let quality: u8 = args[0].parse().unwrap();
    for input in &args[1..] {
        let full = read_animation(input, &ReadOptions::default()).unwrap();
        let frames = full.frame_count();
        let mesh = if frames > 128 {
            let pick = analysis_frames(frames, 128);
            AnimatedMesh::new(
                full.triangles().to_vec(),
                pick.iter().map(|&f| full.frame(f).to_vec()).collect(),
            )
            .unwrap()
        } else {
            full.clone()
        };
        let opts = EncodeOptions {
            quality,
            ..EncodeOptions::default()
        };
        let plan = opts.plan(mesh.bbox_diagonal()).unwrap();
        let step = f64::from(plan.step);
        let weights = WeightPlan::new(16, plan.affine_precision, plan.codec);
        let ff = first_frame::encode(
            mesh.frame(0),
            mesh.triangles(),
            &FirstFrameOptions {
                bits: 12,
                reorder: false,
            },
        )
        .unwrap();
        let reference = &ff.decoded_positions;
        let tris = mesh.triangles();
        let seg = Segmenter::new(&mesh);
        let name = std::path::Path::new(input.trim_end_matches('/'))
            .file_stem()
            .unwrap()
            .to_string_lossy()
            .to_string();
        for model in opts.motion_models() {
            let (partition, _) = seg.segment(model.segmentation, model.clusters).unwrap();
            let t0 = Instant::now();
            let track =
                analysis::fit_track(&mesh, reference, &partition, plan.affine_step).unwrap();
            let pred = analysis::predict_on(
                &mesh,
                reference,
                &partition,
                weights,
                model.predictor,
                track,
            )
            .unwrap();
            let t_pred = t0.elapsed().as_secs_f64();
            let mut side = side_info::encode_partition(
                partition.labels(),
                partition.clusters(),
                (tris, reference),
            )
            .unwrap()
            .len()
                + side_info::encode_affine(&pred.track).unwrap().len();
            if let Some(w) = &pred.weights {
                side += side_info::encode_weights(w, &partition, (tris, reference))
                    .unwrap()
                    .len();
            }
            let t_side = t0.elapsed().as_secs_f64() - t_pred;
            let t1 = Instant::now();
            let actual = bands_actual(&pred.residuals, tris, step);
            let t_actual = t1.elapsed().as_secs_f64();
            let t1 = Instant::now();
            let plain = bands_plain(&pred.residuals, tris, step, &[Spatial::Mean]);
            let t_plain = t1.elapsed().as_secs_f64();
            let t1 = Instant::now();
            let plain2 = bands_plain(&pred.residuals, tris, step, &Spatial::ALL);
            let t_plain2 = t1.elapsed().as_secs_f64();
            let t1 = Instant::now();
            let ent = bands_entropy(&pred.residuals, step);
            let t_ent = t1.elapsed().as_secs_f64();
            println!("{name},{quality},{},{},{side},{actual},{plain},{plain2},{ent},{t_pred:.3},{t_side:.3},{t_actual:.3},{t_plain:.3},{t_plain2:.3},{t_ent:.3}",
                model.name(), partition.clusters());
        }
    }
}
