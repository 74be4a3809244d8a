//! Running resistance of a vehicle: basic (the Chinese traction calculation regulation's
//! quadratic in speed), curve (600/R N/kN) and grade (exact: m·g·sin θ).
//!
//! The regulation writes unit resistances in N per kN of weight with the speed in km/h; this
//! module keeps that form for the file's coefficients and returns forces in N.

use super::smooth_sign;
use crate::GRAVITY;

/// The speed scale, m/s, below which resistance and shoe friction fade smoothly to zero (a
/// smooth sign of the velocity), so a stopping train comes to rest instead of reversing.
pub const STOP_SPEED: f64 = 0.05;

/// Basic running resistance `w₀ = a + b·v + c·v²`, N/kN, with `v` in km/h (the regulation's
/// form; the coefficients and their sources are in the consist file).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BasicResistance {
    /// Constant term, N/kN.
    pub a: f64,
    /// Linear term, N/kN per km/h.
    pub b: f64,
    /// Quadratic term, N/kN per (km/h)².
    pub c: f64,
}

impl BasicResistance {
    /// Unit resistance at speed `v` (m/s, either sign: the magnitude is used), N/kN.
    pub fn per_kn(&self, v: f64) -> f64 {
        let k = v.abs() * 3.6;
        self.a + self.b * k + self.c * k * k
    }

    /// Resistance force on a vehicle of `mass` kg at velocity `v` m/s, N, opposing the motion
    /// (negative when moving in +s), and its derivative in `v`, N·s/m.
    pub fn force(&self, mass: f64, v: f64) -> (f64, f64) {
        let weight_kn = mass * GRAVITY / 1000.0;
        let k = v.abs() * 3.6;
        let w = self.a + self.b * k + self.c * k * k;
        let dw = (self.b + 2.0 * self.c * k) * 3.6; // per m/s of |v|
        let (sg, dsg) = smooth_sign(v, STOP_SPEED);
        let f = -weight_kn * w * sg;
        // d|v|/dv · sg = sign(v) · sg ≥ 0.
        let df = -weight_kn * (dw * v.signum() * sg + w * dsg);
        (f, df)
    }
}

/// Curve resistance, N/kN, at curvature `kappa` (1/m, either sign): 600/R, the regulation's
/// form for a vehicle wholly in the curve.
pub fn curve_per_kn(kappa: f64) -> f64 {
    600.0 * kappa.abs()
}

/// Curve resistance force, N, on a vehicle of `mass` kg moving at `v` m/s through curvature
/// `kappa`: opposing the motion.
pub fn curve_force(mass: f64, kappa: f64, v: f64) -> f64 {
    -mass * GRAVITY / 1000.0 * curve_per_kn(kappa) * smooth_sign(v, STOP_SPEED).0
}

/// Grade force on a vehicle of `mass` kg on grade `i` (rise over run), N along +s: −m·g·sin θ
/// with tan θ = i (exact; the regulation's `i` N/kN is its small-angle form).
pub fn grade_force(mass: f64, i: f64) -> f64 {
    -mass * GRAVITY * i / (1.0 + i * i).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    const LOADED: BasicResistance = BasicResistance {
        a: 0.92,
        b: 0.0048,
        c: 0.000125,
    };

    #[test]
    fn the_loaded_wagon_formula_at_60_kmh() {
        // 0.92 + 0.0048·60 + 0.000125·3600 = 1.658 N/kN.
        let w = LOADED.per_kn(60.0 / 3.6);
        assert!((w - 1.658).abs() < 1e-12, "{w}");
        let (f, _) = LOADED.force(100e3, 60.0 / 3.6);
        assert!(
            (f + 100e3 * GRAVITY * 1.658e-3).abs() < 1e-5 * f.abs(),
            "{f}"
        );
    }

    #[test]
    fn resistance_opposes_motion_and_its_slope_is_right() {
        let (f, _) = LOADED.force(100e3, -10.0);
        assert!(f > 0.0);
        for v in [-3.0, -0.01, 0.02, 0.3, 12.0] {
            let h = 1e-6;
            let num = (LOADED.force(1e5, v + h).0 - LOADED.force(1e5, v - h).0) / (2.0 * h);
            let ana = LOADED.force(1e5, v).1;
            assert!(
                (num - ana).abs() < 1e-4 * ana.abs().max(1.0),
                "{v}: {num} {ana}"
            );
        }
    }

    #[test]
    fn curve_and_grade() {
        assert!((curve_per_kn(1.0 / 800.0) - 0.75).abs() < 1e-12);
        assert!((curve_per_kn(-1.0 / 600.0) - 1.0).abs() < 1e-12);
        let g = grade_force(1000.0, 0.02);
        assert!((g + 1000.0 * GRAVITY * 0.02 / (1.0004f64).sqrt()).abs() < 1e-9);
        assert!(curve_force(1000.0, 1.0 / 600.0, 20.0) < 0.0);
    }
}
