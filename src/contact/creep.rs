//! Tangential contact: creep force laws.
//!
//! Creepages are normalised by the running speed: longitudinal `ξx`, lateral `ξy` (1), spin
//! `φ` (1/m). Forces are those of the rail on the wheel, in the contact plane, opposing the
//! wheel's slip: Kalker's linear law `Fx = −G·ab·C11·ξx`, `Fy = −G·ab·(C22·ξy + √(ab)·C23·φ)`,
//! saturated by Polach's method (default) or computed by Kalker's FASTSIM (reference).

use super::kalker::KalkerCoefficients;
use std::f64::consts::PI;

/// Creepages at one contact.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Creepage {
    /// Longitudinal creepage ξx.
    pub x: f64,
    /// Lateral creepage ξy.
    pub y: f64,
    /// Spin creepage φ, 1/m.
    pub spin: f64,
}

/// Everything a creep law needs besides the creepages.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CreepContact {
    /// Semi-axis in the rolling direction, m.
    pub a: f64,
    /// Lateral semi-axis, m.
    pub b: f64,
    /// Normal load, N.
    pub normal: f64,
    /// Friction coefficient.
    pub mu: f64,
    /// Shear modulus, Pa.
    pub shear_modulus: f64,
    /// Poisson ratio.
    pub poisson: f64,
    /// Running speed, m/s: the creepages times it are the slip velocities friction falls
    /// with ([`PolachParams`]).
    pub speed: f64,
}

/// Creep forces of the rail on the wheel in the contact plane, N.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct CreepForce {
    /// Longitudinal.
    pub x: f64,
    /// Lateral (in the contact plane).
    pub y: f64,
}

/// Polach's (2005) extension of his method: reduction factors of the adhesion and slip terms
/// and friction that falls with the slip velocity `w`, `μ = μ0·[(1 − A)·e^(−B·w) + A]`
/// (Polach, O. "Creep forces in simulations of traction vehicles running on adhesion
/// limit", Wear 258, 2005, 992–1000). `kA = kS = 1, A = 1` is the 1999 method.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PolachParams {
    /// Reduction factor of the adhesion term, kA (0 < kS ≤ kA ≤ 1).
    pub ka: f64,
    /// Reduction factor of the slip term, kS.
    pub ks: f64,
    /// Friction at infinite slip velocity over the static, A.
    pub floor: f64,
    /// Exponential decrease of friction with slip velocity, B, s/m.
    pub decay: f64,
}

impl Default for PolachParams {
    /// The 1999 method: no reduction, no falling friction.
    fn default() -> Self {
        PolachParams {
            ka: 1.0,
            ks: 1.0,
            floor: 1.0,
            decay: 0.0,
        }
    }
}

impl PolachParams {
    /// Dry rail, Polach 2005's Table 2 as implemented in Open Rails' `Axle.cs` (whose linear
    /// fits in μ0 reproduce the row: A = 0.4, B = 1.6μ0 − 0.28, kA = 2.8μ0 − 0.54,
    /// kS = 1.2μ0 − 0.26 at μ0 = 0.55); the paper's own table not read.
    pub const DRY: PolachParams = PolachParams {
        ka: 1.0,
        ks: 0.4,
        floor: 0.4,
        decay: 0.6,
    };
    /// Wet rail (μ0 = 0.30), the same source.
    pub const WET: PolachParams = PolachParams {
        ka: 0.3,
        ks: 0.1,
        floor: 0.4,
        decay: 0.2,
    };

    /// Friction at slip velocity `w` (m/s) for static friction `mu0`.
    #[inline]
    pub fn friction(&self, mu0: f64, w: f64) -> f64 {
        mu0 * ((1.0 - self.floor) * (-self.decay * w).exp() + self.floor)
    }
}

/// The creep force law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CreepLaw {
    /// Kalker's linear theory, unsaturated (valid for small creepages only).
    Linear,
    /// Polach's method, saturated, with spin: fast, the default (1999's with the default
    /// parameters, 2005's with reduction factors and falling friction).
    Polach(PolachParams),
    /// Kalker's FASTSIM on a grid of `n × n` elements: the reference.
    Fastsim {
        /// Strips across and elements along each strip.
        n: usize,
    },
}

impl Default for CreepLaw {
    /// Polach's 1999 method.
    fn default() -> Self {
        CreepLaw::Polach(PolachParams::default())
    }
}

impl CreepLaw {
    /// Parses `linear`, `polach` or `fastsim`.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "linear" => Some(CreepLaw::Linear),
            "polach" => Some(CreepLaw::default()),
            "fastsim" => Some(CreepLaw::Fastsim { n: 60 }),
            _ => None,
        }
    }

    /// Creep forces for the creepages at a contact.
    pub fn force(&self, c: &CreepContact, s: Creepage) -> CreepForce {
        self.force_with(c, &KalkerCoefficients::new(c.a / c.b, c.poisson), s)
    }

    /// [`Self::force`] with Kalker's coefficients of the contact's ellipse given (the caller
    /// computed them once for this and the step's linearisation).
    pub fn force_with(&self, c: &CreepContact, k: &KalkerCoefficients, s: Creepage) -> CreepForce {
        if c.normal <= 0.0 || c.a <= 0.0 || c.b <= 0.0 {
            return CreepForce::default();
        }
        match self {
            CreepLaw::Linear => linear(c, k, s),
            CreepLaw::Polach(p) => polach(c, k, s, p),
            CreepLaw::Fastsim { n } => fastsim(c, k, s, *n),
        }
    }
}

fn linear(c: &CreepContact, k: &KalkerCoefficients, s: Creepage) -> CreepForce {
    let gab = c.shear_modulus * c.a * c.b;
    CreepForce {
        x: -gab * k.c11 * s.x,
        y: -gab * (k.c22 * s.y + (c.a * c.b).sqrt() * k.c23 * s.spin),
    }
}

/// Polach, O. (1999) "A fast wheel–rail forces calculation computer code", Vehicle System
/// Dynamics 33 (suppl.), 728–739: `F = (2Qμ/π)(ε/(1 + ε²) + atan ε)`,
/// `ε = G·π·a·b·c_jj·s_C/(4Qμ)`, plus the lateral force from spin; with Polach (2005)'s
/// reduction factors `F = (2Qμ/π)(kA·ε/(1 + (kA·ε)²) + atan(kS·ε))` and μ falling with the
/// slip velocity `w = V·√(ξx² + ξy²)` ([`PolachParams`]).
fn polach(c: &CreepContact, k: &KalkerCoefficients, s: Creepage, p: &PolachParams) -> CreepForce {
    let (g, a, b, q) = (c.shear_modulus, c.a, c.b, c.normal);
    // Spin enlarges the effective lateral creepage where it adds to it.
    let syc = if (s.y + s.spin * a).abs() > s.y.abs() {
        s.y + s.spin * a
    } else {
        s.y
    };
    let sc = (s.x * s.x + syc * syc).sqrt();
    let sxy = (s.x * s.x + s.y * s.y).sqrt();
    let mu = p.friction(c.mu, c.speed * sxy);
    let mut fx = 0.0;
    let mut fy = 0.0;
    if sxy > 1e-15 {
        let cjj = ((k.c11 * s.x / sxy).powi(2) + (k.c22 * s.y / sxy).powi(2)).sqrt();
        let eps = g * PI * a * b * cjj * sc / (4.0 * q * mu);
        let (ea, es) = (p.ka * eps, p.ks * eps);
        let f = 2.0 * q * mu / PI * (ea / (1.0 + ea * ea) + es.atan());
        // Polach's F acts along the creepage; the force on the wheel opposes it.
        fx = -f * s.x / sc.max(1e-300);
        fy = -f * s.y / sc.max(1e-300);
    }
    if s.spin != 0.0 && sc > 1e-15 {
        let ab_term = 1.0 + 6.3 * (1.0 - (-a / b).exp());
        let eps_m = 8.0 / 3.0 * g * b * (a * b).sqrt() / (q * mu) * k.c23 * sc / ab_term;
        let d = (eps_m * eps_m - 1.0) / (eps_m * eps_m + 1.0);
        let km = eps_m.abs() * (d.powi(3) / 3.0 - d * d / 2.0 + 1.0 / 6.0)
            - (1.0 - d * d).max(0.0).powf(1.5) / 3.0;
        let fys = -9.0 / 16.0 * a * q * mu * km * ab_term * s.spin / sc;
        fy -= fys;
    } else if s.spin != 0.0 {
        // Pure spin with vanishing creepage: the linear term is the limit.
        fy -= g * a * b * (a * b).sqrt() * k.c23 * s.spin;
    }
    CreepForce { x: fx, y: fy }
}

/// Kalker's FASTSIM (Kalker 1982) with a parabolic traction bound `μ·p`, `p = 2N/(πab)·(1 −
/// x²/a² − y²/b²)`, flexibilities `L1 = 8a/(3GC11)`, `L2 = 8a/(3GC22)`, `L3 = πa√(a/b)/(4GC23)`,
/// `n` strips across the ellipse and `n` elements along each.
fn fastsim(c: &CreepContact, k: &KalkerCoefficients, s: Creepage, n: usize) -> CreepForce {
    let (g, a, b) = (c.shear_modulus, c.a, c.b);
    let l1 = 8.0 * a / (3.0 * g * k.c11);
    let l2 = 8.0 * a / (3.0 * g * k.c22);
    let l3 = PI * a * (a / b).sqrt() / (4.0 * g * k.c23);
    let p0 = 2.0 * c.normal / (PI * a * b);
    let n = n.max(2);
    let dy = 2.0 * b / n as f64;
    let (mut fx, mut fy) = (0.0, 0.0);
    for j in 0..n {
        let y = -b + (j as f64 + 0.5) * dy;
        let ay = a * (1.0 - (y / b).powi(2)).max(0.0).sqrt();
        let dx = 2.0 * ay / n as f64;
        let (mut px, mut py) = (0.0, 0.0);
        for i in 0..n {
            // Element centre, moving from the leading edge x = a(y) to the trailing edge.
            let x = ay - (i as f64 + 0.5) * dx;
            px += (s.x / l1 - y * s.spin / l3) * dx;
            py += (s.y / l2 + x * s.spin / l3) * dx;
            let bound = c.mu * p0 * (1.0 - (x / a).powi(2) - (y / b).powi(2)).max(0.0);
            let mag = (px * px + py * py).sqrt();
            if mag > bound {
                px *= bound / mag;
                py *= bound / mag;
            }
            fx += px * dx * dy;
            fy += py * dx * dy;
        }
    }
    CreepForce { x: -fx, y: -fy }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn contact() -> CreepContact {
        CreepContact {
            a: 6e-3,
            b: 5e-3,
            normal: 100e3,
            mu: 0.3,
            shear_modulus: 82e9,
            poisson: 0.28,
            speed: 20.0,
        }
    }

    #[test]
    fn all_laws_agree_with_linear_theory_at_small_creepage() {
        let c = contact();
        for s in [
            Creepage {
                x: 1e-6,
                y: 0.0,
                spin: 0.0,
            },
            Creepage {
                x: 0.0,
                y: -1e-6,
                spin: 0.0,
            },
            Creepage {
                x: 5e-7,
                y: 5e-7,
                spin: 0.0,
            },
        ] {
            let lin = CreepLaw::Linear.force(&c, s);
            let scale = lin.x.abs().max(lin.y.abs());
            let f = CreepLaw::Fastsim { n: 200 }.force(&c, s);
            assert!((f.x - lin.x).abs() < 0.01 * scale, "{f:?} vs {lin:?}");
            assert!((f.y - lin.y).abs() < 0.01 * scale, "{f:?} vs {lin:?}");
            // Polach keeps the magnitude of the linear force; its direction follows the
            // creepage (exact for pure longitudinal or pure lateral creep).
            let f = CreepLaw::default().force(&c, s);
            let (m, ml) = (f.x.hypot(f.y), lin.x.hypot(lin.y));
            assert!((m / ml - 1.0).abs() < 0.01, "{f:?} vs {lin:?}");
            if s.x == 0.0 || s.y == 0.0 {
                assert!((f.x - lin.x).abs() < 0.01 * scale && (f.y - lin.y).abs() < 0.01 * scale);
            }
        }
        // Spin alone: Polach and FASTSIM give the linear C23 force at tiny spin.
        let s = Creepage {
            x: 0.0,
            y: 0.0,
            spin: 1e-5,
        };
        let lin = CreepLaw::Linear.force(&c, s);
        let fs = CreepLaw::Fastsim { n: 200 }.force(&c, s);
        assert!((fs.y / lin.y - 1.0).abs() < 0.02, "{fs:?} {lin:?}");
    }

    #[test]
    fn saturated_force_is_mu_n_and_opposes_slip() {
        let c = contact();
        for law in [CreepLaw::default(), CreepLaw::Fastsim { n: 60 }] {
            let f = law.force(
                &c,
                Creepage {
                    x: 0.1,
                    y: 0.0,
                    spin: 0.0,
                },
            );
            assert!(f.x < 0.0);
            assert!(
                (f.x.abs() / (c.mu * c.normal) - 1.0).abs() < 0.02,
                "{law:?} {f:?}"
            );
            let f = law.force(
                &c,
                Creepage {
                    x: 0.05,
                    y: -0.05,
                    spin: 0.0,
                },
            );
            let mag = (f.x * f.x + f.y * f.y).sqrt();
            assert!(
                mag <= c.mu * c.normal * 1.002 && mag > 0.95 * c.mu * c.normal,
                "{law:?} {f:?}"
            );
            assert!(f.x < 0.0 && f.y > 0.0);
        }
    }

    /// Polach 2005: the dry set's curve rises with kA's slope at small creepage, peaks, and
    /// falls towards A·μ0·Q at large slip; the default parameters are the 1999 method bit for
    /// bit.
    #[test]
    fn polach_2005_reduces_the_slope_and_friction_falls_with_slip() {
        let c = contact();
        let at = |law: CreepLaw, x: f64| {
            law.force(
                &c,
                Creepage {
                    x,
                    y: 0.0,
                    spin: 0.0,
                },
            )
            .x
            .abs()
        };
        let (p99, dry) = (CreepLaw::default(), CreepLaw::Polach(PolachParams::DRY));
        // Small creepage: the 2005 form's slope is (kA + kS)/2 of Kalker's (ε/(1+ε²) ≈ ε and
        // atan ε ≈ ε give (2Qμ/π)·2ε for kA = kS = 1).
        let x = 1e-7;
        let ratio = at(dry, x) / at(p99, x);
        let want = (PolachParams::DRY.ka + PolachParams::DRY.ks) / 2.0;
        assert!((ratio - want).abs() < 1e-3, "{ratio} vs {want}");
        // Large slip: 1999 tends to μ0·Q; 2005 falls with w = V·ξ towards A·μ0·Q.
        let mu0q = c.mu * c.normal;
        assert!((at(p99, 0.5) / mu0q - 1.0).abs() < 0.02);
        let w = c.speed * 0.5;
        let mu_w = PolachParams::DRY.friction(c.mu, w);
        assert!((mu_w / c.mu - (0.6 * (-0.6 * w).exp() + 0.4)).abs() < 1e-12);
        assert!(at(dry, 0.5) < mu_w * c.normal * 1.0001);
        // The curve peaks, then falls (an adhesion maximum).
        let curve: Vec<f64> = (1..200).map(|i| at(dry, i as f64 * 1e-3)).collect();
        let peak = curve.iter().cloned().fold(0.0, f64::max);
        assert!(*curve.last().unwrap() < 0.9 * peak, "no fall: {curve:?}");
        // The default parameters reproduce the 1999 formula exactly.
        let eps_check = {
            let k = KalkerCoefficients::new(c.a / c.b, c.poisson);
            let s = 3e-3;
            let eps = c.shear_modulus * PI * c.a * c.b * k.c11 * s / (4.0 * c.normal * c.mu);
            2.0 * c.normal * c.mu / PI * (eps / (1.0 + eps * eps) + eps.atan())
        };
        assert_eq!(at(p99, 3e-3), eps_check);
    }
}
