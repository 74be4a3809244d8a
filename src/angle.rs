//! Sine, cosine, arcsine and arctangent of the small angles a vehicle makes with its track
//! (a wheelset's yaw and roll, a body's attitude in its track frame, the cant): Taylor
//! polynomials where the argument is small enough that the first omitted term is under half a
//! unit in the last place, the standard library elsewhere. The step evaluates some forty of
//! them; the polynomials take a few multiply-adds where the library's general routines take
//! tens of nanoseconds.

/// Largest |x| the polynomials serve (rad; for [`asin`] the sine, for [`atan2`] the ratio
/// `y/x`). The first omitted terms there, `x¹¹/11!` ≈ 3·10⁻¹⁹ (sine), `x¹²/12!` ≈ 2·10⁻²¹
/// (cosine), `0.0116·x¹⁷` ≈ 10⁻¹⁹ (arcsine) and `x¹⁹/19` ≈ 5·10⁻²¹ (arctangent), lie far
/// below half an ulp of the result; what is left is the polynomial's own rounding.
pub const SMALL: f64 = 0.1;

/// `(sin x, cos x)`, exact to rounding.
#[inline]
pub fn sin_cos(x: f64) -> (f64, f64) {
    if x.abs() > SMALL {
        return x.sin_cos();
    }
    let x2 = x * x;
    // sin x = x·(1 − x²/3! + x⁴/5! − x⁶/7! + x⁸/9!)
    let s = x
        * (1.0
            + x2 * (-1.0 / 6.0
                + x2 * (1.0 / 120.0 + x2 * (-1.0 / 5040.0 + x2 * (1.0 / 362_880.0)))));
    // cos x = 1 − x²/2! + x⁴/4! − x⁶/6! + x⁸/8! − x¹⁰/10!
    let c = 1.0
        + x2 * (-0.5
            + x2 * (1.0 / 24.0
                + x2 * (-1.0 / 720.0 + x2 * (1.0 / 40_320.0 + x2 * (-1.0 / 3_628_800.0)))));
    (s, c)
}

/// `asin x`, exact to rounding.
#[inline]
pub fn asin(x: f64) -> f64 {
    if x.abs() > SMALL {
        return x.asin();
    }
    let x2 = x * x;
    // asin x = Σ (2n)! / (4ⁿ (n!)² (2n+1)) x^(2n+1): 1, 1/6, 3/40, 5/112, 35/1152, 63/2816,
    // 231/13312, 143/10240.
    x * (1.0
        + x2 * (1.0 / 6.0
            + x2 * (3.0 / 40.0
                + x2 * (5.0 / 112.0
                    + x2 * (35.0 / 1152.0
                        + x2 * (63.0 / 2816.0
                            + x2 * (231.0 / 13_312.0 + x2 * (143.0 / 10_240.0))))))))
}

/// `atan2(y, x)` for `x > 0`, exact to rounding.
#[inline]
pub fn atan2(y: f64, x: f64) -> f64 {
    let small = x > 0.0 && y.abs() <= SMALL * x;
    if !small {
        return y.atan2(x);
    }
    let r = y / x;
    let r2 = r * r;
    // atan r = r − r³/3 + r⁵/5 − r⁷/7 + r⁹/9 − r¹¹/11 + r¹³/13 − r¹⁵/15 + r¹⁷/17
    r * (1.0
        + r2 * (-1.0 / 3.0
            + r2 * (1.0 / 5.0
                + r2 * (-1.0 / 7.0
                    + r2 * (1.0 / 9.0
                        + r2 * (-1.0 / 11.0
                            + r2 * (1.0 / 13.0 + r2 * (-1.0 / 15.0 + r2 * (1.0 / 17.0)))))))))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every function against the standard library over and across the small range, to a few
    /// units in the last place.
    #[test]
    fn the_polynomials_match_the_library_to_rounding() {
        let ulps = |a: f64, b: f64| (a - b).abs() / (f64::EPSILON * b.abs().max(f64::MIN_POSITIVE));
        let mut worst = [0.0f64; 5];
        for i in -2000..=2000 {
            let x = i as f64 * 6e-5; // ±0.12: both sides of SMALL
            let (s, c) = sin_cos(x);
            let (s0, c0) = x.sin_cos();
            if x != 0.0 {
                worst[0] = worst[0].max(ulps(s, s0));
                worst[2] = worst[2].max(ulps(asin(x), x.asin()));
                worst[3] = worst[3].max(ulps(atan2(x, 1.0), x.atan2(1.0)));
                worst[4] = worst[4].max(ulps(atan2(0.7 * x, 0.7), x.atan2(1.0)));
            }
            worst[1] = worst[1].max(ulps(c, c0));
        }
        assert!(worst.iter().all(|&w| w <= 2.0), "worst ulps {worst:?}");
        // Outside the range, and for x ≤ 0 in atan2, the library's own values.
        assert_eq!(sin_cos(0.3), 0.3f64.sin_cos());
        assert_eq!(asin(-0.5), (-0.5f64).asin());
        assert_eq!(atan2(0.01, -1.0), 0.01f64.atan2(-1.0));
        assert!(atan2(f64::NAN, 1.0).is_nan() && asin(f64::NAN).is_nan());
    }
}
