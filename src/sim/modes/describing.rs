//! Friction by its describing function: each friction element replaced by the stiffness and
//! damping that carry the first harmonic of its force over the cycle of the mode it takes part
//! in, at the cycle's amplitude (equivalent linearisation, Krylov–Bogoliubov; for one
//! elasto-plastic slider of stick stiffness `k` and slip force `F` at displacement amplitude
//! `D > F/k` it gives `k·(β − ½·sin 2β)/π` with `cos β = 1 − 2F/(k·D)`, and the damping that
//! dissipates `4F·(D − F/k)` per cycle).
//!
//! Nothing is written twice: the element's own force (its `apply`, sliders and memory as in a
//! run) is driven through the cycle, and the first harmonic of its friction part (the element
//! less the same element frictionless) is compared with the first harmonic of its stuck part
//! (the same cycle at a vanishing amplitude). Their ratio `c = κ + iη` scales the element's part
//! of the stuck state matrix: `κ` its stiffness, `iη` a quadrature term that is damping. The
//! cycle is the least damped mode's, scaled so that the vehicle's first wheelset moves
//! `amplitude` laterally (the amplitude the contact is quasi-linearised at), and the mode and
//! the factors are iterated to a fixed point.

use super::linear::Linear;
use super::linear_config;
use crate::error::Result;
use crate::sim::Simulation;
use crate::track::Track;
use crate::vehicle::Vehicle;
use nalgebra::{Complex, DMatrix, DVector};

/// Fixed-point iterations at most, and the change of every factor that ends them.
const ITERATIONS: usize = 40;
const TOLERANCE: f64 = 1e-3;

/// The state matrix of `v` (linear creep, friction elements as they are: stuck in the
/// linearisation) at `speed` with every friction element replaced by its describing function
/// at `amplitude`. `lin` is the linearisation of `v` at `speed`, equilibrated.
pub(super) fn equivalent_matrix(
    lin: &mut Linear<'_>,
    v: &Vehicle,
    track: &Track,
    speed: f64,
    amplitude: f64,
    max_frequency: f64,
) -> Result<DMatrix<f64>> {
    let stuck = lin.jacobian(amplitude)?;
    // Each friction element's part of the stuck matrix: stuck less that element frictionless.
    let mut parts = Vec::new();
    for (e, element) in v.elements.iter().enumerate() {
        let mut free = element.clone();
        free.frictionless();
        if free == *element {
            continue;
        }
        let mut ve = v.clone();
        ve.elements[e] = free.clone();
        let mut le = Linear::new(Simulation::new(&ve, track, linear_config(speed))?);
        le.equilibrate();
        let part = &stuck - le.jacobian(amplitude)?;
        parts.push((e, free, part));
    }
    let bodies = 12 * v.bodies.len();
    let assemble = |factors: &[Complex<f64>], omega: f64| {
        let mut a = stuck.clone();
        for ((_, _, part), c) in parts.iter().zip(factors) {
            a += part * (c.re - 1.0);
            if c.im != 0.0 && omega > 0.0 {
                // i·η·(K + iωC)·x̂ in time: (η/ω)·K·ẋ − η·ω·C·x.
                for j in 0..bodies {
                    let (k, dof) = (j / 12, j % 12);
                    let (to, gain) = if dof < 6 {
                        (12 * k + dof + 6, c.im / omega)
                    } else {
                        (12 * k + dof - 6, -c.im * omega)
                    };
                    let col = part.column(j) * gain;
                    let mut target = a.column_mut(to);
                    target += col;
                }
            }
        }
        a
    };
    let mut factors = vec![Complex::new(1.0, 0.0); parts.len()];
    let mut omega = 0.0;
    for _ in 0..ITERATIONS {
        let a = assemble(&factors, omega);
        let Some((l, shape)) = lin.least_damped(&a, max_frequency) else {
            break;
        };
        omega = l.im;
        let lead = shape[lin.leading_lateral()].norm();
        if lead < 1e-12 {
            break; // a mode the wheelsets take no part in: no cycle amplitude to scale by
        }
        let scale = amplitude / lead;
        let tiny = 1e-4 * scale;
        let mut change = 0.0f64;
        for ((e, free, _), c) in parts.iter().zip(factors.iter_mut()) {
            let element = &v.elements[*e];
            let mut friction = |s: f64| {
                lin.element_harmonic(element, *e, &shape, s)
                    - lin.element_harmonic(free, *e, &shape, s)
            };
            let g = friction(scale);
            let g_stuck = friction(tiny) * Complex::new(scale / tiny, 0.0);
            let Some(new) = factor(&g, &g_stuck) else {
                continue;
            };
            let next = (*c + new) * 0.5;
            change = change.max((next - *c).norm());
            *c = next;
        }
        if change < TOLERANCE {
            break;
        }
    }
    Ok(assemble(&factors, omega))
}

/// The describing function's factor `c = κ + iη` that best carries the friction's first
/// harmonic `g` as a multiple of the stuck element's `g_stuck` (least squares:
/// `c = ⟨g_stuck, g⟩ / ⟨g_stuck, g_stuck⟩`); `None` when the stuck element carries nothing.
fn factor(g: &DVector<Complex<f64>>, g_stuck: &DVector<Complex<f64>>) -> Option<Complex<f64>> {
    let norm = g_stuck.dotc(g_stuck).re;
    (norm > 0.0).then(|| g_stuck.dotc(g) / norm)
}

#[cfg(test)]
mod tests {
    use super::super::linear::harmonic_weight;
    use super::*;

    /// An elasto-plastic slider (stick stiffness `k`, slip force `f`) driven through
    /// `x = D·cos θ`: the first harmonic of its force, as `element_harmonic` takes it.
    fn slider_harmonic(k: f64, f: f64, d: f64) -> DVector<Complex<f64>> {
        const STEPS: usize = 512;
        let mut slip = 0.0;
        let mut h = Complex::new(0.0, 0.0);
        for n in 0..2 * STEPS {
            let theta = 2.0 * std::f64::consts::PI * n as f64 / STEPS as f64;
            let x = d * theta.cos();
            let mut force = k * (x - slip);
            if force.abs() > f {
                force = f * force.signum();
                slip = x - force / k;
            }
            if n >= STEPS {
                h += harmonic_weight(n, STEPS) * force;
            }
        }
        DVector::from_element(1, h)
    }

    /// The factor of a slider equals the closed form: stiffness `k·(β − ½·sin 2β)/π` with
    /// `cos β = 1 − 2F/(k·D)`, and the quadrature part that dissipates `4F·(D − F/k)` per
    /// cycle (`π·η·k·D²`); stuck below the slip amplitude.
    #[test]
    fn slider_factor_is_the_closed_form_describing_function() {
        let (k, f) = (2.0e7, 5.0e3); // the wedges' stick stiffness; F/k = 0.25 mm
        for d in [0.1e-3, 0.5e-3, 1e-3, 3e-3] {
            let stuck = slider_harmonic(k, f, 1e-9) * Complex::new(d / 1e-9, 0.0);
            let c = factor(&slider_harmonic(k, f, d), &stuck).unwrap();
            let (kappa, eta) = if d <= f / k {
                (1.0, 0.0)
            } else {
                let beta = (1.0 - 2.0 * f / (k * d)).acos();
                let dissipated = 4.0 * f * (d - f / k);
                (
                    (beta - 0.5 * (2.0 * beta).sin()) / std::f64::consts::PI,
                    dissipated / (std::f64::consts::PI * k * d * d),
                )
            };
            assert!((c.re - kappa).abs() < 0.01, "D {d}: κ {} vs {kappa}", c.re);
            assert!((c.im - eta).abs() < 0.01, "D {d}: η {} vs {eta}", c.im);
        }
    }
}
