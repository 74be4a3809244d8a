//! Eigenvectors by inverse iteration on the Hessenberg form.

use nalgebra::{Complex, DMatrix, DVector};

/// The eigenvector of `λ` from `A = Q·H·Qᵀ` (H upper Hessenberg): inverse iteration on
/// `H − λ·I` by Gaussian elimination with pivoting between neighbouring rows (O(n²) per solve),
/// then `Q·y`.
pub(super) fn eigenvector(
    q: &DMatrix<f64>,
    h: &DMatrix<f64>,
    l: Complex<f64>,
) -> DVector<Complex<f64>> {
    let n = h.nrows();
    // A shift a hair off the eigenvalue keeps the system solvable.
    let shift = l + Complex::new(1e-9 * (1.0 + l.norm()), 1e-9 * (1.0 + l.norm()));
    let mut y = DVector::from_element(n, Complex::new(1.0, 0.0));
    for _ in 0..3 {
        y = hessenberg_solve(h, shift, &y);
        let norm = y
            .iter()
            .map(|v| v.norm_sqr())
            .sum::<f64>()
            .sqrt()
            .max(1e-300);
        y /= Complex::new(norm, 0.0);
    }
    let qc = q.map(|v| Complex::new(v, 0.0));
    qc * y
}

/// Solves `(H − s·I) y = b` for upper Hessenberg `H`.
fn hessenberg_solve(
    h: &DMatrix<f64>,
    s: Complex<f64>,
    b: &DVector<Complex<f64>>,
) -> DVector<Complex<f64>> {
    let n = h.nrows();
    let mut m: DMatrix<Complex<f64>> = h.map(|v| Complex::new(v, 0.0));
    for i in 0..n {
        m[(i, i)] -= s;
    }
    let mut rhs = b.clone();
    for k in 0..n.saturating_sub(1) {
        // Pivot between rows k and k+1 (the only nonzero below the diagonal).
        if m[(k + 1, k)].norm() > m[(k, k)].norm() {
            m.swap_rows(k, k + 1);
            rhs.swap_rows(k, k + 1);
        }
        let piv = m[(k, k)];
        if piv.norm() == 0.0 {
            continue;
        }
        let f = m[(k + 1, k)] / piv;
        if f.norm() == 0.0 {
            continue;
        }
        for j in k..n {
            let v = m[(k, j)];
            m[(k + 1, j)] -= f * v;
        }
        let r = rhs[k];
        rhs[k + 1] -= f * r;
    }
    let mut y = DVector::from_element(n, Complex::new(0.0, 0.0));
    for i in (0..n).rev() {
        let mut acc = rhs[i];
        for j in i + 1..n {
            acc -= m[(i, j)] * y[j];
        }
        let d = m[(i, i)];
        y[i] = if d.norm() > 1e-300 {
            acc / d
        } else {
            acc * 1e300
        };
    }
    y
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The Hessenberg inverse iteration finds the eigenvector of a known matrix.
    #[test]
    fn eigenvector_of_a_known_matrix() {
        // Two masses (1 kg) on springs: k1 = 100 to ground, k2 = 50 between; damping 0.1.
        let (k1, k2, c): (f64, f64, f64) = (100.0, 50.0, 0.1);
        let a = DMatrix::from_row_slice(
            4,
            4,
            &[
                0.0,
                0.0,
                1.0,
                0.0, //
                0.0,
                0.0,
                0.0,
                1.0, //
                -(k1 + k2),
                k2,
                -c,
                0.0, //
                k2,
                -k2,
                0.0,
                -c,
            ],
        );
        let eig = a.clone().complex_eigenvalues();
        let (q, h) = nalgebra::linalg::Hessenberg::new(a.clone()).unpack();
        // Undamped: ω² = (k1 + 2k2 ± √(k1² + 4k2²))/2.
        let disc = (k1 * k1 + 4.0 * k2 * k2).sqrt();
        let w = [
            ((k1 + 2.0 * k2 - disc) / 2.0).sqrt(),
            ((k1 + 2.0 * k2 + disc) / 2.0).sqrt(),
        ];
        let mut found: Vec<f64> = eig.iter().filter(|l| l.im > 0.0).map(|l| l.im).collect();
        found.sort_by(f64::total_cmp);
        for (f, w) in found.iter().zip(w) {
            assert!((f / w - 1.0).abs() < 1e-3, "{f} vs {w}");
        }
        for l in eig.iter().filter(|l| l.im > 0.0) {
            let v = eigenvector(&q, &h, *l);
            let ac = a.map(|x| Complex::new(x, 0.0));
            let r = &ac * &v - &v * *l;
            let rn = r.iter().map(|x| x.norm()).fold(0.0, f64::max);
            assert!(rn < 1e-6, "residual {rn}");
        }
    }
}
