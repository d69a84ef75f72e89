//! A plain conjugate gradient for symmetric positive definite operators given as a closure.
//!
//! Written by hand rather than taken from a sparse-solver crate: the per-block systems have at most
//! 64 unknowns and there are ~1000 of them per image, so building a crate's sparse matrix (or factoring
//! it) would cost more than the twenty-odd CG steps that solve it; the operators here are cheaper to
//! apply straight from the pixel grid than to store as matrices at all.

/// Reusable work vectors, so solving thousands of small systems allocates once.
#[derive(Debug, Default)]
pub(crate) struct CgScratch {
    r: Vec<f64>,
    p: Vec<f64>,
    ap: Vec<f64>,
}

/// When to stop: ‖r‖₂ ≤ tolerance·‖b‖₂, or after max_iterations steps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct CgLimits {
    pub tolerance: f64,
    pub max_iterations: usize,
}

/// How a solve ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct CgReport {
    /// Iterations run.
    pub iterations: usize,
    /// Whether ‖r‖ ≤ tolerance·‖b‖ was reached (false: the cap stopped it; x is the last iterate).
    pub converged: bool,
}

/// Solves `A x = b` for SPD `A`, starting from the `x` given. `apply(v, out)` writes `A v` to `out`.
pub(crate) fn solve(
    mut apply: impl FnMut(&[f64], &mut [f64]),
    b: &[f64],
    x: &mut [f64],
    limits: CgLimits,
    scratch: &mut CgScratch,
) -> CgReport {
    let n = b.len();
    let CgScratch { r, p, ap } = scratch;
    r.clear();
    r.resize(n, 0.0);
    ap.clear();
    ap.resize(n, 0.0);
    apply(x, ap);
    for ((ri, bi), ai) in r.iter_mut().zip(b).zip(ap.iter()) {
        *ri = bi - ai;
    }
    p.clear();
    p.extend_from_slice(r);
    let b_norm2 = dot(b, b);
    let stop2 = limits.tolerance * limits.tolerance * b_norm2;
    let mut rr = dot(r, r);
    let mut iterations = 0;
    while rr > stop2 && iterations < limits.max_iterations {
        apply(p, ap);
        let pap = dot(p, ap);
        if pap <= 0.0 || !pap.is_finite() {
            // Only reachable through round-off once the residual is ~0; the iterate stands.
            break;
        }
        let alpha = rr / pap;
        for ((xi, pi), (ri, ai)) in x.iter_mut().zip(p.iter()).zip(r.iter_mut().zip(ap.iter())) {
            *xi += alpha * pi;
            *ri -= alpha * ai;
        }
        let rr_next = dot(r, r);
        let beta = rr_next / rr;
        for (pi, ri) in p.iter_mut().zip(r.iter()) {
            *pi = ri + beta * *pi;
        }
        rr = rr_next;
        iterations += 1;
    }
    CgReport {
        iterations,
        converged: rr <= stop2,
    }
}

/// `out = A v` for the Laplace system of the padding solvers: unknown `u` has `degree[u]` neighbours
/// in all, the unknown ones at `links[link_start[u]..link_start[u + 1]]` (the fixed ones are in the
/// right-hand side). Both Laplace paddings build this layout, so they share the product.
pub(crate) fn laplacian(
    degree: &[f64],
    link_start: &[usize],
    links: &[usize],
    v: &[f64],
    out: &mut [f64],
) {
    for (u, o) in out.iter_mut().enumerate() {
        let neighbours: f64 = links[link_start[u]..link_start[u + 1]]
            .iter()
            .map(|&q| v[q])
            .sum();
        *o = degree[u] * v[u] - neighbours;
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_a_small_spd_system() {
        // A = [[4,1],[1,3]], b = [1,2] → x = [1/11, 7/11].
        let a = [[4.0, 1.0], [1.0, 3.0]];
        let mut x = [0.0; 2];
        let report = solve(
            |v, out| {
                for (i, row) in a.iter().enumerate() {
                    out[i] = row[0] * v[0] + row[1] * v[1];
                }
            },
            &[1.0, 2.0],
            &mut x,
            CgLimits {
                tolerance: 1e-12,
                max_iterations: 10,
            },
            &mut CgScratch::default(),
        );
        assert!(report.converged);
        assert!((x[0] - 1.0 / 11.0).abs() < 1e-10);
        assert!((x[1] - 7.0 / 11.0).abs() < 1e-10);
        assert!(report.iterations <= 2);
    }
}
