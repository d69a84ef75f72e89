//! Padding of the free pixels of multi-chart geometry images before block-DCT coding.
//!
//! A geometry image holds a value at the pixels covered by charts ("fixed") and don't-care values
//! elsewhere ("free"). The codec pays for every pixel, so free pixels are filled to cost it as little
//! as possible: [`pad`] does this in place with one of several [`Method`]s, never touching a fixed
//! pixel. The crate knows images and masks only.
//!
//! ```
//! use padding::{pad, Method, PaddingOptions};
//! let (w, h) = (16, 8);
//! let mut image = vec![0.0f32; w * h];
//! let mut fixed = vec![false; w * h];
//! image[0] = 10.0;
//! fixed[0] = true;
//! pad(&mut image, w, h, &fixed, None, &PaddingOptions::with_method(Method::Cg)).unwrap();
//! assert!(image.iter().all(|&v| v == 10.0));
//! ```

mod block_laplace;
mod block_operator;
mod cg;
mod dct_energy;
mod empty_blocks;
mod error;
mod grid;
mod image_laplace;
mod options;
mod push_pull;

pub use error::PaddingError;
pub use options::{EmptyBlocks, JpegTable, Method, PaddingOptions};

use block_laplace::BlockLaplace;
use block_operator::BlockOperator;
use dct_energy::{DctEnergy, Weighting};
use grid::BlockGrid;

/// What a call to [`pad`] did, for benches and diagnostics.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PadStats {
    /// Linear systems solved by conjugate gradient.
    pub systems: usize,
    /// Conjugate gradient iterations, summed over systems.
    pub cg_iterations: usize,
    /// Systems stopped by `max_iterations` before reaching `tolerance` (their last iterate is used).
    pub unconverged: usize,
    /// Blocks filled by their mask's precomputed minimiser (the DCT-energy methods), no CG.
    pub direct: usize,
}

impl PadStats {
    fn record(&mut self, report: cg::CgReport) {
        self.systems += 1;
        self.cg_iterations += report.iterations;
        if !report.converged {
            self.unconverged += 1;
        }
    }
}

/// Fills the free pixels (`fixed[i] == false`) of a row-major `width × height` image in place;
/// fixed pixels never change.
///
/// `previous` is the previous padded frame (same size) when coding P-frames: blocks without a fixed
/// pixel copy it, so the codec can skip them. Without it (intra), such blocks are filled as the
/// method says (block methods: flat, see [`EmptyBlocks`]). An image with no
/// fixed pixel and no previous frame is filled with 0.
///
/// Errors (never panics) on an empty image, buffers whose length is not `width × height`, a zero
/// block size (or not 8 for the DCT-based `dct`, `biharmonic` and `snap`), or a non-finite fixed or previous pixel.
/// Many images on one mask (the frames of a clip) are padded faster by one [`Padder`].
pub fn pad(
    image: &mut [f32],
    width: usize,
    height: usize,
    fixed: &[bool],
    previous: Option<&[f32]>,
    opts: &PaddingOptions,
) -> Result<PadStats, PaddingError> {
    Padder::new(width, height, fixed, opts)?.pad(image, previous)
}

/// [`pad`] for any number of images that share one mask: what depends on the mask alone (for the
/// DCT-energy methods, each block mask's minimiser, see `block_operator.rs`) is made once here.
/// The values are those of the exact block minimiser, where [`Method::Cg`] and [`Method::Laplace`]
/// stop at [`PaddingOptions::tolerance`].
#[derive(Debug, Clone)]
pub struct Padder {
    grid: BlockGrid,
    fixed: Vec<bool>,
    /// For each block, whether it holds a fixed pixel.
    with_fixed: Vec<bool>,
    opts: PaddingOptions,
    operators: BlockOperators,
}

impl Padder {
    /// The padder of `width × height` images whose fixed pixels are those set in `fixed`. Errors as
    /// [`pad`] does on the sizes and the options.
    pub fn new(
        width: usize,
        height: usize,
        fixed: &[bool],
        opts: &PaddingOptions,
    ) -> Result<Self, PaddingError> {
        validate_mask(width, height, fixed, opts)?;
        let grid = BlockGrid::new(width, height, opts.block);
        let operators = match BlockSolver::new(opts) {
            BlockSolver::Dct(solver) => BlockOperators::new(&grid, fixed, &solver, MAX_GAINS),
            _ => BlockOperators::default(),
        };
        Ok(Padder {
            with_fixed: grid.any_set(fixed),
            grid,
            fixed: fixed.to_vec(),
            opts: opts.clone(),
            operators,
        })
    }

    /// The fixed pixels this padder keeps, row-major.
    pub fn fixed(&self) -> &[bool] {
        &self.fixed
    }

    /// The options this padder was made with.
    pub fn options(&self) -> &PaddingOptions {
        &self.opts
    }

    /// Pads `image` (see [`pad`]); `previous` as there.
    pub fn pad(
        &self,
        image: &mut [f32],
        previous: Option<&[f32]>,
    ) -> Result<PadStats, PaddingError> {
        let (grid, fixed, opts) = (&self.grid, self.fixed.as_slice(), &self.opts);
        validate_image(image, fixed, previous, grid.width * grid.height)?;
        let (width, height) = (grid.width, grid.height);
        let limits = cg::CgLimits {
            tolerance: f64::from(opts.tolerance.max(0.0)),
            max_iterations: opts.max_iterations,
        };
        let mut stats = PadStats::default();
        let mut filled = self.with_fixed.clone();
        let mut held = fixed.to_vec();
        if let Some(previous) = previous {
            empty_blocks::copy_from_previous(grid, image, previous, &mut filled, &mut held);
        }
        if !held.iter().any(|&h| h) {
            image.fill(0.0);
            return Ok(stats);
        }
        match opts.method {
            Method::MidGrey => {
                let (lo, hi) = fixed_range(image, fixed);
                let mid = if lo <= hi { 0.5 * (lo + hi) } else { 0.0 };
                image
                    .iter_mut()
                    .zip(&held)
                    .filter(|(_, &h)| !h)
                    .for_each(|(v, _)| *v = mid);
            }
            Method::PushPull => push_pull::fill(image, width, height, &held),
            Method::Laplace => image_laplace::fill(image, width, height, &held, limits, &mut stats),
            Method::Mean | Method::Cg | Method::DctEnergy | Method::Biharmonic | Method::Snap => {
                let mut block_solver = BlockSolver::new(opts);
                for b in (0..grid.len()).filter(|&b| self.with_fixed[b]) {
                    let rect = grid.rect(b);
                    match &mut block_solver {
                        BlockSolver::Mean => fill_block_mean(grid, rect, image, fixed),
                        BlockSolver::Laplace(solver) => {
                            solver.pad_block(grid, rect, image, fixed, limits, &mut stats)
                        }
                        BlockSolver::Dct(solver) => {
                            let operator = self.operators.of(b);
                            solver.pad_block(grid, rect, image, fixed, operator, limits, &mut stats)
                        }
                    }
                }
                self.fill_empty_blocks(image, &mut filled);
            }
        }
        Ok(stats)
    }

    fn fill_empty_blocks(&self, image: &mut [f32], filled: &mut [bool]) {
        let (grid, fixed) = (&self.grid, self.fixed.as_slice());
        match self.opts.empty_blocks {
            EmptyBlocks::NeighbourMean => {
                empty_blocks::fill_flat_from_neighbours(grid, image, filled, 0.0);
            }
            EmptyBlocks::FixedMean => {
                let mean = fixed_mean(image, fixed);
                empty_blocks::fill_flat(grid, image, filled, mean);
            }
            EmptyBlocks::RasterPrevious => {
                let mean = fixed_mean(image, fixed);
                empty_blocks::fill_from_raster_previous(grid, image, filled, mean);
            }
        }
    }
}

/// Each block's mask minimiser, one per distinct mask (many border blocks share a mask).
#[derive(Debug, Clone, Default)]
struct BlockOperators {
    distinct: Vec<Option<BlockOperator>>,
    /// Index into `distinct` per block; `None` for a block without fixed pixels (or no operators).
    of_block: Vec<Option<usize>>,
}

/// Entries of G kept per [`Padder`] at most (32 MB): blocks of masks beyond it are solved by CG.
/// pdance's 128 × 128 lattice needs 0.17 M, BrainStem's 288 × 288 0.68 M; only lattices of
/// thousands of pixels a side come near it.
const MAX_GAINS: usize = 4 << 20;

impl BlockOperators {
    /// Operators for `grid`'s blocks, at most `max_gains` entries of G in all.
    fn new(grid: &BlockGrid, fixed: &[bool], solver: &DctEnergy, max_gains: usize) -> Self {
        let energy = solver.energy_matrix();
        let mut by_mask = std::collections::HashMap::new();
        let mut distinct: Vec<Option<BlockOperator>> = Vec::new();
        let mut gains = 0;
        let of_block: Vec<Option<usize>> = (0..grid.len())
            .map(|b| {
                let mask = grid.block_mask(grid.rect(b), fixed);
                (mask != 0).then(|| {
                    *by_mask.entry(mask).or_insert_with(|| {
                        let operator = BlockOperator::new(&energy, mask)
                            .filter(|o| gains + o.gains() <= max_gains);
                        gains += operator.as_ref().map_or(0, BlockOperator::gains);
                        distinct.push(operator);
                        distinct.len() - 1
                    })
                })
            })
            .collect();
        BlockOperators { distinct, of_block }
    }

    fn of(&self, block: usize) -> Option<&BlockOperator> {
        let index = (*self.of_block.get(block)?)?;
        self.distinct[index].as_ref()
    }
}

enum BlockSolver {
    Mean,
    Laplace(Box<BlockLaplace>),
    Dct(Box<DctEnergy>),
}

impl BlockSolver {
    fn new(opts: &PaddingOptions) -> Self {
        match opts.method {
            Method::Cg => BlockSolver::Laplace(Box::default()),
            Method::DctEnergy => BlockSolver::Dct(Box::new(DctEnergy::new(Weighting::Quantiser))),
            Method::Biharmonic => BlockSolver::Dct(Box::new(DctEnergy::new(Weighting::Biharmonic))),
            Method::Snap => BlockSolver::Dct(Box::new(
                DctEnergy::new(Weighting::Biharmonic).with_snap(opts.jpeg_quality, opts.jpeg_table),
            )),
            _ => BlockSolver::Mean,
        }
    }
}

fn fill_block_mean(grid: &BlockGrid, rect: grid::BlockRect, image: &mut [f32], fixed: &[bool]) {
    let (sum, count) = grid
        .pixels(rect)
        .filter(|&i| fixed[i])
        .fold((0.0f64, 0usize), |(s, c), i| {
            (s + f64::from(image[i]), c + 1)
        });
    if count == 0 {
        return;
    }
    let mean = (sum / count as f64) as f32;
    for i in grid.pixels(rect) {
        if !fixed[i] {
            image[i] = mean;
        }
    }
}

fn fixed_mean(image: &[f32], fixed: &[bool]) -> f32 {
    let (sum, count) = image
        .iter()
        .zip(fixed)
        .filter(|(_, &f)| f)
        .fold((0.0f64, 0usize), |(s, c), (&v, _)| {
            (s + f64::from(v), c + 1)
        });
    if count == 0 {
        0.0
    } else {
        (sum / count as f64) as f32
    }
}

fn fixed_range(image: &[f32], fixed: &[bool]) -> (f32, f32) {
    image
        .iter()
        .zip(fixed)
        .filter(|(_, &f)| f)
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), (&v, _)| {
            (lo.min(v), hi.max(v))
        })
}

fn validate_mask(
    width: usize,
    height: usize,
    fixed: &[bool],
    opts: &PaddingOptions,
) -> Result<(), PaddingError> {
    if width == 0 || height == 0 {
        return Err(PaddingError::EmptyImage { width, height });
    }
    let expected = width
        .checked_mul(height)
        .ok_or(PaddingError::EmptyImage { width, height })?;
    check_len("mask", fixed.len(), expected)?;
    if opts.block == 0 {
        return Err(PaddingError::BadBlock {
            block: 0,
            method: opts.method.to_string(),
            why: "blocks must be at least one pixel wide",
        });
    }
    if matches!(
        opts.method,
        Method::DctEnergy | Method::Biharmonic | Method::Snap
    ) && opts.block != dct_energy::SIDE
    {
        return Err(PaddingError::BadBlock {
            block: opts.block,
            method: opts.method.to_string(),
            why: "the quantiser-weighted DCT works on JPEG's 8x8 blocks",
        });
    }
    Ok(())
}

fn check_len(what: &'static str, got: usize, expected: usize) -> Result<(), PaddingError> {
    if got == expected {
        Ok(())
    } else {
        Err(PaddingError::SizeMismatch {
            what,
            got,
            expected,
        })
    }
}

fn validate_image(
    image: &[f32],
    fixed: &[bool],
    previous: Option<&[f32]>,
    expected: usize,
) -> Result<(), PaddingError> {
    check_len("image", image.len(), expected)?;
    if let Some(previous) = previous {
        check_len("previous", previous.len(), expected)?;
        if let Some(index) = previous.iter().position(|v| !v.is_finite()) {
            return Err(PaddingError::NonFinite {
                what: "previous",
                index,
            });
        }
    }
    if let Some(index) = image
        .iter()
        .zip(fixed)
        .position(|(v, &f)| f && !v.is_finite())
    {
        return Err(PaddingError::NonFinite {
            what: "image",
            index,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Past the budget of G's entries, blocks are solved by CG, to the same values.
    #[test]
    fn blocks_past_the_operators_budget_are_solved_by_cg() {
        let (w, h) = (40, 24);
        let fixed: Vec<bool> = (0..w * h).map(|i| (i * 7 + i / 9) % 5 < 2).collect();
        let image: Vec<f32> = (0..w * h).map(|i| ((i * 53) % 211) as f32).collect();
        let opts = PaddingOptions::with_method(Method::Biharmonic);
        let mut padder = Padder::new(w, h, &fixed, &opts).expect("valid");
        let (mut all, mut some) = (image.clone(), image.clone());
        let stats = padder.pad(&mut all, None).expect("pads");
        assert_eq!((stats.direct, stats.systems), (15, 0));
        let BlockSolver::Dct(solver) = BlockSolver::new(&opts) else {
            panic!("biharmonic is a DCT method");
        };
        let first = padder.operators.distinct[0]
            .as_ref()
            .map_or(0, |o| o.gains());
        padder.operators = BlockOperators::new(&padder.grid, &fixed, &solver, first);
        let stats = padder.pad(&mut some, None).expect("pads");
        assert_eq!((stats.direct, stats.systems), (1, 14));
        for (a, b) in all.iter().zip(&some) {
            assert!((a - b).abs() < 0.01, "{a} against {b}");
        }
    }
}
