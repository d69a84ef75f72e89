//! Per-block padding as a weighted energy of the block's 2-D DCT coefficients c = D·b:
//! E = Σ_{k≠0} w_k c_k², fixed pixels held. Two weightings (see [`Weighting`]):
//!
//! - quantiser: w_k = 1/Q_k² with JPEG's Annex K table, i.e. the energy of what the codec rounds.
//!   JPEG's quality scales the table uniformly (up to rounding), which leaves the minimiser unchanged.
//!   It loses (measured): high frequencies weigh little, so the padding fills them, JPEG drops them,
//!   and what is dropped lands as error on the fixed pixels too.
//! - biharmonic: w_k = λ_k², λ_k the eigenvalues of the block's 4-connected Neumann Laplacian,
//!   which the DCT-II diagonalises, so E = ‖Δb‖². Where the paper's ψ (≈ Σ λ_k c_k²) gives a
//!   harmonic fill with kinks at the chart border, this continues the chart's gradient, and JPEG
//!   spends fewer high-frequency coefficients on it (the measured winner).
//!
//! `snap` follows the biharmonic solve with 30 rounds of: DCT, zero the AC coefficients JPEG's
//! quantiser at the target quality would round to 0 (|c_k| < Q_k/2), inverse DCT, put the fixed pixels
//! back. The coefficients JPEG will drop are then ~0 already, so dropping them moves little error onto
//! the fixed pixels (alternating projections; more rounds gain next to nothing: README.md, "Methods").
//!
//! With b = P·x + f (x the free pixels, f the fixed ones), E is minimised by
//! Pᵀ DᵀWD P x = −Pᵀ DᵀWD f, an SPD system solved by CG: W ≥ 0 with only DC unweighted and D
//! orthogonal, so a null vector would be a constant block that is 0 on the fixed pixels. Pixels of a
//! block lying outside the image are treated as free.

use crate::block_operator::BlockOperator;
use crate::cg::{self, CgLimits, CgScratch};
use crate::grid::{BlockGrid, BlockRect};
use crate::PadStats;

/// The block side this method works on (JPEG's DCT size).
pub(crate) const SIDE: usize = 8;
const N: usize = SIDE * SIDE;

/// ITU-T T.81 Annex K luminance quantisation table, row-major.
const ANNEX_K_LUMA: [f64; N] = [
    16., 11., 10., 16., 24., 40., 51., 61., 12., 12., 14., 19., 26., 58., 60., 55., 14., 13., 16.,
    24., 40., 57., 69., 56., 14., 17., 22., 29., 51., 87., 80., 62., 18., 22., 37., 56., 68., 109.,
    103., 77., 24., 35., 55., 64., 81., 104., 113., 92., 49., 64., 78., 87., 103., 121., 120.,
    101., 72., 92., 95., 98., 112., 100., 103., 99.,
];

/// Orthonormal DCT-II basis and weights, plus per-block work space.
#[derive(Debug)]
pub(crate) struct DctEnergy {
    basis: Basis,
    weight: [f64; N],
    /// JPEG quantiser steps (orthonormal-DCT units, equal to JPEG's table entries) at the target
    /// quality, when the solve is followed by snapping to what the quantiser keeps.
    snap_steps: Option<[f64; N]>,
    unknowns: Vec<usize>,
    rhs: Vec<f64>,
    x: Vec<f64>,
    scratch: CgScratch,
}

/// Which weights w_k the block energy Σ w_k c_k² uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Weighting {
    /// w_k = 1 / Q_k² (Annex K luminance table): the energy of what the codec quantises.
    Quantiser,
    /// w_k = λ_k², λ_k the eigenvalue of the block's 4-connected Neumann Laplacian that the DCT
    /// basis function k diagonalises: ‖Δb‖², a thin-plate (biharmonic) smoothness in the block.
    Biharmonic,
}

impl DctEnergy {
    pub fn new(weighting: Weighting) -> Self {
        let mut basis = [0.0; N];
        for k in 0..SIDE {
            let alpha = if k == 0 {
                (1.0 / SIDE as f64).sqrt()
            } else {
                (2.0 / SIDE as f64).sqrt()
            };
            for n in 0..SIDE {
                basis[k * SIDE + n] = alpha
                    * (std::f64::consts::PI * (2 * n + 1) as f64 * k as f64 / (2 * SIDE) as f64)
                        .cos();
            }
        }
        let mut weight: [f64; N] = std::array::from_fn(|k| match weighting {
            Weighting::Quantiser => 1.0 / (ANNEX_K_LUMA[k] * ANNEX_K_LUMA[k]),
            Weighting::Biharmonic => {
                let step = std::f64::consts::PI / SIDE as f64;
                let (u, v) = ((k / SIDE) as f64, (k % SIDE) as f64);
                let lambda = (2.0 - 2.0 * (step * u).cos()) + (2.0 - 2.0 * (step * v).cos());
                lambda * lambda
            }
        });
        // DC is coded as a difference from the previous block's DC, so its size is not its cost;
        // weighting it would drag padded values towards 0. With DC free, a single fixed pixel still
        // pins the system: a nonzero free-pixel vector with only a DC component would be a constant
        // block that is 0 on the fixed pixels.
        weight[0] = 0.0;
        DctEnergy {
            basis: Basis::new(basis),
            weight,
            snap_steps: None,
            unknowns: Vec::new(),
            rhs: Vec::new(),
            x: Vec::new(),
            scratch: CgScratch::default(),
        }
    }
}

impl DctEnergy {
    /// After each solve, alternate (SNAP_ROUNDS times) between the JPEG quantiser at `quality`
    /// (`table` scaled as libjpeg does) and putting the fixed pixels back.
    pub fn with_snap(mut self, quality: u8, table: crate::JpegTable) -> Self {
        let quality = u32::from(quality.clamp(1, 100));
        let scale = if quality < 50 {
            5000 / quality
        } else {
            200 - quality * 2
        };
        let base = match table {
            crate::JpegTable::AnnexK => ANNEX_K_LUMA,
            crate::JpegTable::Flat => [16.0; N],
        };
        self.snap_steps = Some(base.map(|t| {
            ((t * scale as f64 + 50.0) / 100.0)
                .floor()
                .clamp(1.0, 255.0)
        }));
        self
    }

    /// The energy's matrix DᵀWD (row-major N × N): column j is the operator applied to pixel j's
    /// unit block.
    pub fn energy_matrix(&self) -> Vec<f64> {
        let mut matrix = vec![0.0; N * N];
        for j in 0..N {
            let mut unit = [0.0; N];
            unit[j] = 1.0;
            let mut column = [0.0; N];
            apply_energy(&self.basis, &self.weight, &unit, &mut column);
            for (i, &v) in column.iter().enumerate() {
                matrix[i * N + j] = v;
            }
        }
        matrix
    }

    /// Pads the free pixels of one block that holds at least one fixed pixel: by `operator`, the
    /// block mask's minimiser, when there is one, else by CG.
    #[allow(clippy::too_many_arguments)]
    pub fn pad_block(
        &mut self,
        grid: &BlockGrid,
        rect: BlockRect,
        image: &mut [f32],
        fixed: &[bool],
        operator: Option<&BlockOperator>,
        limits: CgLimits,
        stats: &mut PadStats,
    ) {
        let Some(known) = self.gather(grid.width, rect, image, fixed) else {
            return;
        };
        match operator {
            Some(operator) => {
                debug_assert!(operator.free().eq(self.unknowns.iter().copied()));
                operator.apply(&known.values, &mut self.x);
                stats.direct += 1;
            }
            None => stats.record(self.solve(&known, limits)),
        }
        if let Some(steps) = self.snap_steps {
            self.snap(&known, &steps);
        }
        for (&u, &value) in self.unknowns.iter().zip(&self.x) {
            let (x, y) = (u % SIDE, u / SIDE);
            if x < rect.w && y < rect.h && !known.is_fixed[u] {
                image[(rect.y0 + y) * grid.width + rect.x0 + x] = value as f32;
            }
        }
    }

    /// Reads the block's fixed pixels and lists the others (and those outside the image) as
    /// unknowns; `None` when the block has no fixed pixel or no free one.
    fn gather(
        &mut self,
        width: usize,
        rect: BlockRect,
        image: &[f32],
        fixed: &[bool],
    ) -> Option<Known> {
        let mut known = Known {
            values: [0.0; N],
            is_fixed: [false; N],
            mean: 0.0,
        };
        let mut fixed_sum = 0.0;
        let mut fixed_count = 0usize;
        self.unknowns.clear();
        for y in 0..SIDE {
            for x in 0..SIDE {
                let local = y * SIDE + x;
                let inside = x < rect.w && y < rect.h;
                let pixel = (rect.y0 + y) * width + rect.x0 + x;
                if inside && fixed[pixel] {
                    known.is_fixed[local] = true;
                    known.values[local] = f64::from(image[pixel]);
                    fixed_sum += known.values[local];
                    fixed_count += 1;
                } else {
                    self.unknowns.push(local);
                }
            }
        }
        if fixed_count == 0 || self.unknowns.is_empty() {
            return None;
        }
        known.mean = fixed_sum / fixed_count as f64;
        Some(known)
    }

    /// Minimises the block energy over the unknowns by CG, from the fixed pixels' mean; the
    /// solution is left in `self.x`.
    fn solve(&mut self, known: &Known, limits: CgLimits) -> cg::CgReport {
        let (basis, weight) = (&self.basis, &self.weight);
        let mut image_of_known = [0.0; N];
        apply_energy(basis, weight, &known.values, &mut image_of_known);
        self.rhs.clear();
        self.rhs
            .extend(self.unknowns.iter().map(|&u| -image_of_known[u]));
        self.x.clear();
        self.x.resize(self.unknowns.len(), known.mean);
        let unknowns = &self.unknowns;
        cg::solve(
            |v, out| {
                let mut block = [0.0; N];
                for (&u, &value) in unknowns.iter().zip(v) {
                    block[u] = value;
                }
                let mut result = [0.0; N];
                apply_energy(basis, weight, &block, &mut result);
                for (o, &u) in out.iter_mut().zip(unknowns) {
                    *o = result[u];
                }
            },
            &self.rhs,
            &mut self.x,
            limits,
            &mut self.scratch,
        )
    }

    /// `SNAP_ROUNDS` rounds of: zero the AC coefficients the quantiser `steps` round to 0, then
    /// put the fixed pixels back; updates `self.x`.
    fn snap(&mut self, known: &Known, steps: &[f64; N]) {
        let mut block = known.values;
        for (&u, &value) in self.unknowns.iter().zip(&self.x) {
            block[u] = value;
        }
        for _ in 0..SNAP_ROUNDS {
            let mut c = [0.0; N];
            transform(&self.basis, &block, &mut c, false);
            for (ck, q) in c.iter_mut().zip(steps).skip(1) {
                if ck.abs() < 0.5 * q {
                    *ck = 0.0;
                }
            }
            let mut back = [0.0; N];
            transform(&self.basis, &c, &mut back, true);
            for &u in &self.unknowns {
                block[u] = back[u];
            }
        }
        for (x, &u) in self.x.iter_mut().zip(&self.unknowns) {
            *x = block[u];
        }
    }
}

/// One block's fixed pixels, read from the image.
struct Known {
    /// Fixed values at their place in the block, 0 elsewhere.
    values: [f64; N],
    is_fixed: [bool; N],
    /// Mean of the fixed values: where CG starts the unknowns.
    mean: f64,
}

/// The energy's operator DᵀWD applied to a block: DCT, weight each coefficient, inverse DCT.
fn apply_energy(basis: &Basis, weight: &[f64; N], block: &[f64; N], out: &mut [f64; N]) {
    let mut coefficients = [0.0; N];
    transform(basis, block, &mut coefficients, false);
    coefficients
        .iter_mut()
        .zip(weight)
        .for_each(|(c, w)| *c *= w);
    transform(basis, &coefficients, out, true);
}

/// Projection rounds of `snap` (see the module doc).
const SNAP_ROUNDS: usize = 30;

/// The DCT-II matrix as rows and as columns.
#[derive(Debug)]
struct Basis {
    /// rows[k * SIDE + n] = α_k cos(π (2n+1) k / 16).
    rows: [f64; N],
    /// transposed[n * SIDE + k] = rows[k * SIDE + n].
    transposed: [f64; N],
}

impl Basis {
    fn new(rows: [f64; N]) -> Self {
        let transposed = std::array::from_fn(|i| rows[(i % SIDE) * SIDE + i / SIDE]);
        Basis { rows, transposed }
    }
}

/// Separable 2-D DCT (`inverse == false`: c = D b Dᵀ) or its transpose (b = Dᵀ c D).
fn transform(basis: &Basis, input: &[f64; N], output: &mut [f64; N], inverse: bool) {
    // entry(k, n) = basis[k][n] forward, basis[n][k] inverse.
    if inverse {
        separable(&basis.transposed, &basis.rows, input, output)
    } else {
        separable(&basis.rows, &basis.transposed, input, output)
    }
}

/// First `rows[y][k] = Σ_n entry(k, n) · input[y][n]`, then `output[k][x] = Σ_n entry(k, n) · rows[n][x]`,
/// with `by_k[k][n] = by_n[n][k] = entry(k, n)`.
///
/// Each output is the sum of its eight products in the order n = 0..8 from −0.0, as
/// `Iterator::sum` adds them, so the result is the same to the bit as the plain loops; the loops
/// run over the outputs innermost so that they are summed side by side in vector registers. This
/// is most of `snap`'s and the CG's time, so it is also compiled for AVX and AVX-512 and chosen at
/// run time (`multiversion`): wider vectors of the same IEEE products and sums (no fused
/// multiply–add), hence the same bits on every machine.
#[multiversion::multiversion(targets("x86_64+avx512f+avx2+avx", "x86_64+avx2+avx", "x86_64+avx"))]
fn separable(by_k: &[f64; N], by_n: &[f64; N], input: &[f64; N], output: &mut [f64; N]) {
    let mut rows = [-0.0; N];
    for (row, pixels) in rows.chunks_exact_mut(SIDE).zip(input.chunks_exact(SIDE)) {
        for (column, &pixel) in by_n.chunks_exact(SIDE).zip(pixels) {
            for (r, &e) in row.iter_mut().zip(column) {
                *r += e * pixel;
            }
        }
    }
    output.fill(-0.0);
    for (out, entries) in output.chunks_exact_mut(SIDE).zip(by_k.chunks_exact(SIDE)) {
        for (&e, row) in entries.iter().zip(rows.chunks_exact(SIDE)) {
            for (o, &r) in out.iter_mut().zip(row) {
                *o += e * r;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transform_is_orthonormal() {
        let dct = DctEnergy::new(Weighting::Quantiser);
        let block: [f64; N] = std::array::from_fn(|i| ((i * 37) % 11) as f64 - 5.0);
        let mut c = [0.0; N];
        let mut back = [0.0; N];
        transform(&dct.basis, &block, &mut c, false);
        transform(&dct.basis, &c, &mut back, true);
        let energy_b: f64 = block.iter().map(|v| v * v).sum();
        let energy_c: f64 = c.iter().map(|v| v * v).sum();
        assert!((energy_b - energy_c).abs() < 1e-9 * energy_b);
        for (a, b) in block.iter().zip(&back) {
            assert!((a - b).abs() < 1e-9);
        }
        // A flat block has only a DC coefficient, 8× its value.
        let flat = [3.0; N];
        transform(&dct.basis, &flat, &mut c, false);
        assert!((c[0] - 24.0).abs() < 1e-9);
        assert!(c[1..].iter().all(|v| v.abs() < 1e-9));
    }

    #[test]
    fn the_mask_operator_gives_the_cg_minimiser() {
        // A 13 × 11 image: full, right-edge, bottom-edge and corner blocks, each with a mask of
        // its own, and values of a few hundred grey levels.
        let (w, h) = (13, 11);
        let grid = BlockGrid::new(w, h, SIDE);
        let fixed: Vec<bool> = (0..w * h).map(|i| (i * 7 + i / 5) % 5 < 2).collect();
        let image: Vec<f32> = (0..w * h).map(|i| ((i * 53) % 211) as f32).collect();
        let limits = CgLimits {
            tolerance: 1e-12,
            max_iterations: 400,
        };
        let mut stats = PadStats::default();
        let mut solver = DctEnergy::new(Weighting::Biharmonic);
        let energy = solver.energy_matrix();
        for b in 0..grid.len() {
            let rect = grid.rect(b);
            let mask = grid.block_mask(rect, &fixed);
            let operator = BlockOperator::new(&energy, mask).expect("a pinned block");
            let (mut by_cg, mut direct) = (image.clone(), image.clone());
            solver.pad_block(&grid, rect, &mut by_cg, &fixed, None, limits, &mut stats);
            let op = Some(&operator);
            solver.pad_block(&grid, rect, &mut direct, &fixed, op, limits, &mut stats);
            for (cg, exact) in by_cg.iter().zip(&direct) {
                assert!(
                    (cg - exact).abs() < 1e-3,
                    "block {b}: CG {cg}, direct {exact}"
                );
            }
        }
        assert_eq!((stats.systems, stats.direct), (grid.len(), grid.len()));
    }

    /// The plain separable loops `transform` replaced, summed by `Iterator::sum`.
    fn reference(basis: &Basis, input: &[f64; N], inverse: bool) -> [f64; N] {
        let entry = |k: usize, n: usize| {
            if inverse {
                basis.rows[n * SIDE + k]
            } else {
                basis.rows[k * SIDE + n]
            }
        };
        let mut rows = [0.0; N];
        for y in 0..SIDE {
            for k in 0..SIDE {
                rows[y * SIDE + k] = (0..SIDE).map(|n| entry(k, n) * input[y * SIDE + n]).sum();
            }
        }
        std::array::from_fn(|i| {
            let (k, x) = (i / SIDE, i % SIDE);
            (0..SIDE).map(|n| entry(k, n) * rows[n * SIDE + x]).sum()
        })
    }

    #[test]
    fn transform_matches_the_plain_loops_to_the_bit() {
        let dct = DctEnergy::new(Weighting::Biharmonic);
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for trial in 0..200 {
            // Some blocks with zeros and negative zeros, whose sums' signs depend on the order.
            let block: [f64; N] = std::array::from_fn(|i| match (trial + i) % 7 {
                0 => 0.0,
                1 if trial % 2 == 0 => -0.0,
                _ => next() * 1e3,
            });
            for inverse in [false, true] {
                let mut out = [0.0; N];
                transform(&dct.basis, &block, &mut out, inverse);
                let want = reference(&dct.basis, &block, inverse);
                for (a, b) in out.iter().zip(&want) {
                    assert_eq!(a.to_bits(), b.to_bits());
                }
            }
        }
        let zeros = [-0.0; N];
        let mut out = [0.0; N];
        transform(&dct.basis, &zeros, &mut out, false);
        let want = reference(&dct.basis, &zeros, false);
        assert!(out
            .iter()
            .zip(&want)
            .all(|(a, b)| a.to_bits() == b.to_bits()));
    }
}
