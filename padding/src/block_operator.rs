//! The DCT-energy minimiser of one block mask as a matrix: free pixels = G · fixed pixels.
//!
//! The block energy of [`crate::dct_energy`] is a quadratic form bᵀ M b with M = DᵀWD, so with
//! b = P·x + f its minimiser over the free pixels x is x = −A⁻¹ B f, A = M[free, free] and
//! B = M[free, fixed]: a linear map of the fixed values that depends on the mask alone. A geometry
//! image keeps its mask for every frame of a clip, so [`crate::Padder`] factors each distinct
//! block mask once and every frame's block then costs one small matrix–vector product instead of
//! a conjugate-gradient solve (most of the padding's time before: docs/design.md, "Padding per
//! codec").
//!
//! Written here rather than taken from nalgebra: a dense Cholesky of at most 63 unknowns is a
//! dozen lines, and the crate is also built for the WebAssembly decoder, which pads nothing and
//! should not compile a linear-algebra crate for it.

/// Pixels of an 8 × 8 block.
const N: usize = crate::dct_energy::SIDE * crate::dct_energy::SIDE;

/// G of one block mask: `free` and `fixed` list the block's pixels (row-major in the block,
/// ascending), `gain[i * fixed.len() + j]` is free pixel i's weight of fixed pixel j.
#[derive(Debug, Clone)]
pub(crate) struct BlockOperator {
    free: Vec<u8>,
    fixed: Vec<u8>,
    gain: Vec<f64>,
}

impl BlockOperator {
    /// G for the block whose pixel k is fixed where bit k of `mask` is set, from the energy's
    /// matrix `energy` (row-major N × N, symmetric). `None` when the mask has no fixed or no free
    /// pixel, or when A is not numerically positive definite (the caller then solves by CG).
    pub fn new(energy: &[f64], mask: u64) -> Option<Self> {
        let is_fixed = |k: usize| mask >> k & 1 == 1;
        let free: Vec<u8> = (0..N as u8).filter(|&k| !is_fixed(k.into())).collect();
        let fixed: Vec<u8> = (0..N as u8).filter(|&k| is_fixed(k.into())).collect();
        if free.is_empty() || fixed.is_empty() {
            return None;
        }
        let entry = |r: u8, c: u8| energy[usize::from(r) * N + usize::from(c)];
        let mut a: Vec<f64> = free
            .iter()
            .flat_map(|&r| free.iter().map(move |&c| entry(r, c)))
            .collect();
        cholesky(&mut a, free.len())?;
        // Column j of G solves A g = −B e_j.
        let (nf, nk) = (free.len(), fixed.len());
        let mut gain = vec![0.0; nf * nk];
        let mut column = vec![0.0; nf];
        for (j, &k) in fixed.iter().enumerate() {
            for (c, &r) in column.iter_mut().zip(&free) {
                *c = -entry(r, k);
            }
            solve_factored(&a, nf, &mut column);
            for (i, &g) in column.iter().enumerate() {
                gain[i * nk + j] = g;
            }
        }
        Some(BlockOperator { free, fixed, gain })
    }

    /// Entries of G: free × fixed pixels.
    pub fn gains(&self) -> usize {
        self.gain.len()
    }

    /// The block's free pixels (ascending), in the order [`Self::apply`] writes them.
    pub fn free(&self) -> impl Iterator<Item = usize> + '_ {
        self.free.iter().map(|&k| usize::from(k))
    }

    /// The free pixels' values that minimise the energy given the block's fixed values (`block`
    /// holds the fixed pixels at their place; other entries are ignored), into `out`.
    pub fn apply(&self, block: &[f64; N], out: &mut Vec<f64>) {
        let mut gathered = [0.0; N];
        for (v, &k) in gathered.iter_mut().zip(&self.fixed) {
            *v = block[usize::from(k)];
        }
        let values = &gathered[..self.fixed.len()];
        out.clear();
        out.extend(
            self.gain
                .chunks_exact(values.len())
                .map(|row| row.iter().zip(values).fold(-0.0, |sum, (g, v)| sum + g * v)),
        );
    }
}

/// In-place Cholesky factor L (lower triangle, row-major `n × n`) of the SPD matrix `a`; `None`
/// when a pivot is not clearly positive.
fn cholesky(a: &mut [f64], n: usize) -> Option<()> {
    // Pivots below this fraction of the largest diagonal entry mean A is singular to working
    // precision (a block whose fixed pixels do not pin the energy): CG handles those.
    let scale = (0..n).map(|i| a[i * n + i]).fold(0.0f64, f64::max);
    for j in 0..n {
        let mut d = a[j * n + j];
        for k in 0..j {
            d -= a[j * n + k] * a[j * n + k];
        }
        // Also catches a NaN pivot, which no comparison passes.
        if d.is_nan() || d <= 1e-12 * scale {
            return None;
        }
        let d = d.sqrt();
        a[j * n + j] = d;
        for i in j + 1..n {
            let mut s = a[i * n + j];
            for k in 0..j {
                s -= a[i * n + k] * a[j * n + k];
            }
            a[i * n + j] = s / d;
        }
    }
    Some(())
}

/// Solves L Lᵀ x = b in place, `l` the factor [`cholesky`] left.
fn solve_factored(l: &[f64], n: usize, b: &mut [f64]) {
    for i in 0..n {
        let mut s = b[i];
        for k in 0..i {
            s -= l[i * n + k] * b[k];
        }
        b[i] = s / l[i * n + i];
    }
    for i in (0..n).rev() {
        let mut s = b[i];
        for k in i + 1..n {
            s -= l[k * n + i] * b[k];
        }
        b[i] = s / l[i * n + i];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cholesky_solves_a_small_system() {
        // A = [[4, 2], [2, 3]], b = [2, 1] → x = [0.5, 0].
        let mut a = vec![4.0, 2.0, 2.0, 3.0];
        cholesky(&mut a, 2).expect("SPD");
        let mut b = vec![2.0, 1.0];
        solve_factored(&a, 2, &mut b);
        assert!((b[0] - 0.5).abs() < 1e-12 && b[1].abs() < 1e-12);
        let mut singular = vec![1.0, 1.0, 1.0, 1.0];
        assert!(cholesky(&mut singular, 2).is_none());
    }
}
