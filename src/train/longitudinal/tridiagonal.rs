//! The step's linear solve: a symmetric tridiagonal system by twisted factorisation.

/// Solves the symmetric tridiagonal system with diagonal `d` and off-diagonal `o` (`o[j]`
/// joins rows `j` and `j + 1`) for the right side `r` (overwritten), into `x`, using `inv` for
/// the pivots' inverses. Twisted factorisation: the elimination runs from both ends at once
/// towards the middle row, so the two halves' chains of dependent divisions overlap in the
/// processor, and the way back multiplies by the stored inverses. Needs a system that
/// elimination without pivoting solves (here: diagonally dominant).
pub(super) fn solve_tridiagonal(
    d: &[f64],
    o: &[f64],
    r: &mut [f64],
    inv: &mut [f64],
    x: &mut [f64],
) {
    let n = d.len();
    if n == 0 {
        return;
    }
    let p = n / 2;
    // forward from the top (rows 1..p) and backward from the bottom (rows n-2..p+1), fused
    if p > 0 {
        inv[0] = 1.0 / d[0];
    }
    if n - 1 > p {
        inv[n - 1] = 1.0 / d[n - 1];
    }
    let top = p.saturating_sub(1); // rows 1..p
    let bottom = (n - 1).saturating_sub(p + 1); // rows p+1..n-1, from n-2 down
    for k in 1..=top.max(bottom) {
        if k <= top {
            let i = k;
            let (oi, prev) = (o[i - 1], inv[i - 1]);
            inv[i] = 1.0 / (d[i] - oi * oi * prev);
            r[i] -= oi * prev * r[i - 1];
        }
        if k <= bottom {
            let i = n - 1 - k;
            let (oi, next) = (o[i], inv[i + 1]);
            inv[i] = 1.0 / (d[i] - oi * oi * next);
            r[i] -= oi * next * r[i + 1];
        }
    }
    // the twist row
    let (mut gamma, mut rho) = (d[p], r[p]);
    if p > 0 {
        let l = o[p - 1] * inv[p - 1];
        gamma -= l * o[p - 1];
        rho -= l * r[p - 1];
    }
    if p + 1 < n {
        let l = o[p] * inv[p + 1];
        gamma -= l * o[p];
        rho -= l * r[p + 1];
    }
    x[p] = rho / gamma;
    // back out from the middle, both ways at once
    for k in 1..=p.max(n - 1 - p) {
        if k <= p {
            let i = p - k;
            x[i] = (r[i] - o[i] * x[i + 1]) * inv[i];
        }
        if p + k < n {
            let i = p + k;
            x[i] = (r[i] - o[i - 1] * x[i - 1]) * inv[i];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::solve_tridiagonal;

    #[test]
    fn the_twisted_solve_matches_the_system() {
        for n in 1..12 {
            let d: Vec<f64> = (0..n).map(|i| 4.0 + i as f64 * 0.3).collect();
            let o: Vec<f64> = (0..n).map(|i| -1.0 - 0.1 * i as f64).collect();
            let b: Vec<f64> = (0..n).map(|i| (i as f64 * 1.7).sin()).collect();
            let (mut r, mut piv, mut x) = (b.clone(), vec![0.0; n], vec![0.0; n]);
            solve_tridiagonal(&d, &o, &mut r, &mut piv, &mut x);
            for i in 0..n {
                let mut ax = d[i] * x[i];
                if i > 0 {
                    ax += o[i - 1] * x[i - 1];
                }
                if i + 1 < n {
                    ax += o[i] * x[i + 1];
                }
                assert!((ax - b[i]).abs() < 1e-12, "n {n} row {i}");
            }
        }
    }
}
