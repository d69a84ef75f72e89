//! Measures atlases of real meshes: charts, packing efficiency, moved
//! vertices, L2 stretch and build time, per input.
//!
//! ```text
//! cargo run --release -p atlas --example measure -- [--png DIR] [--jpeg] [--lattice SIDE] INPUT...
//! ```
//! An INPUT is a folder of numbered OBJ frames (the first is used), an `.obj`
//! file or a `.glb` file (all primitives, bind pose, identical positions
//! welded). The partition is a plain k-means (K = 20) on positions, a stand-in
//! for the motion segmentation. With `--jpeg`, both interior modes are coded
//! with JPEG (free pixels filled with the mean, then also with 300 Jacobi
//! smoothing sweeps as a stand-in for padding) for a frame-10 displacement
//! signal, to compare sizes at matching error.
//!
//! The OBJ reader here is minimal (`v` and `f` lines) on purpose: this is a
//! measuring tool; the project's reader lives in the main crate.

use atlas::{build, sample, Atlas, AtlasOptions, Interior};
use std::collections::HashMap;
use std::error::Error;
use std::path::{Path, PathBuf};

type Mesh = (Vec<[f32; 3]>, Vec<[u32; 3]>);

fn read_obj(path: &Path) -> Result<Mesh, Box<dyn Error>> {
    let text = std::fs::read_to_string(path)?;
    let (mut v, mut f) = (Vec::new(), Vec::new());
    for line in text.lines() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => {
                let c: Vec<f32> = it.take(3).map(str::parse).collect::<Result<_, _>>()?;
                v.push([c[0], c[1], c[2]]);
            }
            Some("f") => {
                let n = v.len() as i64;
                let idx: Vec<u32> = it
                    .map(|t| {
                        let i: i64 = t.split('/').next().unwrap_or("0").parse()?;
                        Ok::<u32, Box<dyn Error>>((if i < 0 { n + i } else { i - 1 }) as u32)
                    })
                    .collect::<Result<_, _>>()?;
                for k in 1..idx.len().saturating_sub(1) {
                    f.push([idx[0], idx[k], idx[k + 1]]);
                }
            }
            _ => {}
        }
    }
    Ok((v, f))
}

fn read_glb(path: &Path) -> Result<Mesh, Box<dyn Error>> {
    let (doc, buffers, _) = gltf::import(path)?;
    let (mut v, mut f) = (Vec::new(), Vec::new());
    let mut weld: HashMap<[u32; 3], u32> = HashMap::new();
    for mesh in doc.meshes() {
        for prim in mesh.primitives() {
            let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
            let Some(pos) = reader.read_positions() else {
                continue;
            };
            let map: Vec<u32> = pos
                .map(|p| {
                    let next = v.len() as u32;
                    *weld.entry(p.map(f32::to_bits)).or_insert_with(|| {
                        v.push(p);
                        next
                    })
                })
                .collect();
            let idx: Vec<u32> = match reader.read_indices() {
                Some(i) => i.into_u32().collect(),
                None => (0..map.len() as u32).collect(),
            };
            for t in idx.chunks_exact(3) {
                f.push([map[t[0] as usize], map[t[1] as usize], map[t[2] as usize]]);
            }
        }
    }
    Ok((v, f))
}

/// Numbered OBJ files of a folder, in frame order.
fn obj_frames(dir: &Path) -> Result<Vec<PathBuf>, Box<dyn Error>> {
    let mut files: Vec<(u64, PathBuf)> = std::fs::read_dir(dir)?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "obj"))
        .map(|p| {
            let digits: String = p
                .file_stem()
                .map(|s| {
                    s.to_string_lossy()
                        .chars()
                        .filter(char::is_ascii_digit)
                        .collect()
                })
                .unwrap_or_default();
            (digits.parse().unwrap_or(0), p)
        })
        .collect();
    files.sort();
    Ok(files.into_iter().map(|(_, p)| p).collect())
}

/// Plain k-means: farthest-point seeds, 15 Lloyd steps.
fn kmeans(points: &[[f32; 3]], k: usize) -> Vec<u32> {
    let d2 = |a: [f32; 3], b: [f32; 3]| (0..3).map(|i| (a[i] - b[i]).powi(2)).sum::<f32>();
    let mut centres = vec![points[0]];
    while centres.len() < k.min(points.len()) {
        let far = points
            .iter()
            .max_by(|a, b| {
                let da = centres
                    .iter()
                    .map(|c| d2(**a, *c))
                    .fold(f32::INFINITY, f32::min);
                let db = centres
                    .iter()
                    .map(|c| d2(**b, *c))
                    .fold(f32::INFINITY, f32::min);
                da.total_cmp(&db)
            })
            .copied()
            .unwrap_or(points[0]);
        centres.push(far);
    }
    let mut label = vec![0u32; points.len()];
    for _ in 0..15 {
        for (l, p) in label.iter_mut().zip(points) {
            *l = (0..centres.len())
                .min_by(|&a, &b| d2(*p, centres[a]).total_cmp(&d2(*p, centres[b])))
                .unwrap_or(0) as u32;
        }
        let mut sum = vec![([0.0f64; 3], 0usize); centres.len()];
        for (l, p) in label.iter().zip(points) {
            let s = &mut sum[*l as usize];
            (0..3).for_each(|i| s.0[i] += f64::from(p[i]));
            s.1 += 1;
        }
        for (c, (s, n)) in centres.iter_mut().zip(&sum) {
            if *n > 0 {
                *c = s.map(|x| (x / *n as f64) as f32);
            }
        }
    }
    label
}

/// Free pixels relaxed towards the mean of their 4 neighbours (Jacobi
/// sweeps from the mean): a crude stand-in for the padding crate.
fn smooth_fill(image: &mut [f32], fixed: &[bool], width: usize, sweeps: usize) {
    let height = image.len() / width;
    for _ in 0..sweeps {
        let prev = image.to_vec();
        for y in 0..height {
            for x in 0..width {
                let i = y * width + x;
                if fixed[i] {
                    continue;
                }
                let mut sum = 0.0;
                let mut n = 0.0;
                for (dx, dy) in [(-1i64, 0i64), (1, 0), (0, -1), (0, 1)] {
                    let (nx, ny) = (x as i64 + dx, y as i64 + dy);
                    if nx >= 0 && ny >= 0 && (nx as usize) < width && (ny as usize) < height {
                        sum += prev[ny as usize * width + nx as usize];
                        n += 1.0;
                    }
                }
                image[i] = sum / n;
            }
        }
    }
}

/// JPEG-codes a splatted image (free pixels set to the fixed pixels' mean,
/// then `sweeps` smoothing sweeps) and returns (bytes, vertex RMS error
/// relative to the signal range).
fn jpeg_cost(
    atlas: &Atlas,
    values: &[f32],
    quality: u8,
    sweeps: usize,
) -> Result<(usize, f64), Box<dyn Error>> {
    let mut image = atlas.try_splat(values)?;
    let fixed = atlas.fixed_mask();
    let (lo, hi) = values
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), v| {
            (a.min(*v), b.max(*v))
        });
    let range = (hi - lo).max(1e-12);
    let n_fixed = fixed.iter().filter(|f| **f).count().max(1);
    let mean = image
        .iter()
        .zip(&fixed)
        .filter(|(_, f)| **f)
        .map(|(v, _)| f64::from(*v))
        .sum::<f64>()
        / n_fixed as f64;
    for (v, f) in image.iter_mut().zip(&fixed) {
        if !*f {
            *v = mean as f32;
        }
    }
    smooth_fill(&mut image, &fixed, atlas.width() as usize, sweeps);
    let bytes: Vec<u8> = image
        .iter()
        .map(|v| ((v - lo) / range * 255.0).round().clamp(0.0, 255.0) as u8)
        .collect();
    let mut out = Vec::new();
    let enc = jpeg_encoder::Encoder::new(&mut out, quality);
    enc.encode(
        &bytes,
        atlas.width() as u16,
        atlas.height() as u16,
        jpeg_encoder::ColorType::Luma,
    )?;
    let decoded = image::load_from_memory_with_format(&out, image::ImageFormat::Jpeg)?.to_luma8();
    let back: Vec<f32> = decoded
        .as_raw()
        .iter()
        .map(|b| f32::from(*b) / 255.0 * range + lo)
        .collect();
    let got = sample(atlas.vertex_pixels(), atlas.width(), &back)?;
    let mse = got
        .iter()
        .zip(values)
        .map(|(a, b)| f64::from(a - b).powi(2))
        .sum::<f64>()
        / values.len().max(1) as f64;
    Ok((out.len(), mse.sqrt() / f64::from(range)))
}

/// The command line: flags, then the inputs.
struct Args {
    png_dir: Option<PathBuf>,
    options: AtlasOptions,
    jpeg: bool,
    inputs: Vec<String>,
}

fn parse_args() -> Result<Args, Box<dyn Error>> {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let png_dir = args.iter().position(|a| a == "--png").map(|i| {
        args.remove(i);
        PathBuf::from(args.remove(i))
    });
    let lattice: u32 = match args.iter().position(|a| a == "--lattice") {
        Some(i) => {
            args.remove(i);
            args.remove(i).parse()?
        }
        None => 256,
    };
    let options = AtlasOptions {
        width: lattice,
        height: lattice,
        ..AtlasOptions::default()
    };
    let jpeg = args
        .iter()
        .position(|a| a == "--jpeg")
        .map(|i| args.remove(i))
        .is_some();
    Ok(Args {
        png_dir,
        options,
        jpeg,
        inputs: args,
    })
}

/// The OBJ frames of a folder input (empty for a file) and the mesh of its first frame.
fn read_input(path: &Path) -> Result<(Vec<PathBuf>, Mesh), Box<dyn Error>> {
    Ok(if path.is_dir() {
        let frames = obj_frames(path)?;
        let first = frames.first().ok_or("no OBJ frames")?;
        (frames.clone(), read_obj(first)?)
    } else if path.extension().is_some_and(|e| e == "glb") {
        (Vec::new(), read_glb(path)?)
    } else {
        (Vec::new(), read_obj(path)?)
    })
}

/// One table row: the atlas's figures (and with `ATLAS_DEBUG` set, a line of build details).
fn print_row(name: &str, mesh: &Mesh, atlas: &Atlas) {
    let (positions, triangles) = mesh;
    let s = atlas.stats();
    println!(
        "{name:<22} {:>6} {:>6} {:>6} {:>7.1} {:>7.1} {:>6} {:>6.3} {:>6.2} {:>8.1}",
        positions.len(),
        triangles.len(),
        s.charts,
        100.0 * s.packing_efficiency,
        100.0 * s.block_efficiency,
        s.moved_vertices,
        s.l2_stretch,
        s.max_chart_stretch,
        s.build_time.as_secs_f64() * 1e3
    );
    if std::env::var("ATLAS_DEBUG").is_ok() {
        let mut sizes: Vec<usize> = atlas.charts().iter().map(|c| c.vertices).collect();
        sizes.sort_unstable();
        println!(
            "  seeds {} split rounds {} scale {:.2} faceless {} chart sizes {:?}",
            s.seed_pieces, s.split_rounds, s.scale, s.faceless_vertices, sizes
        );
    }
}

/// `--jpeg`: JPEG sizes and errors of the frame-10 displacement with rasterised and free
/// interiors, per axis, fill and quality.
fn compare_interiors(
    atlas: &Atlas,
    mesh: &Mesh,
    partition: &[u32],
    later: &Path,
) -> Result<(), Box<dyn Error>> {
    let (positions, triangles) = mesh;
    let (moved_pos, _) = read_obj(later)?;
    let free = build(
        positions,
        triangles,
        partition,
        &AtlasOptions {
            interior: Interior::Free,
            ..AtlasOptions::default()
        },
    )?;
    for axis in 0..3 {
        let values: Vec<f32> = moved_pos
            .iter()
            .zip(positions)
            .map(|(a, b)| a[axis] - b[axis])
            .collect();
        for sweeps in [0, 300] {
            for q in [50u8, 75, 90] {
                let (rb, re) = jpeg_cost(atlas, &values, q, sweeps)?;
                let (fb, fe) = jpeg_cost(&free, &values, q, sweeps)?;
                println!("  jpeg axis {axis} fill sweeps {sweeps:>3} q{q}: rasterised {rb:>6} B rmse {re:.4} | free {fb:>6} B rmse {fe:.4}");
            }
        }
    }
    Ok(())
}

fn main() -> Result<(), Box<dyn Error>> {
    let args = parse_args()?;
    println!(
        "{:<22} {:>6} {:>6} {:>6} {:>7} {:>7} {:>6} {:>6} {:>6} {:>8}",
        "input", "V", "F", "charts", "pack%", "block%", "moved", "L2", "maxL2", "ms"
    );
    for input in &args.inputs {
        let path = Path::new(input);
        let (frames, mesh) = read_input(path)?;
        let (positions, triangles) = &mesh;
        let partition = kmeans(positions, 20);
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().to_string())
            .unwrap_or_default();
        let atlas = match build(positions, triangles, &partition, &args.options) {
            Ok(a) => a,
            Err(e) => {
                println!(
                    "{name:<22} {:>6} {:>6} error: {e}",
                    positions.len(),
                    triangles.len()
                );
                continue;
            }
        };
        print_row(&name, &mesh, &atlas);
        if let Some(dir) = &args.png_dir {
            std::fs::create_dir_all(dir)?;
            atlas.write_png(dir.join(format!("{name}.png")))?;
        }
        if let Some(later) = frames.get(10).filter(|_| args.jpeg) {
            compare_interiors(&atlas, &mesh, &partition, later)?;
        }
    }
    Ok(())
}
