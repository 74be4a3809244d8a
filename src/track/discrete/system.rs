//! One wavenumber's small system of the discrete track: its masses, springs and dampers, and
//! its step ([`super::dynamics`] explains the decomposition and the step).

use nalgebra::{SMatrix, SVector};

/// The largest `ω·Δt` of a rail degree of freedom's free frequency that the step follows
/// (Fox and Goodwin's share, stable below 2.45); above it, backward Euler damps it.
pub(super) const FOLLOWED: f64 = 1.0;

/// One wavenumber's mass, stiffness and damping (`D` degrees of freedom).
#[derive(Debug, Clone, Copy)]
pub(super) struct System<const D: usize> {
    /// The rails' bending or twisting stiffness (diagonal; zero off the rails).
    pub bend: SVector<f64, D>,
    k: SMatrix<f64, D, D>,
    c: SMatrix<f64, D, D>,
    /// `(M + Δt/2·C + Δt²/12·K + Δt²·B)⁻¹` at the current step (`B` the rail degrees of
    /// freedom taken backward Euler, [`System::factor`]).
    pub inv: SMatrix<f64, D, D>,
    /// The step's free velocity change from the displacement and from the velocity:
    /// `−Δt·inv·(K + B)` and `−Δt·inv·(C + Δt·B)`.
    pub from_x: SMatrix<f64, D, D>,
    pub from_v: SMatrix<f64, D, D>,
    m: SVector<f64, D>,
}

impl<const D: usize> System<D> {
    /// No spring yet, masses (or inertias) `m`.
    pub fn new(m: SVector<f64, D>) -> Self {
        let zero = SMatrix::<f64, D, D>::zeros();
        System {
            bend: SVector::zeros(),
            k: zero,
            c: zero,
            inv: zero,
            from_x: zero,
            from_v: zero,
            m,
        }
    }

    /// Adds a spring `k` and damper `c` whose elongation is `e·x`.
    pub fn spring(&mut self, e: SVector<f64, D>, k: f64, c: f64) {
        self.k += e * e.transpose() * k;
        self.c += e * e.transpose() * c;
    }

    /// Builds the step at `dt`. Each rail degree of freedom is taken by its free frequency
    /// `ω` (its bending and its own pad stiffness on its mass): at Fox and Goodwin's share with
    /// the rest of the track where `ω·Δt ≤ followed`, else backward Euler.
    pub fn factor(&mut self, dt: f64, followed: f64) {
        let mut k = self.k;
        let mut backward = SVector::<f64, D>::zeros();
        for d in (0..D).filter(|&d| self.bend[d] > 0.0) {
            let stiff = self.bend[d] + self.k[(d, d)];
            if stiff * dt * dt > followed * followed * self.m[d] {
                backward[d] = stiff;
                k[(d, d)] = 0.0;
            } else {
                k[(d, d)] = stiff;
            }
        }
        let b = SMatrix::<f64, D, D>::from_diagonal(&backward);
        let a = SMatrix::<f64, D, D>::from_diagonal(&self.m)
            + self.c * (0.5 * dt)
            + k * (dt * dt / 12.0)
            + b * (dt * dt);
        self.inv = a.try_inverse().unwrap_or_else(SMatrix::zeros);
        self.from_x = self.inv * (k + b) * -dt;
        self.from_v = self.inv * (self.c + b * dt) * -dt;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A rail wave the step follows (`ω·Δt` 0.5) keeps its amplitude, undamped, over a thousand
    /// steps; one it does not follow (`ω·Δt` 2) is damped away by backward Euler.
    #[test]
    fn followed_rail_waves_ring_and_the_others_are_damped() {
        let amplitude = |wdt: f64| {
            let (dt, w) = (1e-4, wdt / 1e-4);
            let mut s = System::new(SVector::<f64, 1>::new(2.0));
            s.bend[0] = 2.0 * w * w;
            s.factor(dt, FOLLOWED);
            let (mut x, mut v, mut last) = (1e-3, 0.0, 0.0f64);
            for i in 0..1000 {
                v += s.from_x[(0, 0)] * x + s.from_v[(0, 0)] * v;
                x += v * dt;
                if i >= 900 {
                    last = last.max(x.abs());
                }
            }
            last / 1e-3
        };
        let kept = amplitude(0.5);
        assert!((kept - 1.0).abs() < 0.05, "{kept}");
        let damped = amplitude(2.0);
        assert!(damped < 1e-3, "{damped}");
    }
}
