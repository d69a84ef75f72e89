//! L2 stretch of a parameterization (Sander, Snyder, Gortler, Hoppe 2001).

/// Running sums that give the normalised L2 stretch of a set of triangles.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct StretchSum {
    area_3d: f64,
    area_2d: f64,
    weighted: f64,
}

impl StretchSum {
    /// Adds one triangle: its 3D corners and its 2D corners (any common unit).
    /// Triangles without area in either domain are skipped: they carry no surface.
    pub(crate) fn add(&mut self, q: [[f64; 3]; 3], uv: [[f64; 2]; 3]) {
        let [p1, p2, p3] = uv;
        let a2 = ((p2[0] - p1[0]) * (p3[1] - p1[1]) - (p3[0] - p1[0]) * (p2[1] - p1[1])) / 2.0;
        let e1 = sub(q[1], q[0]);
        let e2 = sub(q[2], q[0]);
        let a3 = norm(cross(e1, e2)) / 2.0;
        if !(a2.abs() > 1e-20) || !(a3 > 1e-20) {
            return;
        }
        let (s1, s2, s3) = (p1[0], p2[0], p3[0]);
        let (t1, t2, t3) = (p1[1], p2[1], p3[1]);
        let mut ss = [0.0; 3];
        let mut st = [0.0; 3];
        for i in 0..3 {
            ss[i] = (q[0][i] * (t2 - t3) + q[1][i] * (t3 - t1) + q[2][i] * (t1 - t2)) / (2.0 * a2);
            st[i] = (q[0][i] * (s3 - s2) + q[1][i] * (s1 - s3) + q[2][i] * (s2 - s1)) / (2.0 * a2);
        }
        let a = dot(ss, ss);
        let c = dot(st, st);
        self.area_3d += a3;
        self.area_2d += a2.abs();
        self.weighted += a3 * (a + c) / 2.0;
    }

    /// Merges two sums.
    pub(crate) fn merge(&mut self, other: &StretchSum) {
        self.area_3d += other.area_3d;
        self.area_2d += other.area_2d;
        self.weighted += other.weighted;
    }

    /// Normalised L2 stretch: 1 for an isometry up to scale, larger otherwise.
    /// `None` without any surface.
    pub(crate) fn value(&self) -> Option<f64> {
        (self.area_3d > 0.0)
            .then(|| (self.weighted / self.area_3d).sqrt() * (self.area_2d / self.area_3d).sqrt())
    }

    /// Summed 2D area.
    pub(crate) fn area_2d(&self) -> f64 {
        self.area_2d
    }
}

pub(crate) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
pub(crate) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
pub(crate) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
pub(crate) fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn isometry_has_stretch_one_and_shear_more() {
        let q = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let mut iso = StretchSum::default();
        iso.add(q, [[0.0, 0.0], [2.0, 0.0], [0.0, 2.0]]);
        assert!((iso.value().unwrap_or(0.0) - 1.0).abs() < 1e-12);
        let mut sheared = StretchSum::default();
        sheared.add(q, [[0.0, 0.0], [1.0, 0.0], [3.0, 1.0]]);
        assert!(sheared.value().unwrap_or(0.0) > 1.5);
    }
}
