//! What moving a quantised skinning weight away from its fit costs in prediction error.
//!
//! Each vertex's weights `β` are the least-squares solution of `min Σ_i ‖D_i β − r_i‖²` over the
//! frames (`motion/skinning.rs`), so the squared prediction error of any other `β̂` exceeds the
//! fit's by `(β̂ − β)ᵀ G (β̂ − β)`, `G = Σ_i D_iᵀ D_i` the fit's normal matrix (without its
//! ridge): exactly for the plain least-squares `β`, up to a term of the ridge's size for the
//! ridged (or clamped) `β` the fit keeps. Rounding each weight on its own ignores `G`'s
//! off-diagonal terms; choosing the weights one after the other with this growth in view (and the
//! bits each costs, in the encoder) lands nearer the fit for fewer bits.

/// Each vertex's exact weights and the normal matrix of its fit (unit frame, summed over the
/// frames), with the quantisation step of the weights they were quantised at.
#[derive(Debug, Clone, Default)]
pub struct WeightFits {
    pub(super) exact: Vec<Vec<f64>>,
    /// `m × m` per vertex, `m` its number of weights (symmetric, so row- and column-major alike).
    pub(super) grams: Vec<Vec<f64>>,
    pub(super) step: f64,
}

impl WeightFits {
    /// How much the squared prediction error of vertex `v` (unit frame, summed over the frames)
    /// grows when its weight `index` is quantised to `candidate` instead of `values[index]`, its
    /// other weights as `values` has them. 0 for a weight the fits do not know.
    pub fn growth(&self, v: usize, index: usize, values: &[i32], candidate: i32) -> f64 {
        let (Some(exact), Some(gram)) = (self.exact.get(v), self.grams.get(v)) else {
            return 0.0;
        };
        let m = exact.len();
        if index >= m || values.len() != m || gram.len() != m * m {
            return 0.0;
        }
        let error = |j: usize, q: i32| f64::from(q) * self.step - exact[j];
        let row = &gram[index * m..][..m];
        let cross: f64 = (0..m)
            .filter(|&j| j != index)
            .map(|j| row[j] * error(j, values[j]))
            .sum();
        let own = |q: i32| {
            let e = error(index, q);
            row[index] * e * e + 2.0 * e * cross
        };
        own(candidate) - own(values[index])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn growth_is_the_normal_matrix_quadratic_form() {
        // Two weights, G = [[4, 1], [1, 2]], exact (0.3, -0.2), step 0.1.
        let fits = WeightFits {
            exact: vec![vec![0.3, -0.2]],
            grams: vec![vec![4.0, 1.0, 1.0, 2.0]],
            step: 0.1,
        };
        let form = |q: [i32; 2]| {
            let e = [f64::from(q[0]) * 0.1 - 0.3, f64::from(q[1]) * 0.1 + 0.2];
            4.0 * e[0] * e[0] + 2.0 * e[0] * e[1] + 2.0 * e[1] * e[1]
        };
        let values = [3, -1];
        for candidate in [-2, 0, 3, 5] {
            let want = form([values[0], candidate]) - form(values);
            let got = fits.growth(0, 1, &values, candidate);
            assert!((got - want).abs() < 1e-12, "{candidate}: {got} against {want}");
        }
        for candidate in [0, 2, 4] {
            let want = form([candidate, values[1]]) - form(values);
            let got = fits.growth(0, 0, &values, candidate);
            assert!((got - want).abs() < 1e-12, "{candidate}: {got} against {want}");
        }
        // Weights the fits do not know cost nothing: another index, vertex or length.
        assert_eq!(fits.growth(0, 2, &values, 1), 0.0);
        assert_eq!(fits.growth(1, 0, &values, 1), 0.0);
        assert_eq!(fits.growth(0, 0, &[3, -1, 0], 1), 0.0);
    }
}
