//! A locomotive's tractive and dynamic-brake effort against speed.
//!
//! Traction: the starting effort up to the speed where the continuous power takes over, then a
//! constant-power hyperbola through the continuous rating (for the HXD1, 700 kN starting and
//! 494 kN at 70 km/h, i.e. 9.6 MW). Dynamic brake: its maximum up to a speed, then constant
//! power (for the HXD1, 461 kN up to 75 km/h and 288 kN at 120 km/h: the same 9.6 MW), and
//! below a low speed a linear fade to zero (the figure is an estimate). The effort at a notch
//! is the notch's share of the curve. The curves' corners are the public points; the shape
//! between them (flat, then hyperbolic) is an estimate.

/// A locomotive's effort curves (the consist file's `traction` and `dynamic_brake` tables).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Locomotive {
    /// Starting tractive effort, N.
    pub max_traction: f64,
    /// Power of the constant-power part of the traction curve, W.
    pub traction_power: f64,
    /// Maximum dynamic-brake effort, N.
    pub max_dynamic_brake: f64,
    /// Power of the constant-power part of the dynamic-brake curve, W.
    pub dynamic_brake_power: f64,
    /// Below this speed the dynamic brake fades linearly to zero, m/s.
    pub dynamic_brake_fade: f64,
}

impl Locomotive {
    /// The full tractive effort at speed `v` (m/s, magnitude used), N, and its derivative in
    /// `|v|`.
    pub fn traction(&self, v: f64) -> (f64, f64) {
        let v = v.abs();
        if v * self.max_traction <= self.traction_power {
            (self.max_traction, 0.0)
        } else {
            let f = self.traction_power / v;
            (f, -f / v)
        }
    }

    /// The full dynamic-brake effort at speed `v` (m/s, magnitude used), N (a magnitude: it
    /// opposes the motion), and its derivative in `|v|`.
    pub fn dynamic_brake(&self, v: f64) -> (f64, f64) {
        let v = v.abs();
        let (f, df) = if v * self.max_dynamic_brake <= self.dynamic_brake_power {
            (self.max_dynamic_brake, 0.0)
        } else {
            let f = self.dynamic_brake_power / v;
            (f, -f / v)
        };
        if v < self.dynamic_brake_fade {
            let r = v / self.dynamic_brake_fade;
            (f * r, df * r + f / self.dynamic_brake_fade)
        } else {
            (f, df)
        }
    }

    /// The effort along +s at control `u ∈ [−1, 1]` (positive: that share of full traction;
    /// negative: that share of full dynamic brake, opposing the motion) and velocity `v`, N.
    pub fn effort(&self, u: f64, v: f64) -> f64 {
        if u >= 0.0 {
            u * self.traction(v).0
        } else {
            u * self.dynamic_brake(v).0 * v.signum()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hxd1() -> Locomotive {
        Locomotive {
            max_traction: 700e3,
            traction_power: 494e3 * 70.0 / 3.6,
            max_dynamic_brake: 461e3,
            dynamic_brake_power: 461e3 * 75.0 / 3.6,
            dynamic_brake_fade: 10.0 / 3.6,
        }
    }

    #[test]
    fn hxd1_curves_pass_the_public_points() {
        let l = hxd1();
        assert_eq!(l.traction(0.0).0, 700e3);
        assert!((l.traction(70.0 / 3.6).0 - 494e3).abs() < 1e-6);
        assert!((l.dynamic_brake(60.0 / 3.6).0 - 461e3).abs() < 1e-6);
        // 461 kN · 75 / 120 = 288.1 kN: the public 288 kN at 120 km/h
        assert!((l.dynamic_brake(120.0 / 3.6).0 - 288e3).abs() < 0.5e3);
        assert_eq!(l.dynamic_brake(0.0).0, 0.0);
        assert!((l.dynamic_brake(5.0 / 3.6).0 - 230.5e3).abs() < 1.0);
    }

    #[test]
    fn effort_sign_follows_the_control() {
        let l = hxd1();
        assert!(l.effort(0.5, 10.0) > 0.0);
        assert!(l.effort(-0.5, 10.0) < 0.0);
        assert_eq!(l.effort(-1.0, 0.0), 0.0);
        let h = 1e-6;
        for v in [1.0, 5.0, 15.0, 25.0] {
            let d = (l.dynamic_brake(v + h).0 - l.dynamic_brake(v - h).0) / (2.0 * h);
            assert!((d - l.dynamic_brake(v).1).abs() < 1e-3 * d.abs().max(1.0));
            let d = (l.traction(v + h).0 - l.traction(v - h).0) / (2.0 * h);
            assert!((d - l.traction(v).1).abs() < 1e-3 * d.abs().max(1.0));
        }
    }
}
