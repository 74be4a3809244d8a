//! What the discrete track does in frequency: its point receptance from an impulse response,
//! and the cut-on frequencies of the periodic track (the whole track moving in phase, where
//! its first waves start to travel).

use super::{DiscreteSupport, Load, TrackDynamics};
use rustfft::FftPlanner;
use rustfft::num_complex::Complex64;

/// The track's vertical cut-on frequencies, Hz: the eigenfrequencies of one rail seat's chain
/// moving in phase with its neighbours (a bay's rail on the pad on half a sleeper on the
/// ballast block on the subgrade; no shear, no roll), lowest first: derived here, not
/// published. Zhai's 2004 set: 52 Hz (the whole track on the subgrade), 157 Hz (the sleeper
/// between pad and ballast) and 263 Hz (the rail on its pads).
pub fn cut_on_frequencies(p: &DiscreteSupport) -> [f64; 3] {
    let m = [
        p.rail_mass * p.spacing,
        0.5 * p.sleeper_mass,
        p.ballast_mass,
    ];
    let (kp, kb, kf) = (
        p.pad_vertical.stiffness,
        p.ballast.stiffness,
        p.subgrade.stiffness,
    );
    let k = nalgebra::Matrix3::new(kp, -kp, 0.0, -kp, kp + kb, -kb, 0.0, -kb, kb + kf);
    let s = nalgebra::Matrix3::from_diagonal(&nalgebra::Vector3::from(m.map(|x| 1.0 / x.sqrt())));
    let mut w: Vec<f64> = (s * k * s)
        .symmetric_eigenvalues()
        .iter()
        .map(|l| l.max(0.0).sqrt() / (2.0 * std::f64::consts::PI))
        .collect();
    w.sort_by(f64::total_cmp);
    [w[0], w[1], w[2]]
}

/// The frequencies of a receptance's peaks from `from_hz` on, Hz (local maxima of `|H|`).
pub fn peaks(r: &[(f64, f64)], from_hz: f64) -> Vec<f64> {
    r.windows(3)
        .filter(|w| w[0].0 >= from_hz && w[1].1 > w[0].1 && w[1].1 >= w[2].1)
        .map(|w| w[1].0)
        .collect()
}

/// The vertical point receptance of one rail with both rails struck alike at `offset` m from
/// a sleeper (0: over it, half the spacing: mid-span), m/N, at the frequencies of an impulse
/// response of `seconds` at step `dt`: `(f Hz, |H|)` from 0 to `f_max`.
pub fn receptance(
    p: DiscreteSupport,
    offset: f64,
    dt: f64,
    seconds: f64,
    f_max: f64,
) -> Vec<(f64, f64)> {
    let centre = 0.5 * p.window();
    let mut t = TrackDynamics::new(p, centre);
    let s = t.start() + (0.5 * p.bays as f64).floor() * p.spacing + offset;
    let n = (seconds / dt).round() as usize;
    // A unit impulse over the first step, then free vibration.
    let strike = Load::wheelset(s, 0.0, 1.0 / dt);
    let mut x: Vec<Complex64> = Vec::with_capacity(n);
    t.step(dt, &strike);
    x.push(Complex64::new(t.rail(0, s)[2], 0.0));
    for _ in 1..n {
        t.step(dt, &[]);
        x.push(Complex64::new(t.rail(0, s)[2], 0.0));
    }
    FftPlanner::new().plan_fft_forward(n).process(&mut x);
    let df = 1.0 / (n as f64 * dt);
    x.iter()
        .enumerate()
        .map(|(i, h)| (i as f64 * df, h.norm() * dt))
        .take_while(|(f, _)| *f <= f_max)
        .collect()
}
