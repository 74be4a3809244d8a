//! Welch's averaged periodogram (Hann window, 50 % overlap, one-sided, linear detrend off).

use rustfft::FftPlanner;
use rustfft::num_complex::Complex64;

/// A one-sided power spectral density estimate.
#[derive(Debug, Clone)]
pub struct WelchPsd {
    /// Frequencies, cycles per unit of the sampling variable (Hz for time, 1/m for distance).
    pub freq: Vec<f64>,
    /// Density, (signal unit)² per frequency unit.
    pub density: Vec<f64>,
    /// Number of averaged segments.
    pub segments: usize,
}

/// Welch PSD of `x` sampled every `dx`, with segments of `nperseg` samples (rounded down to a
/// power of two is not required) overlapping by half. The mean of each segment is removed. The
/// density integrates (sum × df) to the variance of `x`.
pub fn welch_psd(x: &[f64], dx: f64, nperseg: usize) -> WelchPsd {
    let nperseg = nperseg.min(x.len()).max(2);
    let step = (nperseg / 2).max(1);
    let window: Vec<f64> = (0..nperseg)
        .map(|i| 0.5 - 0.5 * (2.0 * std::f64::consts::PI * i as f64 / nperseg as f64).cos())
        .collect();
    let wss: f64 = window.iter().map(|w| w * w).sum();
    let fft = FftPlanner::<f64>::new().plan_fft_forward(nperseg);
    let nf = nperseg / 2 + 1;
    let mut acc = vec![0.0; nf];
    let mut segments = 0;
    let mut buf = vec![Complex64::new(0.0, 0.0); nperseg];
    let mut start = 0;
    while start + nperseg <= x.len() {
        let seg = &x[start..start + nperseg];
        let mean = seg.iter().sum::<f64>() / nperseg as f64;
        for ((b, &v), &w) in buf.iter_mut().zip(seg).zip(&window) {
            *b = Complex64::new((v - mean) * w, 0.0);
        }
        fft.process(&mut buf);
        for (a, b) in acc.iter_mut().zip(&buf) {
            *a += b.norm_sqr();
        }
        segments += 1;
        start += step;
    }
    let fs = 1.0 / dx;
    let scale = 1.0 / (fs * wss * segments.max(1) as f64);
    let density = acc
        .iter()
        .enumerate()
        .map(|(k, &a)| {
            // One-sided: double every bin but DC and Nyquist.
            let twice = k != 0 && !(nperseg.is_multiple_of(2) && k == nf - 1);
            a * scale * if twice { 2.0 } else { 1.0 }
        })
        .collect();
    let freq = (0..nf).map(|k| k as f64 * fs / nperseg as f64).collect();
    WelchPsd {
        freq,
        density,
        segments,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn white_noise_density_integrates_to_variance() {
        // A sine of amplitude 1 has variance 1/2: the PSD must integrate to it.
        let dx = 0.01;
        let x: Vec<f64> = (0..100_000)
            .map(|i| (2.0 * std::f64::consts::PI * 5.0 * i as f64 * dx).sin())
            .collect();
        let p = welch_psd(&x, dx, 1024);
        let df = p.freq[1] - p.freq[0];
        let var: f64 = p.density.iter().sum::<f64>() * df;
        assert!((var - 0.5).abs() < 0.01, "variance {var}");
        let peak = p
            .density
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1))
            .unwrap()
            .0;
        assert!((p.freq[peak] - 5.0).abs() < 0.1);
    }
}
