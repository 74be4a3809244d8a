//! Order statistics of a series.

/// Φ, the standard normal CDF, from `libm`'s erfc (accurate to a few ulp).
pub fn normal_cdf(x: f64) -> f64 {
    0.5 * libm::erfc(-x / std::f64::consts::SQRT_2)
}

/// Φ⁻¹, the inverse of the standard normal CDF: Acklam's rational approximation (relative
/// error below 1.2e-9), refined by one Halley step on [`normal_cdf`] (Acklam's own
/// refinement), to about machine precision; ±∞ at 0 and 1.
pub fn normal_quantile(p: f64) -> f64 {
    if p <= 0.0 || p >= 1.0 {
        return if p >= 1.0 {
            f64::INFINITY
        } else if p <= 0.0 {
            f64::NEG_INFINITY
        } else {
            f64::NAN
        };
    }
    let x = acklam(p);
    // Halley: e = Φ(x) − p, u = e·√(2π)·exp(x²/2), x − u / (1 + x·u/2).
    let e = normal_cdf(x) - p;
    let u = e * (2.0 * std::f64::consts::PI).sqrt() * (0.5 * x * x).exp();
    x - u / (1.0 + 0.5 * x * u)
}

/// Acklam's rational approximation of Φ⁻¹ on (0, 1).
fn acklam(p: f64) -> f64 {
    const A: [f64; 6] = [
        -3.969_683_028_665_376e1,
        2.209_460_984_245_205e2,
        -2.759_285_104_469_687e2,
        1.383_577_518_672_69e2,
        -3.066_479_806_614_716e1,
        2.506_628_277_459_239,
    ];
    const B: [f64; 5] = [
        -5.447_609_879_822_406e1,
        1.615_858_368_580_409e2,
        -1.556_989_798_598_866e2,
        6.680_131_188_771_972e1,
        -1.328_068_155_288_572e1,
    ];
    const C: [f64; 6] = [
        -7.784_894_002_430_293e-3,
        -3.223_964_580_411_365e-1,
        -2.400_758_277_161_838,
        -2.549_732_539_343_734,
        4.374_664_141_464_968,
        2.938_163_982_698_783,
    ];
    const D: [f64; 4] = [
        7.784_695_709_041_462e-3,
        3.224_671_290_700_398e-1,
        2.445_134_137_142_996,
        3.754_408_661_907_416,
    ];
    let tail = |q: f64| {
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    };
    if p < 0.02425 {
        tail((-2.0 * p.ln()).sqrt())
    } else if p > 1.0 - 0.02425 {
        -tail((-2.0 * (1.0 - p).ln()).sqrt())
    } else {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    }
}

/// The `p` % percentile of `values` (0 ≤ p ≤ 100), linear between order statistics (rank
/// `p/100·(n − 1)`, numpy's default), ignoring non-finite values; NaN for no finite value.
pub fn percentile(values: &[f64], p: f64) -> f64 {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let rank = (p.clamp(0.0, 100.0) / 100.0) * (v.len() - 1) as f64;
    let n = v.len();
    let (lo, hi) = (
        crate::bounds::cell_clamped(rank.floor(), n),
        crate::bounds::cell_clamped(rank.ceil(), n),
    );
    v[lo] + (rank - lo as f64) * (v[hi] - v[lo])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Φ and Φ⁻¹ at tabulated points, and each the other's inverse across the tails.
    #[test]
    fn normal_distribution_at_known_points() {
        assert!((normal_cdf(0.0) - 0.5).abs() < 1e-15);
        assert!((normal_cdf(1.959_963_984_540_054) - 0.975).abs() < 1e-15);
        assert!((normal_cdf(-1.644_853_626_951_472_2) - 0.05).abs() < 1e-15);
        assert!((normal_quantile(0.95) - 1.644_853_626_951_472_2).abs() < 1e-13);
        assert!(normal_quantile(0.5).abs() < 1e-15);
        for p in [1e-12, 1e-6, 0.01, 0.02425, 0.3, 0.7, 0.99, 1.0 - 1e-9] {
            let x = normal_quantile(p);
            assert!(
                (normal_cdf(x) / p - 1.0).abs() < 1e-9,
                "p {p}: Φ(Φ⁻¹) = {}",
                normal_cdf(x)
            );
        }
        assert_eq!(normal_quantile(0.0), f64::NEG_INFINITY);
        assert_eq!(normal_quantile(1.0), f64::INFINITY);
    }

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
