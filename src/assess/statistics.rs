//! Statistics of acceptance assessment: the sliding mean over track distance, percentiles
//! (see [`crate::dsp::percentile`]) and the quasi-static value of a section.

/// Sliding mean of `x` over windows `window` metres long of the positions `s`, centred every
/// `step` metres from the first position plus half a window to the last minus half a window
/// (EN 14363's (Y/Q)2m and (ΣY)2m: 2 m every 0.5 m). A window holding no sample is skipped.
/// Returns `(centre, mean)`.
pub fn sliding_mean(s: &[f64], x: &[f64], window: f64, step: f64) -> Vec<(f64, f64)> {
    let mut pairs: Vec<(f64, f64)> = s
        .iter()
        .zip(x)
        .filter(|(a, b)| a.is_finite() && b.is_finite())
        .map(|(&a, &b)| (a, b))
        .collect();
    if pairs.is_empty() || !(window > 0.0 && step > 0.0) {
        return Vec::new();
    }
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    // Prefix sums: the mean over any interval in two look-ups.
    let mut prefix = Vec::with_capacity(pairs.len() + 1);
    prefix.push(0.0);
    for p in &pairs {
        prefix.push(prefix.last().copied().unwrap_or(0.0) + p.1);
    }
    let (first, last) = (pairs[0].0, pairs[pairs.len() - 1].0);
    let half = 0.5 * window;
    let mut out = Vec::new();
    let mut k = 0usize;
    loop {
        let c = first + half + k as f64 * step;
        if c > last - half + 1e-9 {
            break;
        }
        let lo = pairs.partition_point(|p| p.0 < c - half);
        let hi = pairs.partition_point(|p| p.0 <= c + half);
        if hi > lo {
            out.push((c, (prefix[hi] - prefix[lo]) / (hi - lo) as f64));
        }
        k += 1;
    }
    out
}

/// Zero-phase band-pass of `x` (sampled at `fs`) between `lo` and `hi` Hz: the `hi` low-pass
/// of `x` minus its own `lo` low-pass (both `order`, forward and backward). `lo` ≤ 0 keeps
/// everything below `hi`.
pub fn band_pass(x: &[f64], fs: f64, lo: f64, hi: f64, order: usize) -> Vec<f64> {
    use crate::dsp::Butterworth;
    let hi = hi.min(0.45 * fs);
    let low = Butterworth::lowpass(order, hi, fs).filtfilt(x);
    if lo <= 0.0 {
        return low;
    }
    let base = Butterworth::lowpass(order, lo, fs).filtfilt(&low);
    low.iter().zip(base).map(|(a, b)| a - b).collect()
}

/// The frequency of the largest spectral line of `x` within `(lo, hi)` Hz.
pub fn dominant_frequency(x: &[f64], fs: f64, lo: f64, hi: f64) -> Option<f64> {
    crate::dsp::amplitude_spectrum(x, fs)
        .into_iter()
        .filter(|(f, _)| *f > lo && *f < hi)
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map(|p| p.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Samples every 5 mm (200 Hz at 1 m/s) over `len` metres.
    fn positions(len: f64) -> Vec<f64> {
        (0..=crate::bounds::to_count((len / 0.005).round()))
            .map(|i| i as f64 * 0.005)
            .collect()
    }

    #[test]
    fn sliding_mean_of_a_ramp_is_the_ramp() {
        let s = positions(10.0);
        let x: Vec<f64> = s.iter().map(|v| 3.0 * v + 1.0).collect();
        let m = sliding_mean(&s, &x, 2.0, 0.5);
        // Centres 1, 1.5, …, 9: 17 windows.
        assert_eq!(m.len(), 17);
        assert!((m[0].0 - 1.0).abs() < 1e-12 && (m[16].0 - 9.0).abs() < 1e-9);
        for (c, v) in &m {
            assert!((v - (3.0 * c + 1.0)).abs() < 1e-9, "{c}: {v}");
        }
    }

    #[test]
    fn band_pass_keeps_the_band_and_finds_its_line() {
        let fs = 200.0;
        let x: Vec<f64> = (0..8000)
            .map(|i| {
                let t = i as f64 / fs;
                let w = 2.0 * std::f64::consts::PI;
                (w * 3.0 * t).sin() + 0.5 * (w * 0.2 * t).sin() + 0.5 * (w * 30.0 * t).sin()
            })
            .collect();
        assert_eq!(dominant_frequency(&x, fs, 1.0, 10.0), Some(3.0));
        let b = band_pass(&x, fs, 1.0, 5.0, 4);
        let peak = b[2000..6000].iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!((peak - 1.0).abs() < 0.05, "the 3 Hz line passes: {peak}");
    }

    #[test]
    fn sliding_mean_of_a_step_ramps_over_one_window() {
        let s = positions(10.0);
        let x: Vec<f64> = s.iter().map(|&v| if v < 5.0 { 0.0 } else { 1.0 }).collect();
        let m = sliding_mean(&s, &x, 2.0, 0.5);
        let at = |c: f64| m.iter().find(|p| (p.0 - c).abs() < 1e-9).unwrap().1;
        assert_eq!(at(3.5), 0.0);
        assert_eq!(at(6.5), 1.0);
        // Centred on the step: half the window above it (201 of 401 samples).
        assert!((at(5.0) - 201.0 / 401.0).abs() < 1e-12);
        // Half a metre past it: 1.5 m of 2 m.
        assert!((at(5.5) - 301.0 / 401.0).abs() < 1e-12);
    }
}
