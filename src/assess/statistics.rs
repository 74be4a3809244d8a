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

#[cfg(test)]
mod tests {
    use super::*;

    /// Samples every 5 mm (200 Hz at 1 m/s) over `len` metres.
    fn positions(len: f64) -> Vec<f64> {
        (0..=((len / 0.005).round() as usize))
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
