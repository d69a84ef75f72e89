//! Property tests of the whole pipeline and its coders on awkward meshes: non-manifold edges, several
//! components, degenerate triangles, duplicate and isolated vertices, a single triangle, one frame,
//! a thousand frames of three vertices. Each must encode and decode with its connectivity intact.
//!
//! Case counts are low so that `make test` stays fast; `PROPTEST_CASES=256 cargo test --test
//! hostile_meshes` runs more.

use crate::common::{canonical, config};
use mcgv_video::codec::Codec;
use mcgv_video::encoder::{encode, EncodeOptions};
use mcgv_video::mesh::{AnimatedMesh, Point, Triangle};
use mcgv_video::stream::entropy::{self, BitModel, IntModel, SymbolCoder, SymbolModel, UIntModel};
use mcgv_video::Decoder;
use mcgv_video::{Lattice, PaddingMethod};
use proptest::prelude::*;

/// Cases per property unless `PROPTEST_CASES` says otherwise.
fn cases(default: u32) -> ProptestConfig {
    let n = std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default);
    ProptestConfig::with_cases(n)
}

/// What goes into a random test mesh besides its grids.
#[derive(Debug, Clone)]
struct Oddities {
    /// Three triangles on one edge.
    fin: bool,
    /// Triangles with a repeated corner.
    degenerate: usize,
    /// Vertices that copy another's position, each used by a triangle of its own.
    duplicates: usize,
    /// Vertices no triangle uses.
    isolated: usize,
}

/// `components` small triangulated grids side by side, with the oddities added; frame `f` bends and
/// moves each component differently, so the motion partition has something to find.
fn odd_mesh(grids: &[(usize, usize)], odd: &Oddities, frames: usize, seed: u64) -> AnimatedMesh {
    let mut base: Vec<Point> = Vec::new();
    let mut component: Vec<usize> = Vec::new();
    let mut triangles: Vec<Triangle> = Vec::new();
    for (c, &(nx, ny)) in grids.iter().enumerate() {
        let first = base.len() as u32;
        for j in 0..ny {
            for i in 0..nx {
                base.push([i as f32 + 1.5 * c as f32 * 5.0, j as f32, 0.1 * c as f32]);
                component.push(c);
            }
        }
        for j in 0..ny as u32 - 1 {
            for i in 0..nx as u32 - 1 {
                let v = first + j * nx as u32 + i;
                triangles.push([v, v + 1, v + nx as u32 + 1]);
                triangles.push([v, v + nx as u32 + 1, v + nx as u32]);
            }
        }
    }
    if odd.fin {
        // Vertices 0 and 1 already share an edge with a grid triangle; two more make it non-manifold.
        for k in 0..2 {
            base.push([0.5, -1.0 - k as f32, 0.5 + k as f32]);
            component.push(0);
            triangles.push([0, 1, base.len() as u32 - 1]);
        }
    }
    for k in 0..odd.degenerate {
        let a = (k * 7) as u32 % base.len() as u32;
        let b = (a + 1) % base.len() as u32;
        triangles.push([a, a, b]);
    }
    for k in 0..odd.duplicates {
        let src = (k * 5) % base.len();
        base.push(base[src]);
        component.push(component[src]);
        let d = base.len() as u32 - 1;
        triangles.push([d, ((src + 1) % (base.len() - 1)) as u32, src as u32]);
    }
    for k in 0..odd.isolated {
        base.push([-2.0, k as f32, 1.0]);
        component.push(0);
    }
    let frames = (0..frames)
        .map(|f| {
            let t = f as f32 * 0.15;
            base.iter()
                .zip(&component)
                .enumerate()
                .map(|(i, (p, &c))| {
                    let phase = c as f32 + (seed % 7) as f32 * 0.3;
                    let angle = t * (1.0 + phase * 0.2);
                    let (s, co) = angle.sin_cos();
                    let wobble = 0.02 * ((i as f32 * 1.7 + t * 3.0).sin());
                    [
                        p[0] * co - p[2] * s + t * phase,
                        p[1] + 0.05 * p[0] * t + wobble,
                        p[0] * s + p[2] * co,
                    ]
                })
                .collect()
        })
        .collect();
    AnimatedMesh::new(triangles, frames).expect("test mesh is valid")
}

/// Small-lattice settings that keep one encode well under a second in a debug build (the temporal
/// DCT has no images: it takes only the quality and the clusters).
fn small(codec: Codec) -> EncodeOptions {
    let lattice = Some(Lattice::Fixed(64, 64));
    EncodeOptions {
        codec: config(codec, lattice, Some(PaddingMethod::Cg), Some(3)),
        quality: 90,
        clusters: 3,
        ..EncodeOptions::default()
    }
}

/// Encodes, checks the file decodes to the same connectivity, vertex and frame count, and that
/// every decoded vertex is within `tolerance` of the bounding-box diagonal of where it was.
fn round_trip(mesh: &AnimatedMesh, opts: &EncodeOptions, tolerance: f64) -> Vec<u8> {
    let bytes = encode(mesh, opts)
        .unwrap_or_else(|e| panic!("encode failed: {e}"))
        .container
        .to_bytes();
    let decoded = Decoder::new(&bytes)
        .unwrap_or_else(|e| panic!("decoder refused its own stream: {e}"))
        .decode_all()
        .unwrap();
    assert_eq!(decoded.vertex_count(), mesh.vertex_count());
    assert_eq!(decoded.frame_count(), mesh.frame_count());
    assert_eq!(canonical(decoded.triangles()), canonical(mesh.triangles()));
    let (lo, hi) = mcgv_video::mesh::bounding_box(mesh.frame(0));
    let diagonal = (0..3)
        .map(|k| f64::from(hi[k] - lo[k]).powi(2))
        .sum::<f64>()
        .sqrt()
        .max(1e-9);
    for (f, (a, b)) in mesh.frames().iter().zip(decoded.frames()).enumerate() {
        for (v, (p, q)) in a.iter().zip(b).enumerate() {
            let d = (0..3)
                .map(|k| f64::from(p[k] - q[k]).powi(2))
                .sum::<f64>()
                .sqrt();
            assert!(
                d <= tolerance * diagonal,
                "frame {f} vertex {v} moved {d} (diagonal {diagonal})"
            );
        }
    }
    bytes
}

proptest! {
    #![proptest_config(cases(12))]
    #[test]
    fn odd_meshes_round_trip(
        grids in proptest::collection::vec((2usize..5, 2usize..5), 1..4),
        fin in any::<bool>(),
        degenerate in 0usize..3,
        duplicates in 0usize..3,
        isolated in 0usize..3,
        frames in 1usize..4,
        codec in 0usize..3,
        seed in any::<u64>(),
    ) {
        let odd = Oddities { fin, degenerate, duplicates, isolated };
        let mesh = odd_mesh(&grids, &odd, frames, seed);
        // The temporal DCT's spatial prediction walks the connectivity the decoder rebuilds.
        round_trip(&mesh, &small(Codec::ALL[codec]), 0.05);
    }
}

#[test]
fn a_single_triangle_of_one_frame_round_trips_with_every_codec() {
    let mesh = AnimatedMesh::new(
        vec![[0, 1, 2]],
        vec![vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]],
    )
    .unwrap();
    for codec in Codec::ALL {
        let opts = EncodeOptions {
            clusters: 1,
            ..small(codec)
        };
        round_trip(&mesh, &opts, 0.01);
    }
}

#[test]
fn a_thousand_frames_of_three_vertices_round_trip() {
    let frames: Vec<Vec<Point>> = (0..1000)
        .map(|f| {
            let t = f as f32 * 0.01;
            vec![
                [t.sin(), 0.0, 0.0],
                [1.0 + t, 0.2 * t.cos(), 0.0],
                [0.0, 1.0, 0.3 * (2.0 * t).sin()],
            ]
        })
        .collect();
    let mesh = AnimatedMesh::new(vec![[0, 1, 2]], frames).unwrap();
    for codec in [Codec::Jpeg, Codec::Mpeg4] {
        let lattice = Some(Lattice::Fixed(16, 16));
        let opts = EncodeOptions {
            codec: config(codec, lattice, Some(PaddingMethod::Cg), Some(50)),
            clusters: 1,
            ..small(codec)
        };
        round_trip(&mesh, &opts, 0.05);
    }
    let tdct = EncodeOptions {
        clusters: 1,
        ..small(Codec::Tdct)
    };
    round_trip(&mesh, &tdct, 0.05);
}

/// One coding step of the entropy property test.
#[derive(Debug, Clone)]
enum Op {
    Bit(bool, usize),
    Symbol(usize, usize),
    Unsigned(u64, usize),
    Signed(i64, usize),
    Raw(u64, u32),
}

fn op() -> impl Strategy<Value = Op> {
    prop_oneof![
        (any::<bool>(), 0usize..3).prop_map(|(b, m)| Op::Bit(b, m)),
        (1usize..=256)
            .prop_flat_map(|n| (0..n, Just(n)))
            .prop_map(|(s, n)| Op::Symbol(s, n)),
        (
            prop_oneof![0u64..16, any::<u64>(), Just(u64::MAX)],
            0usize..3
        )
            .prop_map(|(v, m)| Op::Unsigned(v, m)),
        (
            prop_oneof![-16i64..16, any::<i64>(), Just(i64::MIN), Just(i64::MAX)],
            0usize..3
        )
            .prop_map(|(v, m)| Op::Signed(v, m)),
        (0u32..=64)
            .prop_flat_map(|n| (any::<u64>(), Just(n)))
            .prop_map(|(v, n)| Op::Raw(if n == 64 { v } else { v & ((1u64 << n) - 1) }, n)),
    ]
}

/// Runs `ops` through a coder, with three adaptive models of each kind picked by the op, and
/// returns what the coder gave back for each.
fn run_ops<C: SymbolCoder>(c: &mut C, ops: &[Op]) -> mcgv_video::Result<Vec<i128>> {
    let mut bits = vec![BitModel::default(); 3];
    let mut uints = vec![UIntModel::default(); 3];
    let mut ints = vec![IntModel::default(); 3];
    let mut symbols: Vec<(usize, SymbolModel)> = Vec::new();
    let mut out = Vec::with_capacity(ops.len());
    for op in ops {
        out.push(match *op {
            Op::Bit(b, m) => i128::from(c.bit(b, &mut bits[m])?),
            Op::Symbol(s, n) => {
                let model = match symbols.iter_mut().position(|(size, _)| *size == n) {
                    Some(i) => &mut symbols[i].1,
                    None => {
                        symbols.push((n, SymbolModel::new(n)));
                        &mut symbols.last_mut().expect("just pushed").1
                    }
                };
                c.symbol(s, model)? as i128
            }
            Op::Unsigned(v, m) => i128::from(c.unsigned(v, &mut uints[m])?),
            Op::Signed(v, m) => i128::from(c.signed(v, &mut ints[m])?),
            Op::Raw(v, n) => i128::from(c.raw_bits(v, n)?),
        });
    }
    Ok(out)
}

fn expected(ops: &[Op]) -> Vec<i128> {
    ops.iter()
        .map(|op| match *op {
            Op::Bit(b, _) => i128::from(b),
            Op::Symbol(s, _) => s as i128,
            Op::Unsigned(v, _) => i128::from(v),
            Op::Signed(v, _) => i128::from(v),
            Op::Raw(v, _) => i128::from(v),
        })
        .collect()
}

proptest! {
    #![proptest_config(cases(64))]
    #[test]
    fn entropy_coder_round_trips_any_mix(ops in proptest::collection::vec(op(), 0..200)) {
        let mut enc = entropy::Encoder::new();
        let coded = run_ops(&mut enc, &ops).unwrap();
        prop_assert_eq!(&coded, &expected(&ops));
        let bytes = enc.finish().unwrap();
        let mut dec = entropy::Decoder::new(&bytes).unwrap();
        let decoded = run_ops(&mut dec, &ops).unwrap();
        prop_assert_eq!(decoded, expected(&ops));
    }

    #[test]
    fn entropy_decoder_on_garbage_errors_or_stays_in_budget(
        bytes in proptest::collection::vec(any::<u8>(), 0..64),
        ops in proptest::collection::vec(op(), 0..400),
    ) {
        // Whatever it reads, a decoder over garbage must return values of the asked-for kind and
        // never panic; once past its symbol budget it must refuse.
        if let Ok(mut dec) = entropy::Decoder::new(&bytes) {
            if let Ok(values) = run_ops(&mut dec, &ops) {
                for (v, op) in values.iter().zip(&ops) {
                    match *op {
                        Op::Bit(..) => prop_assert!(*v == 0 || *v == 1),
                        Op::Symbol(_, n) => prop_assert!(*v >= 0 && (*v as usize) < n),
                        Op::Raw(_, n) if n < 64 => prop_assert!(*v >= 0 && *v < 1i128 << n),
                        _ => {}
                    }
                }
            }
        }
    }
}
