//! Hertz normal contact (Johnson, *Contact Mechanics*, §4.2).
//!
//! Relative curvatures `A` (rolling direction) and `B` (lateral), `cos θ = |B − A|/(A + B)`.
//! The ellipse eccentricity `e` solves `B/A = [E(e)/(1 − e²) − K(e)] / [K(e) − E(e)]` (for
//! `A ≤ B`); then `m = (2E(e)/(π(1 − e²)))^{1/3}`, `n = m·√(1 − e²)`, semi-axes `m·c` and
//! `n·c` with `c = (3N(1 − ν²)/(2E(A + B)))^{1/3}`, peak pressure `p0 = 3N/(2πab)` and
//! approach `δ = (A + B)·b_min²·K(e)/E(e)`.

use std::f64::consts::PI;

/// Complete elliptic integrals `K(k)` and `E(k)` of modulus `k` (arithmetic–geometric mean).
pub fn elliptic_ke(k: f64) -> (f64, f64) {
    let mut a = 1.0;
    let mut b = (1.0 - k * k).max(0.0).sqrt();
    let mut c = k;
    let mut sum = 0.5 * c * c;
    let mut pow = 0.5;
    for _ in 0..40 {
        if c.abs() < 1e-16 {
            break;
        }
        let an = 0.5 * (a + b);
        let bn = (a * b).sqrt();
        c = 0.5 * (a - b);
        a = an;
        b = bn;
        pow *= 2.0;
        sum += pow * c * c;
    }
    let kk = PI / (2.0 * a);
    (kk, kk * (1.0 - sum))
}

/// Hertz coefficients `(m, n, r)` for the angle θ defined by `cos θ = |B − A|/(A + B)`, where
/// `m ≥ n` multiply `c` to give the major and minor semi-axes and `r = K(e)/E(e)` enters the
/// approach.
pub fn hertz_mn(cos_theta: f64) -> (f64, f64, f64) {
    let ct = cos_theta.clamp(0.0, 0.999_999);
    // Ratio of the larger to the smaller curvature sum.
    let ratio = (1.0 + ct) / (1.0 - ct);
    if ratio < 1.0 + 1e-12 {
        return (1.0, 1.0, 1.0);
    }
    let f = |e: f64| {
        let (k, ee) = elliptic_ke(e);
        (ee / (1.0 - e * e) - k) / (k - ee)
    };
    // f grows monotonically from 1 (e → 0) to ∞ (e → 1): bisect on e² for resolution near 1.
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if f(mid.sqrt()) < ratio {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let e2 = 0.5 * (lo + hi);
    let e = e2.sqrt();
    let (k, ee) = elliptic_ke(e);
    let m = (2.0 * ee / (PI * (1.0 - e2))).cbrt();
    let n = m * (1.0 - e2).sqrt();
    (m, n, k / ee)
}

/// Elastic constants of the wheel and rail (same material for both).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    /// Young's modulus, Pa.
    pub young: f64,
    /// Poisson's ratio.
    pub poisson: f64,
}

impl Material {
    /// Steel as in the worked case of this file's tests (N 122.6 kN: a 7.33 mm, p0 1 363 MPa): E 210 GPa, ν 0.3.
    pub const STEEL: Material = Material {
        young: 210e9,
        poisson: 0.3,
    };

    /// Shear modulus `G = E/(2(1 + ν))`, Pa.
    pub fn shear_modulus(&self) -> f64 {
        self.young / (2.0 * (1.0 + self.poisson))
    }
}

/// The Hertz contact ellipse.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HertzEllipse {
    /// Semi-axis in the rolling direction, m.
    pub a: f64,
    /// Semi-axis across (lateral, in the contact plane), m.
    pub b: f64,
    /// Peak pressure, Pa.
    pub p0: f64,
    /// Normal approach of the two bodies, m.
    pub approach: f64,
}

/// Geometry part of a Hertz contact that does not depend on the load: precomputed once per
/// contact point (e.g. in contact tables), so a simulation step only takes a cube root.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HertzShape {
    /// Sum of relative curvatures `A + B`, 1/m.
    pub curvature_sum: f64,
    /// Multiplier of `c` for the semi-axis in the rolling direction.
    pub ma: f64,
    /// Multiplier of `c` for the lateral semi-axis.
    pub mb: f64,
    /// `K(e)/E(e)`.
    pub k_over_e: f64,
}

impl HertzShape {
    /// From the relative curvatures `A` (rolling direction) and `B` (lateral), 1/m. Both are
    /// clamped to a small positive value: a conformal or saddle contact has no Hertz solution,
    /// and the ellipse is then that of nearly flat bodies.
    pub fn new(a_curv: f64, b_curv: f64) -> Self {
        let (a_c, b_c) = (a_curv.max(1e-3), b_curv.max(1e-3));
        let sum = a_c + b_c;
        let (m, n, r) = hertz_mn((b_c - a_c).abs() / sum);
        // The longer semi-axis lies along the direction of the smaller curvature sum.
        let (ma, mb) = if a_c <= b_c { (m, n) } else { (n, m) };
        HertzShape {
            curvature_sum: sum,
            ma,
            mb,
            k_over_e: r,
        }
    }

    /// From principal radii (concave negative): wheel rolling and lateral, rail lateral (the
    /// rail is straight along x). `A = ½/R_wx`, `B = ½(1/R_wy + 1/R_ry)`.
    pub fn from_radii(r_wx: f64, r_wy: f64, r_ry: f64) -> Self {
        Self::new(0.5 / r_wx, 0.5 * (1.0 / r_wy + 1.0 / r_ry))
    }

    /// The ellipse under normal load `n` (N).
    pub fn ellipse(&self, load: f64, mat: &Material) -> HertzEllipse {
        let load = load.max(0.0);
        let c = (3.0 * load * (1.0 - mat.poisson * mat.poisson)
            / (2.0 * mat.young * self.curvature_sum))
            .cbrt();
        let (a, b) = (self.ma * c, self.mb * c);
        let minor = a.min(b);
        HertzEllipse {
            a,
            b,
            p0: if load > 0.0 {
                3.0 * load / (2.0 * PI * a * b)
            } else {
                0.0
            },
            approach: self.curvature_sum * minor * minor * self.k_over_e,
        }
    }

    /// Normal load (N) that gives the approach `delta` (m): the inverse of
    /// [`HertzShape::ellipse`]'s approach, `N ∝ δ^{3/2}`.
    pub fn load_from_approach(&self, delta: f64, mat: &Material) -> f64 {
        if delta <= 0.0 {
            return 0.0;
        }
        // δ = S·(m_min·c)²·r with c³ = k·N → N = (δ/(S·m_min²·r))^{3/2}/k.
        let k = 3.0 * (1.0 - mat.poisson * mat.poisson) / (2.0 * mat.young * self.curvature_sum);
        let mmin = self.ma.min(self.mb);
        (delta / (self.curvature_sum * mmin * mmin * self.k_over_e)).powf(1.5) / k
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn m_and_n_match_the_spec_table() {
        let table = [
            (10.0, 6.611, 0.311),
            (20.0, 3.816, 0.412),
            (30.0, 2.731, 0.493),
            (40.0, 2.136, 0.567),
            (50.0, 1.754, 0.641),
            (60.0, 1.486, 0.717),
            (70.0, 1.285, 0.800),
            (80.0, 1.128, 0.893),
            (90.0, 1.000, 1.000),
        ];
        for (theta, m, n) in table {
            let (mm, nn, _) = hertz_mn(f64::to_radians(theta).cos());
            assert!((mm / m - 1.0).abs() < 0.005, "θ {theta}: m {mm} vs {m}");
            assert!((nn / n - 1.0).abs() < 0.005, "θ {theta}: n {nn} vs {n}");
        }
    }

    #[test]
    fn worked_case_of_the_spec() {
        // N 122.6 kN, flat tread r 0.42 m, rail crown R 0.30 m, E 210 GPa, ν 0.3.
        let shape = HertzShape::from_radii(0.42, f64::INFINITY, 0.30);
        let e = shape.ellipse(122.6e3, &Material::STEEL);
        assert!((e.a / 7.33e-3 - 1.0).abs() < 0.01, "a {}", e.a);
        assert!((e.b / 5.86e-3 - 1.0).abs() < 0.01, "b {}", e.b);
        assert!((e.p0 / 1363e6 - 1.0).abs() < 0.01, "p0 {}", e.p0);
        // Approach and load are inverse.
        let n = shape.load_from_approach(e.approach, &Material::STEEL);
        assert!((n / 122.6e3 - 1.0).abs() < 1e-9);
        // N ∝ δ^{3/2}.
        let n2 = shape.load_from_approach(2.0 * e.approach, &Material::STEEL);
        assert!((n2 / n - 2f64.powf(1.5)).abs() < 1e-9);
    }

    #[test]
    fn elliptic_integrals_known_values() {
        let (k, e) = elliptic_ke(0.0);
        assert!((k - PI / 2.0).abs() < 1e-14 && (e - PI / 2.0).abs() < 1e-14);
        let (k, e) = elliptic_ke((0.5f64).sqrt());
        assert!((k - 1.854_074_677_301_372).abs() < 1e-12);
        assert!((e - 1.350_643_881_047_675_5).abs() < 1e-12);
    }
}
