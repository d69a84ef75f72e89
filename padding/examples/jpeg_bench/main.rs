//! Padding methods compared by what JPEG pays for the padded geometry images.
//!
//! ```text
//! cargo run --release -p padding --example jpeg_bench -- synth [--frames N] [--dump DIR] SEQ_DIR...
//! cargo run --release -p padding --example jpeg_bench -- folder [--per-frame N] DIR...
//! ```
//! `synth` makes images from OBJ sequences (see `synth.rs`); `folder` reads `NAME.png` (16-bit grey)
//! with `NAME_mask.png` (nonzero = fixed) — the entry point for the real encoder's residual images.
//! Prints Markdown tables: (bytes/frame, RMSE on fixed pixels) at JPEG quality 50/75/90, bytes/frame
//! at the error `cg` reaches at those qualities, and padding time per frame.

mod images;
mod measure;
mod synth;

use std::path::PathBuf;

use padding::{EmptyBlocks, Method, PaddingOptions};

use images::Sequence;
use measure::MethodResult;

/// Qualities coded for every image; the reported ones are a subset, the rest support interpolation.
const SWEEP: [u8; 12] = [20, 30, 40, 50, 60, 70, 75, 80, 85, 90, 95, 98];
const REPORTED: [u8; 3] = [50, 75, 90];
const SIDE: usize = 256;

fn main() {
    if let Err(message) = run() {
        eprintln!("jpeg_bench: {message}");
        std::process::exit(1);
    }
}

fn run() -> Result<(), String> {
    let mut args = std::env::args().skip(1);
    let mode = args
        .next()
        .ok_or("usage: jpeg_bench synth|folder [options] DIR...")?;
    let mut frames = 16usize;
    let mut per_frame = 1usize;
    let mut dump: Option<PathBuf> = None;
    let mut dirs = Vec::new();
    while let Some(arg) = args.next() {
        let mut value = || args.next().ok_or(format!("{arg} needs a value"));
        match arg.as_str() {
            "--frames" => frames = value()?.parse().map_err(|e| format!("--frames: {e}"))?,
            "--per-frame" => {
                per_frame = value()?.parse().map_err(|e| format!("--per-frame: {e}"))?
            }
            "--dump" => dump = Some(PathBuf::from(value()?)),
            _ => dirs.push(PathBuf::from(arg)),
        }
    }
    if dirs.is_empty() {
        return Err("no input folder given".into());
    }
    for dir in &dirs {
        let sequence = match mode.as_str() {
            "synth" => synth::from_obj_sequence(dir, frames, SIDE)?,
            "folder" => images::read_folder(dir, per_frame.max(1))?,
            other => return Err(format!("unknown mode {other} (synth or folder)")),
        };
        if let Some(root) = &dump {
            images::write_folder(&sequence, &root.join(&sequence.name))?;
        }
        let mut variants: Vec<(String, PaddingOptions)> = Method::ALL
            .iter()
            .map(|&m| (m.to_string(), PaddingOptions::with_method(m)))
            .collect();
        for (name, empty_blocks) in [
            ("fixed mean", EmptyBlocks::FixedMean),
            ("neighbour mean", EmptyBlocks::NeighbourMean),
        ] {
            for method in [Method::Cg, Method::Biharmonic] {
                variants.push((
                    format!("{method}, empty blocks at {name}"),
                    PaddingOptions {
                        empty_blocks,
                        ..PaddingOptions::with_method(method)
                    },
                ));
            }
        }
        let results = variants
            .iter()
            .map(|(label, options)| measure::run(&sequence, label, options, &SWEEP))
            .collect::<Result<Vec<_>, _>>()?;
        print_tables(&sequence, &results);
    }
    Ok(())
}

fn print_tables(sequence: &Sequence, results: &[MethodResult]) {
    let sweep_index = |q: u8| SWEEP.iter().position(|&s| s == q).unwrap_or(0);
    println!(
        "\n### {} — {:.0} frames × {} images of {}×{}, {:.1} % pixels fixed\n",
        sequence.name,
        sequence.frames(),
        sequence.per_frame,
        sequence.samples.first().map_or(0, |s| s.width),
        sequence.samples.first().map_or(0, |s| s.height),
        100.0 * sequence.fixed_fraction()
    );
    println!("Bytes/frame and RMSE on fixed pixels (grey levels), per JPEG quality:\n");
    print!("| method |");
    REPORTED
        .iter()
        .for_each(|q| print!(" q{q} bytes | q{q} RMSE |"));
    println!(" pad ms/frame | CG iters/system |");
    println!("|---|{}---:|---:|", "---:|---:|".repeat(REPORTED.len()));
    for r in results {
        print!("| {} |", r.label);
        for &q in &REPORTED {
            let p = r.points[sweep_index(q)];
            print!(" {:.0} | {:.3} |", p.bytes_per_frame, p.rmse);
        }
        println!(
            " {:.2} | {:.1}{} |",
            r.pad_ms_per_frame,
            r.cg_iterations_per_system,
            if r.unconverged > 0 {
                format!(" ({} capped)", r.unconverged)
            } else {
                String::new()
            }
        );
    }
    let Some(reference) = results.iter().find(|r| r.label == Method::Cg.name()) else {
        return;
    };
    println!("\nBytes/frame at the RMSE `cg` reaches at q50 / q75 / q90 (log–log interpolation over q {:?}):\n", SWEEP);
    print!("| method |");
    REPORTED.iter().for_each(|q| {
        print!(
            " at cg-q{q} RMSE {:.3} |",
            reference.points[sweep_index(*q)].rmse
        )
    });
    println!(" mean vs cg |");
    println!("|---|{}---:|", "---:|".repeat(REPORTED.len()));
    for r in results {
        print!("| {} |", r.label);
        let mut ratios = Vec::new();
        for &q in &REPORTED {
            let target = reference.points[sweep_index(q)].rmse;
            let (mine, theirs) = (
                measure::bytes_at_error(r, target),
                measure::bytes_at_error(reference, target),
            );
            match mine {
                Some(b) => {
                    print!(" {b:.0} |");
                    if let Some(c) = theirs {
                        ratios.push(b / c);
                    }
                }
                None => print!(" n/a |"),
            }
        }
        if ratios.is_empty() {
            println!(" n/a |");
        } else {
            let mean = ratios.iter().sum::<f64>() / ratios.len() as f64;
            println!(" {:+.1} % |", 100.0 * (mean - 1.0));
        }
    }
}
