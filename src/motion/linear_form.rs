//! How a cluster's affine map stores its linear part `A` (stream version 7), chosen per cluster
//! by the encoder: its nine entries, or its polar decomposition `A = R S`, a rotation and a
//! symmetric stretch.
//!
//! Why both: a rigid part that turns moves all nine entries at once, each a trajectory of sines
//! and cosines; as a rotation it moves three numbers and its stretch stays near the identity, so
//! its trajectories cost less to code. A part that bends or squashes (cloth, a collapsing body)
//! moves its stretch as much as its entries, and there the entries code smaller
//! (docs/design.md, "Affine maps as rotation and stretch").
//!
//! The rotation is stored as its modified Rodrigues parameters `p = tan(θ/4)·axis` (θ ≤ π, so
//! `|p| ≤ 1`). The decoder rebuilds `R` from `p` with `+ − × /` alone, which IEEE 754 rounds
//! alike on every machine; an axis–angle would need `sin` and `cos`, whose last bits differ
//! between maths libraries, so decoded frames would differ across platforms. A turn's error is
//! 2–4 times that of `p` at any angle up to a half turn, where a quaternion's vector part
//! `sin(θ/2)·axis` loses its scalar part's precision as the angle nears π (measured: on pdance
//! it raised the maps' error by three quarters). A reflection (`det A < 0`) is stored as the
//! rotation `−R` and the stretch `−S`.

/// How a cluster's linear part is stored: nine numbers either way, in the order of
/// [`LinearForm::values`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LinearForm {
    /// The entries of `A`, row by row.
    Entries = 0,
    /// `[p0 p1 p2, s00 s11 s22, s01 s02 s12]`: the rotation's parameters, then the stretch.
    RotationStretch = 1,
}

impl LinearForm {
    /// Both forms, by their stored id.
    pub const ALL: [LinearForm; 2] = [LinearForm::Entries, LinearForm::RotationStretch];

    /// The nine stored numbers of `a` (none when its rotation and stretch cannot be found: a
    /// decomposition that does not converge or overflows, entries near the f64 range).
    #[cfg(feature = "encode")]
    pub fn values(self, a: &Linear) -> Option<[f64; 9]> {
        match self {
            LinearForm::Entries => Some(std::array::from_fn(|i| a[i / 3][i % 3])),
            LinearForm::RotationStretch => {
                let parts = RotationStretch::of(a)?;
                let (p, s) = (parts.rotation, parts.stretch);
                Some([p[0], p[1], p[2], s[0], s[1], s[2], s[3], s[4], s[5]])
            }
        }
    }

    /// The linear part of nine stored numbers.
    pub fn linear(self, x: &[f64; 9]) -> Linear {
        match self {
            LinearForm::Entries => std::array::from_fn(|r| [x[3 * r], x[3 * r + 1], x[3 * r + 2]]),
            LinearForm::RotationStretch => RotationStretch {
                rotation: [x[0], x[1], x[2]],
                stretch: [x[3], x[4], x[5], x[6], x[7], x[8]],
            }
            .linear(),
        }
    }

    /// The identity's nine stored numbers.
    pub fn identity(self) -> [f64; 9] {
        match self {
            LinearForm::Entries => [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
            LinearForm::RotationStretch => {
                let RotationStretch { rotation, stretch } = RotationStretch::IDENTITY;
                std::array::from_fn(|i| if i < 3 { rotation[i] } else { stretch[i - 3] })
            }
        }
    }

    /// The RMS distance a unit error in each stored number moves a cluster whose vertices lie
    /// at RMS offsets `spreads` from its centroid along the axes: `σ_j` for entry `a_ij`;
    /// `4 √(σ_y² + σ_z²)` for `p0` (a small turn of `4 e` about x), `σ_i` for `s_ii`,
    /// `√(σ_i² + σ_j²)` for `s_ij`.
    pub fn levers(self, spreads: [f64; 3]) -> [f64; 9] {
        let [x, y, z] = spreads.map(|s| s * s);
        match self {
            LinearForm::Entries => std::array::from_fn(|i| spreads[i % 3]),
            LinearForm::RotationStretch => [
                4.0 * (y + z).sqrt(),
                4.0 * (x + z).sqrt(),
                4.0 * (x + y).sqrt(),
                x.sqrt(),
                y.sqrt(),
                z.sqrt(),
                (x + y).sqrt(),
                (x + z).sqrt(),
                (y + z).sqrt(),
            ],
        }
    }
}

/// A 3 × 3 matrix, row by row.
pub type Linear = [[f64; 3]; 3];

/// A linear part as `A = R(rotation) · S(stretch)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RotationStretch {
    /// The rotation's modified Rodrigues parameters `tan(θ/4)·axis` (any vector is a rotation).
    pub rotation: [f64; 3],
    /// The symmetric stretch: `[s00, s11, s22, s01, s02, s12]`.
    pub stretch: [f64; 6],
}

impl RotationStretch {
    /// No rotation, no stretch: the identity.
    pub const IDENTITY: Self = Self {
        rotation: [0.0; 3],
        stretch: [1.0, 1.0, 1.0, 0.0, 0.0, 0.0],
    };

    /// The polar decomposition of `a` (through its singular value decomposition, nalgebra's);
    /// none if that does not converge or is not finite (entries near the f64 range), and the
    /// cluster keeps its entries.
    #[cfg(feature = "encode")]
    pub fn of(a: &Linear) -> Option<Self> {
        use nalgebra::{Matrix3, Rotation3, UnitQuaternion};
        /// Far above the handful of sweeps a 3 × 3 matrix takes; bounds a pathological one.
        const MAX_SWEEPS: usize = 1000;
        let m = Matrix3::from_fn(|r, c| a[r][c]);
        let svd = m.try_svd(true, true, f64::EPSILON, MAX_SWEEPS)?;
        let (u, v_t) = (svd.u?, svd.v_t?);
        let mut r = u * v_t;
        if r.determinant() < 0.0 {
            r = -r;
        }
        // S = Rᵀ A is symmetric up to rounding: store the mean of its mirrored entries.
        let s = r.transpose() * m;
        let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r));
        // The shorter way round (w ≥ 0): p = v / (1 + w) stays within the unit ball.
        let sign = if q.w < 0.0 { -1.0 } else { 1.0 };
        let d = 1.0 + sign * q.w;
        let parts = Self {
            rotation: [sign * q.i / d, sign * q.j / d, sign * q.k / d],
            stretch: [
                s[(0, 0)],
                s[(1, 1)],
                s[(2, 2)],
                0.5 * (s[(0, 1)] + s[(1, 0)]),
                0.5 * (s[(0, 2)] + s[(2, 0)]),
                0.5 * (s[(1, 2)] + s[(2, 1)]),
            ],
        };
        let finite = parts.rotation.iter().chain(&parts.stretch).all(|x| x.is_finite());
        finite.then_some(parts)
    }

    /// The rotation matrix of the stored parameters, through their unit quaternion
    /// `(w, v) = ((1 − |p|²), 2p) / (1 + |p|²)`.
    fn rotation_matrix(&self) -> Linear {
        let [px, py, pz] = self.rotation;
        let n2 = px * px + py * py + pz * pz;
        let d = 1.0 + n2;
        let (x, y, z, w) = (2.0 * px / d, 2.0 * py / d, 2.0 * pz / d, (1.0 - n2) / d);
        [
            [
                1.0 - 2.0 * (y * y + z * z),
                2.0 * (x * y - w * z),
                2.0 * (x * z + w * y),
            ],
            [
                2.0 * (x * y + w * z),
                1.0 - 2.0 * (x * x + z * z),
                2.0 * (y * z - w * x),
            ],
            [
                2.0 * (x * z - w * y),
                2.0 * (y * z + w * x),
                1.0 - 2.0 * (x * x + y * y),
            ],
        ]
    }

    /// The linear part `R S`.
    pub fn linear(&self) -> Linear {
        let r = self.rotation_matrix();
        let [s00, s11, s22, s01, s02, s12] = self.stretch;
        let s = [[s00, s01, s02], [s01, s11, s12], [s02, s12, s22]];
        std::array::from_fn(|row| {
            std::array::from_fn(|col| (0..3).map(|j| r[row][j] * s[j][col]).sum())
        })
    }
}

#[cfg(all(test, feature = "encode"))]
mod tests {
    use super::*;

    fn close(a: &Linear, b: &Linear, tolerance: f64) -> bool {
        (0..3).all(|r| (0..3).all(|c| (a[r][c] - b[r][c]).abs() <= tolerance))
    }

    #[test]
    fn decomposition_rebuilds_the_matrix() {
        let cases: [Linear; 4] = [
            [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            // A turn of 0.7 rad about z, stretched along x.
            [
                [0.7648 * 1.2, -0.6442, 0.0],
                [0.6442 * 1.2, 0.7648, 0.0],
                [0.0, 0.0, 1.0],
            ],
            // Sheared, nearly a half turn about an oblique axis.
            [[-0.9, 0.3, 0.2], [0.1, -0.8, 0.4], [0.3, 0.2, 0.95]],
            // A mirror.
            [[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        ];
        for a in cases {
            let parts = RotationStretch::of(&a).unwrap();
            assert!(close(&parts.linear(), &a, 1e-12), "{a:?} -> {parts:?}");
            let [x, y, z] = parts.rotation;
            assert!(x * x + y * y + z * z <= 1.0 + 1e-12, "the shorter way round");
        }
        assert_eq!(
            RotationStretch::of(&RotationStretch::IDENTITY.linear()),
            Some(RotationStretch::IDENTITY)
        );
        // Beyond what the decomposition can square: refused, not looped over or made infinite.
        assert_eq!(RotationStretch::of(&[[1e300, 0.0, 0.0], [0.0, 1e300, 1e300], [0.0, 0.0, 1.0]]), None);
    }

    #[test]
    fn both_forms_store_and_rebuild_a_map() {
        let a = [[0.9, -0.4, 0.1], [0.45, 0.85, 0.05], [-0.1, 0.0, 1.1]];
        for form in LinearForm::ALL {
            let values = form.values(&a).unwrap();
            assert!(close(&form.linear(&values), &a, 1e-12), "{form:?}");
            let identity = form.linear(&form.identity());
            assert_eq!(identity, LinearForm::Entries.linear(&LinearForm::Entries.identity()));
        }
    }

    #[test]
    fn a_rigid_turn_has_the_identity_stretch() {
        let (c, s) = (0.3f64.cos(), 0.3f64.sin());
        let a = [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]];
        let parts = RotationStretch::of(&a).unwrap();
        for (got, want) in parts.stretch.iter().zip(RotationStretch::IDENTITY.stretch) {
            assert!((got - want).abs() < 1e-12, "{parts:?}");
        }
        assert!((parts.rotation[1] - 0.075f64.tan()).abs() < 1e-12);
    }

    #[test]
    fn any_parameters_make_a_rotation() {
        let half_turn = RotationStretch {
            rotation: [1.0, 0.0, 0.0],
            stretch: RotationStretch::IDENTITY.stretch,
        };
        let want = [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]];
        assert!(close(&half_turn.linear(), &want, 1e-15));
        // A decoder may meet any levels: the matrix stays orthonormal.
        let r = RotationStretch {
            rotation: [3.0, -7.0, 0.5],
            stretch: RotationStretch::IDENTITY.stretch,
        }
        .linear();
        for i in 0..3 {
            for j in 0..3 {
                let dot: f64 = (0..3).map(|k| r[i][k] * r[j][k]).sum();
                assert!((dot - f64::from(u8::from(i == j))).abs() < 1e-12);
            }
        }
    }
}
