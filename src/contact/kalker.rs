//! Kalker's creepage coefficients C11, C22, C23, C33 (Kalker 1967; the table is in
//! `TABLE_AB_LE_1` and `TABLE_AB_GT_1` below, assets/docs/physics.md §4), interpolated linearly in the ellipse ratio and in ν by
//! `1/C(ν) = 8(ν−¼)(ν−½)/C(0) − 16ν(ν−½)/C(¼) + 8ν(ν−¼)/C(½)`.

/// Kalker's coefficients for one ellipse ratio and Poisson ratio.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KalkerCoefficients {
    /// Longitudinal creepage.
    pub c11: f64,
    /// Lateral creepage.
    pub c22: f64,
    /// Lateral force from spin.
    pub c23: f64,
    /// Spin moment from spin.
    pub c33: f64,
}

/// One table row: `g` and, for ν = 0, ¼, ½, the values of C11, C22, C23, C33.
type Row = (f64, [f64; 3], [f64; 3], [f64; 3], [f64; 3]);

/// Rows `g, [C11; 3], [C22; 3], [C23; 3], [C33; 3]` for ν = 0, ¼, ½, with `g = a/b` (a ≤ b).
// Kalker's table has 3.14 where it means 3.14, not π.
#[allow(clippy::approx_constant)]
const TABLE_AB_LE_1: [Row; 10] = [
    (
        0.1,
        [2.51, 3.31, 4.85],
        [2.51, 2.52, 2.53],
        [0.334, 0.473, 0.731],
        [6.42, 8.28, 11.7],
    ),
    (
        0.2,
        [2.59, 3.37, 4.81],
        [2.59, 2.63, 2.66],
        [0.483, 0.603, 0.809],
        [3.46, 4.27, 5.66],
    ),
    (
        0.3,
        [2.68, 3.44, 4.80],
        [2.68, 2.75, 2.81],
        [0.607, 0.715, 0.889],
        [2.49, 2.96, 3.72],
    ),
    (
        0.4,
        [2.78, 3.53, 4.82],
        [2.78, 2.88, 2.98],
        [0.720, 0.823, 0.977],
        [2.02, 2.32, 2.77],
    ),
    (
        0.5,
        [2.88, 3.62, 4.83],
        [2.88, 3.01, 3.14],
        [0.827, 0.929, 1.07],
        [1.74, 1.93, 2.22],
    ),
    (
        0.6,
        [2.98, 3.72, 4.91],
        [2.98, 3.14, 3.31],
        [0.930, 1.03, 1.18],
        [1.56, 1.68, 1.86],
    ),
    (
        0.7,
        [3.09, 3.81, 4.97],
        [3.09, 3.28, 3.48],
        [1.03, 1.14, 1.29],
        [1.43, 1.50, 1.60],
    ),
    (
        0.8,
        [3.19, 3.91, 5.05],
        [3.19, 3.41, 3.65],
        [1.13, 1.25, 1.40],
        [1.34, 1.37, 1.42],
    ),
    (
        0.9,
        [3.29, 4.01, 5.12],
        [3.29, 3.54, 3.82],
        [1.23, 1.36, 1.51],
        [1.27, 1.27, 1.27],
    ),
    (
        1.0,
        [3.40, 4.12, 5.20],
        [3.40, 3.67, 3.98],
        [1.33, 1.47, 1.63],
        [1.21, 1.19, 1.16],
    ),
];

/// Rows with `g = b/a` (a > b), from 0.9 down to 0.1.
const TABLE_AB_GT_1: [Row; 9] = [
    (
        0.9,
        [3.51, 4.22, 5.30],
        [3.51, 3.81, 4.16],
        [1.44, 1.59, 1.77],
        [1.16, 1.11, 1.06],
    ),
    (
        0.8,
        [3.65, 4.36, 5.42],
        [3.65, 3.99, 4.39],
        [1.58, 1.75, 1.94],
        [1.10, 1.04, 0.954],
    ),
    (
        0.7,
        [3.82, 4.54, 5.58],
        [3.82, 4.21, 4.67],
        [1.76, 1.95, 2.18],
        [1.05, 0.965, 0.852],
    ),
    (
        0.6,
        [4.06, 4.78, 5.80],
        [4.06, 4.50, 5.04],
        [2.01, 2.23, 2.50],
        [1.01, 0.892, 0.751],
    ),
    (
        0.5,
        [4.37, 5.10, 6.11],
        [4.37, 4.90, 5.56],
        [2.35, 2.62, 2.96],
        [0.958, 0.819, 0.650],
    ),
    (
        0.4,
        [4.84, 5.57, 6.57],
        [4.84, 5.48, 6.31],
        [2.88, 3.24, 3.70],
        [0.912, 0.747, 0.549],
    ),
    (
        0.3,
        [5.57, 6.34, 7.34],
        [5.57, 6.40, 7.51],
        [3.79, 4.32, 5.01],
        [0.868, 0.674, 0.446],
    ),
    (
        0.2,
        [6.96, 7.78, 8.82],
        [6.96, 8.14, 9.79],
        [5.72, 6.63, 7.89],
        [0.828, 0.601, 0.341],
    ),
    (
        0.1,
        [10.7, 11.7, 12.9],
        [10.7, 12.8, 16.0],
        [12.2, 14.6, 18.0],
        [0.795, 0.526, 0.228],
    ),
];

/// A table with every coefficient replaced by its reciprocal (the interpolation in ν is of
/// `1/C`), at compile time: a coefficient then costs one division instead of four.
const fn reciprocals<const N: usize>(table: [Row; N]) -> [Row; N] {
    let mut out = table;
    let mut i = 0;
    while i < N {
        let mut v = 0;
        while v < 3 {
            out[i].1[v] = 1.0 / table[i].1[v];
            out[i].2[v] = 1.0 / table[i].2[v];
            out[i].3[v] = 1.0 / table[i].3[v];
            out[i].4[v] = 1.0 / table[i].4[v];
            v += 1;
        }
        i += 1;
    }
    out
}

/// `TABLE_AB_LE_1` and `TABLE_AB_GT_1` as reciprocals.
const INV_AB_LE_1: [Row; 10] = reciprocals(TABLE_AB_LE_1);
/// See [`INV_AB_LE_1`].
const INV_AB_GT_1: [Row; 9] = reciprocals(TABLE_AB_GT_1);

/// Weights of `1/C(0)`, `1/C(¼)`, `1/C(½)` at Poisson ratio ν (assets/docs/physics.md §4).
fn nu_weights(nu: f64) -> [f64; 3] {
    [
        8.0 * (nu - 0.25) * (nu - 0.5),
        -16.0 * nu * (nu - 0.5),
        8.0 * nu * (nu - 0.25),
    ]
}

/// Value at Poisson ratio ν from the three tabulated reciprocals (interpolation of 1/C).
fn in_nu(inv: [f64; 3], w: [f64; 3]) -> f64 {
    1.0 / (w[0] * inv[0] + w[1] * inv[1] + w[2] * inv[2])
}

impl KalkerCoefficients {
    /// Coefficients for ellipse semi-axes ratio `a/b` (a in the rolling direction) and Poisson
    /// ratio `nu` (0 to ½). Ratios beyond the table (below 0.1 or above 10) are clamped.
    pub fn new(a_over_b: f64, nu: f64) -> Self {
        let nu = nu.clamp(0.0, 0.5);
        // One ordered list of rows, increasing with a/b: t = a/b on the first table (0.1 … 1)
        // and t = 2 − b/a on the second (1.1 … 1.9).
        let row = |i: usize| -> (f64, [[f64; 3]; 4]) {
            let (c11, c22, c23, c33, t) = if i < INV_AB_LE_1.len() {
                let r = INV_AB_LE_1[i];
                (r.1, r.2, r.3, r.4, r.0)
            } else {
                let r = INV_AB_GT_1[i - INV_AB_LE_1.len()];
                (r.1, r.2, r.3, r.4, 2.0 - r.0)
            };
            (t, [c11, c22, c23, c33])
        };
        let n_rows = TABLE_AB_LE_1.len() + TABLE_AB_GT_1.len();
        let t = if a_over_b <= 1.0 {
            a_over_b.max(0.1)
        } else {
            (2.0 - 1.0 / a_over_b).min(1.9)
        };
        // Rows are 0.1 apart in t from 0.1 to 1.9.
        let i = crate::bounds::cell_clamped((t - 0.1) / 0.1, n_rows - 1);
        let (t0, v0) = row(i);
        let (t1, v1) = row(i + 1);
        let w = ((t - t0) / (t1 - t0)).clamp(0.0, 1.0);
        let weights = nu_weights(nu);
        let c = |k: usize| {
            let a = in_nu(v0[k], weights);
            let b = in_nu(v1[k], weights);
            a + w * (b - a)
        };
        KalkerCoefficients {
            c11: c(0),
            c22: c(1),
            c23: c(2),
            c33: c(3),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reproduces_table_nodes_and_nu_interpolation() {
        let k = KalkerCoefficients::new(0.5, 0.25);
        assert!((k.c11 - 3.62).abs() < 1e-12 && (k.c23 - 0.929).abs() < 1e-12);
        let k = KalkerCoefficients::new(2.0, 0.0);
        assert!((k.c11 - 4.37).abs() < 1e-12 && (k.c33 - 0.958).abs() < 1e-12);
        let k = KalkerCoefficients::new(1.0, 0.5);
        assert!((k.c22 - 3.98).abs() < 1e-12);
        // ν = 0.28 lies between the ¼ and ½ columns.
        let k = KalkerCoefficients::new(0.5, 0.28);
        assert!(k.c11 > 3.62 && k.c11 < 4.83);
        // Continuous through a/b = 1 (the two tables meet).
        let (a, b) = (
            KalkerCoefficients::new(0.999, 0.3),
            KalkerCoefficients::new(1.001, 0.3),
        );
        assert!((a.c11 - b.c11).abs() < 0.01);
    }
}
