//! Behaviour of `padding::pad` through its public API.

use padding::{pad, EmptyBlocks, Method, PaddingError, PaddingOptions};
use proptest::prelude::*;

fn opts(method: Method) -> PaddingOptions {
    PaddingOptions {
        tolerance: 1e-7,
        ..PaddingOptions::with_method(method)
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn fixed_pixels_never_change(
        width in 1usize..30,
        height in 1usize..30,
        seed in any::<u64>(),
        density in 0.0f64..1.0,
        with_previous in any::<bool>(),
    ) {
        let n = width * height;
        let mut state = seed | 1;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let values: Vec<f32> = (0..n).map(|_| (next() * 510.0 - 255.0) as f32).collect();
        let fixed: Vec<bool> = (0..n).map(|_| next() < density).collect();
        let previous: Vec<f32> = (0..n).map(|_| (next() * 100.0) as f32).collect();
        let empty_fills = [EmptyBlocks::RasterPrevious, EmptyBlocks::FixedMean, EmptyBlocks::NeighbourMean];
        for (method, empty_blocks) in Method::ALL.into_iter().flat_map(|m| empty_fills.map(|e| (m, e))) {
            let mut image = values.clone();
            let prev = with_previous.then_some(previous.as_slice());
            let options = PaddingOptions { empty_blocks, ..opts(method) };
            pad(&mut image, width, height, &fixed, prev, &options).unwrap();
            for i in 0..n {
                prop_assert!(image[i].is_finite(), "{method}: pixel {i} not finite");
                if fixed[i] {
                    prop_assert_eq!(image[i].to_bits(), values[i].to_bits(), "{} moved pixel {}", method, i);
                }
            }
        }
    }
}

/// The eq. 6 system of one block, built densely and solved by Gaussian elimination with partial pivoting.
fn dense_block_laplace(values: &[f64], fixed: &[bool], w: usize, h: usize) -> Vec<f64> {
    let free: Vec<usize> = (0..w * h).filter(|&i| !fixed[i]).collect();
    let index_of = |i: usize| free.iter().position(|&f| f == i);
    let n = free.len();
    let mut a = vec![vec![0.0; n + 1]; n];
    for (row, &p) in free.iter().enumerate() {
        let (x, y) = ((p % w) as i64, (p / w) as i64);
        for dy in -1..=1i64 {
            for dx in -1..=1i64 {
                let (nx, ny) = (x + dx, y + dy);
                if (dx, dy) == (0, 0) || nx < 0 || ny < 0 || nx >= w as i64 || ny >= h as i64 {
                    continue;
                }
                let q = (ny as usize) * w + nx as usize;
                a[row][row] += 1.0;
                match index_of(q) {
                    Some(col) => a[row][col] -= 1.0,
                    None => a[row][n] += values[q],
                }
            }
        }
    }
    for col in 0..n {
        let pivot = (col..n)
            .max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))
            .unwrap();
        a.swap(col, pivot);
        let pivot_row = a[col].clone();
        for (row, r) in a.iter_mut().enumerate() {
            if row != col {
                let factor = r[col] / pivot_row[col];
                for (v, p) in r.iter_mut().zip(&pivot_row).skip(col) {
                    *v -= factor * p;
                }
            }
        }
    }
    let mut out = values.to_vec();
    for (row, &p) in free.iter().enumerate() {
        out[p] = a[row][n] / a[row][row];
    }
    out
}

#[test]
fn cg_matches_a_dense_solve_on_small_blocks() {
    // One block per image (image size ≤ block size), several shapes and masks, deterministic.
    let cases: [(usize, usize, u32); 5] = [(8, 8, 3), (8, 8, 11), (5, 7, 2), (3, 3, 5), (8, 8, 29)];
    for (w, h, stride) in cases {
        let values: Vec<f64> = (0..w * h)
            .map(|i| ((i as u32).wrapping_mul(2654435761) % 1000) as f64 / 7.0)
            .collect();
        let fixed: Vec<bool> = (0..w * h)
            .map(|i| (i as u32 * 7 + 1) % stride == 0)
            .collect();
        assert!(fixed.iter().any(|&f| f) && fixed.iter().any(|&f| !f));
        let expected = dense_block_laplace(&values, &fixed, w, h);
        let mut image: Vec<f32> = values.iter().map(|&v| v as f32).collect();
        pad(&mut image, w, h, &fixed, None, &opts(Method::Cg)).unwrap();
        for i in 0..w * h {
            assert!(
                (f64::from(image[i]) - expected[i]).abs() < 1e-3,
                "{w}x{h} stride {stride}: pixel {i}: cg {} vs dense {}",
                image[i],
                expected[i]
            );
        }
    }
}

#[test]
fn per_block_solves_are_independent() {
    // Two 8x8 blocks side by side: each block's answer equals its own dense solve.
    let (w, h) = (16, 8);
    let values: Vec<f64> = (0..w * h).map(|i| ((i * 37) % 101) as f64).collect();
    let fixed: Vec<bool> = (0..w * h).map(|i| i % 5 == 0).collect();
    let mut image: Vec<f32> = values.iter().map(|&v| v as f32).collect();
    pad(&mut image, w, h, &fixed, None, &opts(Method::Cg)).unwrap();
    for bx in 0..2 {
        let block_values: Vec<f64> = (0..64)
            .map(|i| values[(i / 8) * w + bx * 8 + i % 8])
            .collect();
        let block_fixed: Vec<bool> = (0..64)
            .map(|i| fixed[(i / 8) * w + bx * 8 + i % 8])
            .collect();
        let expected = dense_block_laplace(&block_values, &block_fixed, 8, 8);
        for i in 0..64 {
            let got = image[(i / 8) * w + bx * 8 + i % 8];
            assert!(
                (f64::from(got) - expected[i]).abs() < 1e-3,
                "block {bx} pixel {i}"
            );
        }
    }
}

#[test]
fn all_fixed_is_untouched() {
    let values: Vec<f32> = (0..64).map(|i| i as f32 * 1.5).collect();
    for method in Method::ALL {
        let mut image = values.clone();
        pad(&mut image, 8, 8, &[true; 64], None, &opts(method)).unwrap();
        assert_eq!(image, values, "{method}");
    }
}

#[test]
fn nothing_fixed_gives_zero_or_the_previous_frame() {
    let previous: Vec<f32> = (0..100).map(|i| i as f32).collect();
    for method in Method::ALL {
        let mut image = vec![7.0f32; 100];
        pad(&mut image, 10, 10, &[false; 100], None, &opts(method)).unwrap();
        assert!(image.iter().all(|&v| v == 0.0), "{method}");
        let mut image = vec![7.0f32; 100];
        pad(
            &mut image,
            10,
            10,
            &[false; 100],
            Some(&previous),
            &opts(method),
        )
        .unwrap();
        assert_eq!(image, previous, "{method}");
    }
}

#[test]
fn a_single_fixed_pixel_spreads_everywhere() {
    for method in Method::ALL {
        let mut image = vec![0.0f32; 24 * 16];
        let mut fixed = vec![false; 24 * 16];
        image[5 * 24 + 3] = 42.0;
        fixed[5 * 24 + 3] = true;
        pad(&mut image, 24, 16, &fixed, None, &opts(method)).unwrap();
        assert!(
            image.iter().all(|&v| (v - 42.0).abs() < 1e-3),
            "{method}: {:?}",
            image.iter().find(|&&v| (v - 42.0).abs() >= 1e-3)
        );
    }
}

#[test]
fn p_frames_copy_previous_into_empty_blocks_only() {
    let (w, h) = (16, 8);
    let mut fixed = vec![false; w * h];
    fixed[3 * w + 2] = true;
    let previous: Vec<f32> = (0..w * h).map(|i| i as f32).collect();
    for method in Method::ALL {
        let mut image = vec![0.0f32; w * h];
        image[3 * w + 2] = -5.0;
        pad(&mut image, w, h, &fixed, Some(&previous), &opts(method)).unwrap();
        for y in 0..h {
            for x in 8..16 {
                assert_eq!(image[y * w + x], previous[y * w + x], "{method}");
            }
        }
        assert_eq!(image[3 * w + 2], -5.0);
    }
}

#[test]
fn intra_empty_blocks_are_flat_at_the_neighbours_border_mean() {
    // Left block fully fixed with column value = x; right block empty: it gets the mean of column 7.
    let (w, h) = (16, 8);
    let mut image = vec![0.0f32; w * h];
    let mut fixed = vec![false; w * h];
    for y in 0..h {
        for x in 0..8 {
            image[y * w + x] = x as f32;
            fixed[y * w + x] = true;
        }
    }
    for method in [
        Method::Cg,
        Method::Mean,
        Method::DctEnergy,
        Method::Biharmonic,
    ] {
        let mut padded = image.clone();
        let options = PaddingOptions {
            empty_blocks: EmptyBlocks::NeighbourMean,
            ..opts(method)
        };
        pad(&mut padded, w, h, &fixed, None, &options).unwrap();
        for y in 0..h {
            for x in 8..16 {
                assert_eq!(padded[y * w + x], 7.0, "{method}");
            }
        }
    }
}

#[test]
fn bad_inputs_are_errors_not_panics() {
    let o = PaddingOptions::default();
    let mut image = vec![0.0f32; 12];
    assert!(matches!(
        pad(&mut image, 0, 12, &[false; 12], None, &o),
        Err(PaddingError::EmptyImage { .. })
    ));
    assert!(matches!(
        pad(&mut image, 3, 5, &[false; 15], None, &o),
        Err(PaddingError::SizeMismatch { what: "image", .. })
    ));
    assert!(matches!(
        pad(&mut image, 3, 4, &[false; 11], None, &o),
        Err(PaddingError::SizeMismatch { what: "mask", .. })
    ));
    assert!(matches!(
        pad(&mut image, 3, 4, &[false; 12], Some(&[0.0; 3]), &o),
        Err(PaddingError::SizeMismatch {
            what: "previous",
            ..
        })
    ));
    assert!(matches!(
        pad(&mut image, usize::MAX, 3, &[false; 12], None, &o),
        Err(PaddingError::EmptyImage { .. })
    ));
    let zero_block = PaddingOptions {
        block: 0,
        ..o.clone()
    };
    assert!(matches!(
        pad(&mut image, 3, 4, &[false; 12], None, &zero_block),
        Err(PaddingError::BadBlock { .. })
    ));
    for method in [Method::DctEnergy, Method::Biharmonic] {
        let dct16 = PaddingOptions {
            block: 16,
            ..PaddingOptions::with_method(method)
        };
        assert!(matches!(
            pad(&mut image, 3, 4, &[false; 12], None, &dct16),
            Err(PaddingError::BadBlock { .. })
        ));
    }
    image[5] = f32::NAN;
    let mut fixed = [false; 12];
    fixed[5] = true;
    assert!(matches!(
        pad(&mut image, 3, 4, &fixed, None, &o),
        Err(PaddingError::NonFinite { index: 5, .. })
    ));
}

#[test]
fn method_names_round_trip() {
    for method in Method::ALL {
        assert_eq!(method.to_string().parse::<Method>().unwrap(), method);
    }
    assert_eq!("Zero".parse::<Method>().unwrap(), Method::MidGrey);
    assert_eq!("push-pull".parse::<Method>().unwrap(), Method::PushPull);
    assert!(matches!(
        "bogus".parse::<Method>(),
        Err(PaddingError::UnknownMethod(_))
    ));
}

#[test]
fn smooth_methods_reproduce_a_linear_ramp() {
    // A linear ramp in x has zero Laplacian, so per-block and whole-image ψ minimisers that see
    // the ramp on each block's edge columns reproduce it inside.
    let (w, h) = (16, 16);
    let ramp: Vec<f32> = (0..w * h).map(|i| (i % w) as f32 * 3.0).collect();
    let fixed: Vec<bool> = (0..w * h).map(|i| i % 8 == 0 || i % 8 == 7).collect();
    for method in [Method::Cg, Method::Laplace] {
        let mut image: Vec<f32> = ramp
            .iter()
            .zip(&fixed)
            .map(|(&v, &f)| if f { v } else { -99.0 })
            .collect();
        pad(&mut image, w, h, &fixed, None, &opts(method)).unwrap();
        for i in 0..w * h {
            assert!(
                (image[i] - ramp[i]).abs() < 1e-2,
                "{method} pixel {i}: {} vs {}",
                image[i],
                ramp[i]
            );
        }
    }
}

/// w(u, v) of the DCT coefficient in row u, column v.
type CoefficientWeight<'a> = dyn Fn(usize, usize) -> f64 + 'a;

/// Σ_{k≠0} w_k c_k² of an 8×8 block, with a textbook (slow) orthonormal DCT.
fn weighted_ac_energy(block: &[f64], weight: impl Fn(usize, usize) -> f64) -> f64 {
    let alpha = |k: usize| {
        if k == 0 {
            (1.0f64 / 8.0).sqrt()
        } else {
            (2.0f64 / 8.0).sqrt()
        }
    };
    let mut energy = 0.0;
    for u in 0..8 {
        for v in 0..8 {
            if (u, v) == (0, 0) {
                continue;
            }
            let mut c = 0.0;
            for y in 0..8 {
                for x in 0..8 {
                    c += block[y * 8 + x]
                        * (std::f64::consts::PI * (2 * y + 1) as f64 * u as f64 / 16.0).cos()
                        * (std::f64::consts::PI * (2 * x + 1) as f64 * v as f64 / 16.0).cos();
                }
            }
            energy += weight(u, v) * (alpha(u) * alpha(v) * c).powi(2);
        }
    }
    energy
}

#[test]
fn dct_methods_reach_their_energy_minimum() {
    const ANNEX_K: [f64; 64] = [
        16., 11., 10., 16., 24., 40., 51., 61., 12., 12., 14., 19., 26., 58., 60., 55., 14., 13.,
        16., 24., 40., 57., 69., 56., 14., 17., 22., 29., 51., 87., 80., 62., 18., 22., 37., 56.,
        68., 109., 103., 77., 24., 35., 55., 64., 81., 104., 113., 92., 49., 64., 78., 87., 103.,
        121., 120., 101., 72., 92., 95., 98., 112., 100., 103., 99.,
    ];
    let lambda = |k: usize| 2.0 - 2.0 * (std::f64::consts::PI * k as f64 / 8.0).cos();
    let values: Vec<f32> = (0..64).map(|i| ((i * 53) % 97) as f32).collect();
    let fixed: Vec<bool> = (0..64).map(|i| (i * 5 + 2) % 7 < 3).collect();
    let cases: [(Method, &CoefficientWeight<'_>); 2] = [
        (Method::DctEnergy, &|u, v| ANNEX_K[u * 8 + v].powi(-2)),
        (Method::Biharmonic, &|u, v| (lambda(u) + lambda(v)).powi(2)),
    ];
    for (method, weight) in cases {
        let mut image = values.clone();
        pad(&mut image, 8, 8, &fixed, None, &opts(method)).unwrap();
        let block: Vec<f64> = image.iter().map(|&v| f64::from(v)).collect();
        let best = weighted_ac_energy(&block, weight);
        for i in (0..64).filter(|&i| !fixed[i]) {
            for step in [-0.05, 0.05] {
                let mut moved = block.clone();
                moved[i] += step;
                assert!(
                    weighted_ac_energy(&moved, weight) >= best * (1.0 - 1e-9),
                    "{method}: moving pixel {i} by {step} lowers the energy"
                );
            }
        }
    }
}

#[test]
fn empty_blocks_can_take_the_fixed_mean_instead() {
    // Left block fully fixed with column value = x (mean 3.5); the empty right block gets 3.5.
    let (w, h) = (16, 8);
    let image: Vec<f32> = (0..w * h)
        .map(|i| if i % w < 8 { (i % w) as f32 } else { 0.0 })
        .collect();
    let fixed: Vec<bool> = (0..w * h).map(|i| i % w < 8).collect();
    let options = PaddingOptions {
        empty_blocks: EmptyBlocks::FixedMean,
        ..opts(Method::Biharmonic)
    };
    let mut padded = image.clone();
    pad(&mut padded, w, h, &fixed, None, &options).unwrap();
    for i in (0..w * h).filter(|i| i % w >= 8) {
        assert_eq!(padded[i], 3.5);
    }
}

#[test]
fn empty_blocks_by_default_repeat_the_previous_block_in_raster_order() {
    // Blocks: [empty, fixed at 10 | empty, empty]: the first empty block precedes any filled one
    // and takes the fixed mean (10); the second row's blocks follow the fixed block and take its mean.
    let (w, h) = (16, 16);
    let fixed: Vec<bool> = (0..w * h).map(|i| i % w >= 8 && i / w < 8).collect();
    let image: Vec<f32> = fixed.iter().map(|&f| if f { 10.0 } else { 0.0 }).collect();
    for method in [Method::Cg, Method::Biharmonic] {
        let mut padded = image.clone();
        pad(&mut padded, w, h, &fixed, None, &opts(method)).unwrap();
        assert!(padded.iter().all(|&v| v == 10.0), "{method}");
    }
    // A ramp block: the following empty block takes the ramp block's mean, 3.5.
    let (w, h) = (16, 8);
    let fixed: Vec<bool> = (0..w * h).map(|i| i % w < 8).collect();
    let image: Vec<f32> = (0..w * h)
        .map(|i| if i % w < 8 { (i % w) as f32 } else { 0.0 })
        .collect();
    let mut padded = image.clone();
    pad(&mut padded, w, h, &fixed, None, &opts(Method::Biharmonic)).unwrap();
    assert!((0..w * h).filter(|i| i % w >= 8).all(|i| padded[i] == 3.5));
}

#[test]
fn snap_leaves_less_energy_in_the_coefficients_jpeg_drops() {
    // Annex K at quality 75 (libjpeg scaling: 200 − 2q = 50 %).
    const ANNEX_K: [f64; 64] = [
        16., 11., 10., 16., 24., 40., 51., 61., 12., 12., 14., 19., 26., 58., 60., 55., 14., 13.,
        16., 24., 40., 57., 69., 56., 14., 17., 22., 29., 51., 87., 80., 62., 18., 22., 37., 56.,
        68., 109., 103., 77., 24., 35., 55., 64., 81., 104., 113., 92., 49., 64., 78., 87., 103.,
        121., 120., 101., 72., 92., 95., 98., 112., 100., 103., 99.,
    ];
    let step = |u: usize, v: usize| ((ANNEX_K[u * 8 + v] * 50.0 + 50.0) / 100.0).floor();
    let values: Vec<f32> = (0..64)
        .map(|i| ((i * 53) % 97) as f32 + (i / 8) as f32 * 9.0)
        .collect();
    let fixed: Vec<bool> = (0..64).map(|i| (i % 8) < 4 && (i / 8) < 5).collect();
    let dropped = |method: Method| {
        let mut image = values.clone();
        let options = PaddingOptions {
            jpeg_quality: 75,
            ..opts(method)
        };
        pad(&mut image, 8, 8, &fixed, None, &options).unwrap();
        let block: Vec<f64> = image.iter().map(|&v| f64::from(v)).collect();
        // Energy of the coefficients the quantiser zeroes: the weight keeps a coefficient only if it
        // is under half its step, so each coefficient is tested on its own.
        let mut total = 0.0;
        for u in 0..8 {
            for v in 0..8 {
                let only = |a: usize, b: usize| if (a, b) == (u, v) { 1.0 } else { 0.0 };
                let c2 = weighted_ac_energy(&block, only);
                if (u, v) != (0, 0) && c2.sqrt() < 0.5 * step(u, v) {
                    total += c2;
                }
            }
        }
        total
    };
    let (snap, biharmonic) = (dropped(Method::Snap), dropped(Method::Biharmonic));
    assert!(
        snap < 0.5 * biharmonic,
        "snap {snap} vs biharmonic {biharmonic}"
    );
}
