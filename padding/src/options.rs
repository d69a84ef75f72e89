//! The padding methods and their tuning knobs.

use std::fmt;
use std::str::FromStr;

use crate::PaddingError;

/// How free pixels are filled. Every method keeps fixed pixels bit-exact and, given a previous frame,
/// copies its co-located content into blocks that hold no fixed pixel (so a P-frame codec skips them).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Method {
    /// The paper (MCGV §3.3, eq. 5–6): per block, minimise the 8-connected Dirichlet energy ψ(B)
    /// with fixed pixels held, solved by conjugate gradient.
    Cg,
    /// Baseline: every free pixel gets the mid-range of the fixed values (mid-grey; 0 for a centred residual).
    MidGrey,
    /// Baseline: free pixels of a block get the mean of that block's fixed pixels.
    Mean,
    /// Baseline: multigrid push–pull over the whole image (the hole filling of MPEG V-PCC).
    PushPull,
    /// ψ minimised over the whole image rather than per block, so padding is smooth across block
    /// borders and fills empty blocks too (CG warm-started by push–pull).
    Laplace,
    /// Per 8×8 block, minimise the AC energy weighted by JPEG's quantiser, Σ_{k≠0} (c_k / Q_k)²
    /// (what the codec rounds). Measured to lose: it fills the high frequencies JPEG then drops.
    DctEnergy,
    /// Per 8×8 block, minimise ‖Δb‖² (thin-plate smoothness, in the DCT basis Σ λ_k² c_k²), fixed
    /// pixels held: continues the chart's gradient instead of flattening at its border.
    Biharmonic,
    /// `biharmonic`, then alternately quantised at `jpeg_quality` and given back its fixed pixels,
    /// so the coefficients JPEG will drop are already ~0 (the error they would cause moves to free pixels).
    Snap,
}

impl Method {
    /// Every method, in the order the bench reports them.
    pub const ALL: [Method; 8] = [
        Method::MidGrey,
        Method::Mean,
        Method::PushPull,
        Method::Cg,
        Method::Laplace,
        Method::DctEnergy,
        Method::Biharmonic,
        Method::Snap,
    ];

    /// The names accepted by [`FromStr`] (the `--padding` values).
    pub const NAMES: [&'static str; 8] = [
        "midgrey",
        "mean",
        "pushpull",
        "cg",
        "laplace",
        "dct",
        "biharmonic",
        "snap",
    ];

    /// The `--padding` name of this method.
    pub fn name(self) -> &'static str {
        match self {
            Method::MidGrey => "midgrey",
            Method::Mean => "mean",
            Method::PushPull => "pushpull",
            Method::Cg => "cg",
            Method::Laplace => "laplace",
            Method::DctEnergy => "dct",
            Method::Biharmonic => "biharmonic",
            Method::Snap => "snap",
        }
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Method {
    type Err = PaddingError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let lower = s.trim().to_ascii_lowercase();
        let method = match lower.as_str() {
            "cg" => Method::Cg,
            "midgrey" | "mid-grey" | "zero" | "grey" => Method::MidGrey,
            "mean" => Method::Mean,
            "pushpull" | "push-pull" => Method::PushPull,
            "laplace" => Method::Laplace,
            "dct" | "dct-energy" | "dctenergy" => Method::DctEnergy,
            "biharmonic" | "thin-plate" => Method::Biharmonic,
            "snap" => Method::Snap,
            _ => return Err(PaddingError::UnknownMethod(s.to_string())),
        };
        Ok(method)
    }
}

/// How the block methods (`cg`, `mean`, `dct`, `biharmonic`) fill, in intra frames, the blocks
/// that hold no fixed pixel. Each way the block is flat, so JPEG codes it as a DC value and an
/// end-of-block; they differ in the DC, which JPEG codes as the difference from the previous
/// block's DC in raster order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum EmptyBlocks {
    /// The mean of the previous block in raster order (the fixed-pixel mean before the first
    /// filled block): DC differences are 0 along every run of empty blocks, paid only where a chart
    /// starts again. Measured the cheapest of the three.
    #[default]
    RasterPrevious,
    /// The mean of all fixed pixels of the image: equal DCs within runs of empty blocks, but a DC
    /// step both where a run starts and where it ends.
    FixedMean,
    /// The mean of the bordering pixels of adjacent already-filled blocks, growing outwards from
    /// the charts: the smallest step at block edges, but a different DC in almost every block.
    NeighbourMean,
}

/// Settings of [`crate::pad`]. `Default` is what the encoder should use: [`Method::Snap`] with
/// [`EmptyBlocks::RasterPrevious`], which needed the fewest JPEG bytes at equal error on the fixed
/// pixels in the crate's bench, below the paper's [`Method::Cg`] at every quality (README.md,
/// "Bench"; docs/design.md, "Padding per codec"). Set `jpeg_quality` to the quality the image is
/// coded at; for a codec other than JPEG (MPEG-4 P-frames), [`Method::Biharmonic`] is the
/// quality-independent runner-up.
#[derive(Debug, Clone, PartialEq)]
pub struct PaddingOptions {
    /// Which filler to run.
    pub method: Method,
    /// Side of the square coding blocks (8 for JPEG / MPEG-4 Part 2). Edge blocks may be partial.
    pub block: usize,
    /// Conjugate gradient stops when ‖r‖₂ ≤ tolerance · ‖b‖₂. The default 1e-5 puts the padded values
    /// well under 0.01 grey level from the exact minimiser, far below the 0.5 of 8-bit rounding.
    /// The DCT methods solve each block mask exactly ([`crate::Padder`]) and use CG, with this
    /// tolerance, only for a block whose mask they could not factor.
    pub tolerance: f32,
    /// Cap on conjugate gradient iterations per system. A block system has at most 64 unknowns, so
    /// CG ends in ≤ 64 steps in exact arithmetic (far fewer on the bench images: README.md); the
    /// whole-image system (`laplace`) is the one the cap could bound, and there the push–pull warm
    /// start leaves ~100 steps to do.
    pub max_iterations: usize,
    /// Fill of blocks without fixed pixels in intra frames (block methods only).
    pub empty_blocks: EmptyBlocks,
    /// The JPEG quality the image will be coded at (1–100); only [`Method::Snap`] uses it.
    pub jpeg_quality: u8,
    /// The quantisation table the image will be coded with; only [`Method::Snap`] uses it.
    pub jpeg_table: JpegTable,
}

/// A JPEG luminance quantisation table, before the quality scales it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum JpegTable {
    /// ITU-T T.81 Annex K (weighted for the eye: coarse high frequencies).
    #[default]
    AnnexK,
    /// 16 everywhere: every frequency quantised alike.
    Flat,
}

impl Default for PaddingOptions {
    fn default() -> Self {
        PaddingOptions {
            method: Method::Snap,
            block: 8,
            tolerance: 1e-5,
            max_iterations: 400,
            empty_blocks: EmptyBlocks::RasterPrevious,
            jpeg_quality: 75,
            jpeg_table: JpegTable::AnnexK,
        }
    }
}

impl PaddingOptions {
    /// Default settings with the given method.
    pub fn with_method(method: Method) -> Self {
        PaddingOptions {
            method,
            ..PaddingOptions::default()
        }
    }
}
