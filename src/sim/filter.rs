//! Anti-alias low-pass before decimation: an 8th-order Butterworth filter (four biquads,
//! bilinear transform with pre-warping), run at the integration rate. At the default 50 Hz
//! cut-off it passes 40 Hz within 0.12 dB and stops the 100 Hz Nyquist frequency of the
//! 200 Hz output by 48 dB (a 4th order at 60 Hz stopped it by only 18 dB).

/// One second-order section.
#[derive(Debug, Clone, Copy)]
struct Biquad {
    b: [f64; 3],
    a: [f64; 2],
}

/// Order of the filter.
pub const ORDER: usize = 8;
/// Filter state of one channel (two values per section).
pub type FilterState = [f64; ORDER];

/// Coefficients of an 8th-order Butterworth low-pass.
#[derive(Debug, Clone, Copy)]
pub struct Lowpass {
    sections: [Biquad; ORDER / 2],
    /// Pre-warped cut-off `tan(π·fc/fs)`.
    k: f64,
    fs: f64,
}

impl Lowpass {
    /// Cut-off `fc` (Hz) at sampling rate `fs` (Hz).
    pub fn new(fc: f64, fs: f64) -> Self {
        use std::f64::consts::PI;
        let k = (PI * fc / fs).tan();
        // Butterworth pole pairs of order n: Q = 1/(2 sin θ), θ = (2i + 1)π/(2n).
        let qs: [f64; ORDER / 2] = std::array::from_fn(|i| {
            1.0 / (2.0 * ((2 * i + 1) as f64 * PI / (2 * ORDER) as f64).sin())
        });
        let sections = qs.map(|q| {
            let norm = 1.0 / (1.0 + k / q + k * k);
            let b0 = k * k * norm;
            Biquad {
                b: [b0, 2.0 * b0, b0],
                a: [2.0 * (k * k - 1.0) * norm, (1.0 - k / q + k * k) * norm],
            }
        });
        Lowpass { sections, k, fs }
    }

    /// Gain at frequency `f` (Hz): `1/√(1 + (tan(πf/fs)/tan(πfc/fs))^{2n})`, the
    /// Butterworth magnitude through the bilinear transform.
    pub fn gain(&self, f: f64) -> f64 {
        let w = (std::f64::consts::PI * f / self.fs).tan() / self.k;
        1.0 / (1.0 + w.powi(2 * ORDER as i32)).sqrt()
    }

    /// Filters one sample of a channel whose state is `state`.
    #[inline]
    pub fn step(&self, x: f64, state: &mut FilterState) -> f64 {
        // Transposed direct form II per section: 2 state values each.
        let mut v = x;
        for (sec, st) in self.sections.iter().zip(state.chunks_exact_mut(2)) {
            let y = sec.b[0] * v + st[0];
            st[0] = sec.b[1] * v - sec.a[0] * y + st[1];
            st[1] = sec.b[2] * v - sec.a[1] * y;
            v = y;
        }
        v
    }

    /// Initial state of a channel that has held the value `x` for ever (no start transient).
    pub fn steady_state(&self, x: f64) -> FilterState {
        let mut st = [0.0; ORDER];
        let mut v = x;
        for (sec, s) in self.sections.iter().zip(st.chunks_exact_mut(2)) {
            // DC gain of each section is 1: y = v; solve the state for constant input.
            let y = v;
            s[1] = sec.b[2] * v - sec.a[1] * y;
            s[0] = sec.b[1] * v - sec.a[0] * y + s[1];
            v = y;
        }
        st
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn passes_low_and_stops_high_frequencies() {
        let fs = 10_000.0;
        let lp = Lowpass::new(60.0, fs);
        let gain = |f: f64| {
            let mut st = [0.0; ORDER];
            let mut peak: f64 = 0.0;
            for i in 0..40_000 {
                let y = lp.step(
                    (2.0 * std::f64::consts::PI * f * i as f64 / fs).sin(),
                    &mut st,
                );
                if i > 20_000 {
                    peak = peak.max(y.abs());
                }
            }
            peak
        };
        assert!((gain(5.0) - 1.0).abs() < 0.01);
        assert!((gain(60.0) - std::f64::consts::FRAC_1_SQRT_2).abs() < 0.02);
        // 8th order: −160 dB/decade; at 500 Hz far below 1e-3; the closed form agrees.
        assert!(gain(500.0) < 1e-6);
        for f in [5.0, 60.0, 100.0] {
            assert!((gain(f) - lp.gain(f)).abs() < 0.01, "{f} Hz");
        }
        // The default: ≥ 40 dB at the 100 Hz Nyquist frequency of 200 Hz output, flat to 40 Hz.
        let d = Lowpass::new(50.0, 5000.0);
        assert!(20.0 * d.gain(100.0).log10() < -40.0);
        assert!(d.gain(40.0) > 0.985);
        let mut st = lp.steady_state(3.0);
        assert!((lp.step(3.0, &mut st) - 3.0).abs() < 1e-12);
    }
}
