//! Order statistics of a series.

/// The `p` % percentile of `values` (0 ≤ p ≤ 100), linear between order statistics (rank
/// `p/100·(n − 1)`, numpy's default), ignoring non-finite values; NaN for no finite value.
pub fn percentile(values: &[f64], p: f64) -> f64 {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let rank = (p.clamp(0.0, 100.0) / 100.0) * (v.len() - 1) as f64;
    let (lo, hi) = (rank.floor() as usize, rank.ceil() as usize);
    v[lo] + (rank - lo as f64) * (v[hi] - v[lo])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentiles_of_known_samples() {
        // 0, 1, …, 100: the p % percentile is p.
        let v: Vec<f64> = (0..=100).map(f64::from).rev().collect();
        for p in [0.0, 0.15, 50.0, 99.85, 100.0] {
            assert!((percentile(&v, p) - p).abs() < 1e-12, "{p}");
        }
        // Uniform on [0, 1] in 100 001 points: the 99.85 % percentile is 0.9985.
        let u: Vec<f64> = (0..=100_000).map(|i| i as f64 / 100_000.0).collect();
        assert!((percentile(&u, 99.85) - 0.9985).abs() < 1e-12);
        assert!(percentile(&[f64::NAN], 50.0).is_nan());
        assert_eq!(percentile(&[3.0, f64::NAN, 1.0], 50.0), 2.0);
    }
}
