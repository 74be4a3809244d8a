//! Sperling's ride index Wz from a carbody acceleration, in the form the Chinese standard
//! quotes (secondary: GB 5599, as commonly reproduced): each spectral line of peak amplitude
//! A (in g) at frequency f contributes `W = 7.08·(A³·F(f)/f)^{1/10}` and the lines combine as
//! `Wz = (Σ W¹⁰)^{1/10}`; `F(f)` weights vertical and lateral motion apart.

use crate::dsp::amplitude_spectrum;

/// Direction of the acceleration.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// Vertical.
    Vertical,
    /// Lateral.
    Lateral,
}

/// Sperling's frequency weighting `F(f)`: vertical `0.325·f²` (0.5–5.9 Hz), `400/f²`
/// (5.9–20 Hz), 1 above; lateral `0.8·f²` (0.5–5.4 Hz), `650/f²` (5.4–26 Hz), 1 above.
pub fn weight(f: f64, dir: Direction) -> f64 {
    let (k_low, corner, k_high, top) = match dir {
        Direction::Vertical => (0.325, 5.9, 400.0, 20.0),
        Direction::Lateral => (0.8, 5.4, 650.0, 26.0),
    };
    if f < corner {
        k_low * f * f
    } else if f < top {
        k_high / (f * f)
    } else {
        1.0
    }
}

/// Wz of an acceleration record (m/s²) sampled at `fs`, over the spectral lines in
/// `band` (Hz; Sperling's 0.5–30 Hz by default in the criteria).
pub fn sperling(acc: &[f64], fs: f64, dir: Direction, band: (f64, f64)) -> f64 {
    let sum: f64 = amplitude_spectrum(acc, fs)
        .into_iter()
        .filter(|(f, _)| *f >= band.0 && *f <= band.1)
        .map(|(f, a)| {
            let a_g = a / crate::GRAVITY;
            a_g.powi(3) * weight(f, dir) / f
        })
        .sum();
    7.08 * sum.powf(0.1)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A single 2 Hz vertical sine of 0.1 g over a whole number of periods: by hand,
    /// F(2) = 0.325·4 = 1.3, W = 7.08·(0.1³·1.3/2)^{0.1} = 7.08·(6.5e-4)^{0.1} = 3.3988.
    #[test]
    fn wz_of_a_single_sine_matches_the_formula() {
        let fs = 200.0;
        let a: Vec<f64> = (0..2000)
            .map(|i| {
                0.1 * crate::GRAVITY * (2.0 * std::f64::consts::PI * 2.0 * i as f64 / fs).sin()
            })
            .collect();
        let w = sperling(&a, fs, Direction::Vertical, (0.5, 30.0));
        assert!((w - 3.3988).abs() < 1e-4, "{w}");
        // Lateral weighting of the same motion: F = 0.8·4 = 3.2.
        let wl = sperling(&a, fs, Direction::Lateral, (0.5, 30.0));
        let by_hand = 7.08 * (1e-3 * 3.2 / 2.0f64).powf(0.1);
        assert!((wl - by_hand).abs() < 1e-9, "{wl} vs {by_hand}");
        // The weighting nearly meets at its corner (0.325·5.9² = 11.3, 400/5.9² = 11.5).
        assert!(
            (weight(5.9 - 1e-9, Direction::Vertical) / weight(5.9, Direction::Vertical) - 1.0)
                .abs()
                < 0.02
        );
    }
}
