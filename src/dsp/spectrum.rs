//! Amplitude spectrum of a record.

use rustfft::FftPlanner;
use rustfft::num_complex::Complex64;

/// One-sided peak-amplitude spectrum of `x` sampled at `fs` (Hz), mean removed, rectangular
/// window: a sine of amplitude A at a bin frequency gives A at that bin. Returns `(f, A)` for
/// the bins 1 … n/2.
pub fn amplitude_spectrum(x: &[f64], fs: f64) -> Vec<(f64, f64)> {
    let n = x.len();
    if n < 2 {
        return Vec::new();
    }
    let mean = x.iter().sum::<f64>() / n as f64;
    let mut buf: Vec<Complex64> = x.iter().map(|&v| Complex64::new(v - mean, 0.0)).collect();
    FftPlanner::<f64>::new()
        .plan_fft_forward(n)
        .process(&mut buf);
    (1..=n / 2)
        .map(|k| {
            // The Nyquist bin of an even record is not doubled.
            let scale = if 2 * k == n { 1.0 } else { 2.0 };
            (k as f64 * fs / n as f64, scale * buf[k].norm() / n as f64)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_sine_on_a_bin_has_its_amplitude() {
        let fs = 200.0;
        let x: Vec<f64> = (0..2000)
            .map(|i| 5.0 + 0.3 * (2.0 * std::f64::consts::PI * 2.0 * i as f64 / fs).sin())
            .collect();
        let s = super::amplitude_spectrum(&x, fs);
        let at2 = s.iter().find(|p| (p.0 - 2.0).abs() < 1e-9).unwrap();
        assert!((at2.1 - 0.3).abs() < 1e-12);
        assert!(
            s.iter()
                .filter(|p| (p.0 - 2.0).abs() > 1e-9)
                .all(|p| p.1 < 1e-12)
        );
    }
}
