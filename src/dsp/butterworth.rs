//! Butterworth low-pass filters of any even order as cascaded biquads (bilinear transform with
//! pre-warping): the simulator's anti-alias filter and the assessment's 20 Hz filter are both
//! this one design.

/// One second-order section (transposed direct form II).
#[derive(Debug, Clone, Copy)]
struct Biquad {
    b: [f64; 3],
    a: [f64; 2],
}

/// Coefficients of a Butterworth low-pass of even order.
#[derive(Debug, Clone)]
pub struct Butterworth {
    sections: Vec<Biquad>,
    /// Pre-warped cut-off `tan(π·fc/fs)`.
    k: f64,
    fs: f64,
}

impl Butterworth {
    /// Low-pass of even `order` (≥ 2) with cut-off `fc` (Hz) at sampling rate `fs` (Hz).
    ///
    /// # Panics
    /// When `order` is odd or zero, or `fc` is not inside (0, fs/2).
    pub fn lowpass(order: usize, fc: f64, fs: f64) -> Self {
        use std::f64::consts::PI;
        assert!(
            order >= 2 && order.is_multiple_of(2),
            "even order ≥ 2, got {order}"
        );
        assert!(
            fc > 0.0 && fc < fs / 2.0,
            "cut-off {fc} Hz outside (0, {}) Hz",
            fs / 2.0
        );
        let k = (PI * fc / fs).tan();
        // Butterworth pole pairs of order n: Q = 1/(2 sin θ), θ = (2i + 1)π/(2n).
        let sections = (0..order / 2)
            .map(|i| {
                let q = 1.0 / (2.0 * ((2 * i + 1) as f64 * PI / (2 * order) as f64).sin());
                let norm = 1.0 / (1.0 + k / q + k * k);
                let b0 = k * k * norm;
                Biquad {
                    b: [b0, 2.0 * b0, b0],
                    a: [2.0 * (k * k - 1.0) * norm, (1.0 - k / q + k * k) * norm],
                }
            })
            .collect();
        Butterworth { sections, k, fs }
    }

    /// Order of the filter.
    pub fn order(&self) -> usize {
        2 * self.sections.len()
    }

    /// Gain at frequency `f` (Hz): `1/√(1 + (tan(πf/fs)/tan(πfc/fs))^{2n})`, the Butterworth
    /// magnitude through the bilinear transform.
    pub fn gain(&self, f: f64) -> f64 {
        let w = (std::f64::consts::PI * f / self.fs).tan() / self.k;
        1.0 / (1.0 + w.powi(2 * self.order() as i32)).sqrt()
    }

    /// Filters one sample; `state` holds two values per section ([`Self::order`] in all).
    #[inline]
    pub fn step(&self, x: f64, state: &mut [f64]) -> f64 {
        let mut v = x;
        for (sec, st) in self.sections.iter().zip(state.chunks_exact_mut(2)) {
            let y = sec.b[0] * v + st[0];
            st[0] = sec.b[1] * v - sec.a[0] * y + st[1];
            st[1] = sec.b[2] * v - sec.a[1] * y;
            v = y;
        }
        v
    }

    /// The state of a filter that has seen the value `x` for ever (no start transient).
    pub fn steady_state(&self, x: f64, state: &mut [f64]) {
        let mut v = x;
        for (sec, s) in self.sections.iter().zip(state.chunks_exact_mut(2)) {
            // DC gain of each section is 1: y = v; solve the state for constant input.
            let y = v;
            s[1] = sec.b[2] * v - sec.a[1] * y;
            s[0] = sec.b[1] * v - sec.a[0] * y + s[1];
            v = y;
        }
    }

    /// A bank of `channels` independent channels through this filter, stepped together
    /// ([`FilterBank`]).
    pub fn bank(&self, channels: usize) -> FilterBank {
        FilterBank {
            sections: self.sections.clone(),
            s0: vec![0.0; self.sections.len() * channels],
            s1: vec![0.0; self.sections.len() * channels],
            channels,
        }
    }

    /// Zero-phase filtering of a whole record: forward, then backward (gain [`Self::gain`]
    /// squared, no phase, so peaks stay where they were). As scipy's `filtfilt`, the record
    /// is first extended at both ends by its odd reflection (`2·x₀ − x_k`), here over three
    /// time constants of the cut-off (`3·fs/fc` samples, at most the record), and each pass
    /// starts in the steady state of its first value: ramps and slow swings do not ring at
    /// the ends.
    pub fn filtfilt(&self, x: &[f64]) -> Vec<f64> {
        let n = x.len();
        if n == 0 {
            return Vec::new();
        }
        let fc = self.k.atan() * self.fs / std::f64::consts::PI;
        let pad = crate::bounds::to_count((3.0 * self.fs / fc).ceil()).min(n - 1);
        let (first, last) = (x[0], x[n - 1]);
        let mut ext = Vec::with_capacity(n + 2 * pad);
        ext.extend((1..=pad).rev().map(|k| 2.0 * first - x[k]));
        ext.extend_from_slice(x);
        ext.extend((1..=pad).map(|k| 2.0 * last - x[n - 1 - k]));
        let mut state = vec![0.0; self.order()];
        self.steady_state(ext[0], &mut state);
        let forward: Vec<f64> = ext.iter().map(|&v| self.step(v, &mut state)).collect();
        self.steady_state(forward[forward.len() - 1], &mut state);
        let mut back: Vec<f64> = forward
            .iter()
            .rev()
            .map(|&v| self.step(v, &mut state))
            .collect();
        back.reverse();
        back[pad..pad + n].to_vec()
    }
}

/// Many channels through one Butterworth filter, stepped section by section across the
/// channels (the state laid out per section, then per channel) so the channels go through in
/// vector lanes: the same operations in the same order per channel as [`Butterworth::step`],
/// so the same numbers to the last bit.
#[derive(Debug, Clone)]
pub struct FilterBank {
    sections: Vec<Biquad>,
    s0: Vec<f64>,
    s1: Vec<f64>,
    channels: usize,
}

impl FilterBank {
    /// Number of channels.
    pub fn channels(&self) -> usize {
        self.channels
    }

    /// Sets every channel to the state of having held its value in `x` for ever.
    pub fn hold(&mut self, x: &[f64]) {
        let n = self.channels;
        for (c, &x) in x.iter().enumerate().take(n) {
            for (j, sec) in self.sections.iter().enumerate() {
                // DC gain of each section is 1: y = v = x.
                self.s1[j * n + c] = sec.b[2] * x - sec.a[1] * x;
                self.s0[j * n + c] = sec.b[1] * x - sec.a[0] * x + self.s1[j * n + c];
            }
        }
    }

    /// Filters one sample of every channel in place (`x` holds [`Self::channels`] values).
    /// Where the CPU has AVX the same code runs four lanes wide instead of two: the same
    /// multiplications and additions in the same order (no fused multiply-add), so the same
    /// numbers to the last bit on any machine.
    #[inline]
    pub fn step(&mut self, x: &mut [f64]) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: the CPU has AVX (checked just above).
            unsafe { self.step_avx(x) };
            return;
        }
        self.step_lanes(x);
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    fn step_avx(&mut self, x: &mut [f64]) {
        self.step_lanes(x);
    }

    #[inline(always)]
    fn step_lanes(&mut self, x: &mut [f64]) {
        let n = self.channels;
        let x = &mut x[..n];
        for (j, sec) in self.sections.iter().enumerate() {
            let (s0, s1) = (
                &mut self.s0[j * n..(j + 1) * n],
                &mut self.s1[j * n..(j + 1) * n],
            );
            let ([b0, b1, b2], [a0, a1]) = (sec.b, sec.a);
            for ((v, s0), s1) in x.iter_mut().zip(s0.iter_mut()).zip(s1.iter_mut()) {
                let y = b0 * *v + *s0;
                *s0 = b1 * *v - a0 * y + *s1;
                *s1 = b2 * *v - a1 * y;
                *v = y;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Peak of the filtered steady sine at `f`.
    fn response(lp: &Butterworth, f: f64, zero_phase: bool) -> f64 {
        let fs = lp.fs;
        let x: Vec<f64> = (0..40_000)
            .map(|i| (2.0 * std::f64::consts::PI * f * i as f64 / fs).sin())
            .collect();
        let y = if zero_phase {
            lp.filtfilt(&x)
        } else {
            let mut st = vec![0.0; lp.order()];
            x.iter().map(|&v| lp.step(v, &mut st)).collect()
        };
        y[15_000..25_000].iter().fold(0.0f64, |m, v| m.max(v.abs()))
    }

    #[test]
    fn a_bank_gives_each_channels_single_filter_to_the_last_bit() {
        // 13 channels: full vector lanes and a remainder, on whichever path the CPU takes.
        let lp = Butterworth::lowpass(8, 50.0, 2000.0);
        let n = 13;
        let mut bank = lp.bank(n);
        let mut states = vec![vec![0.0; lp.order()]; n];
        let start: Vec<f64> = (0..n).map(|c| c as f64 * 0.3 - 1.0).collect();
        bank.hold(&start);
        for (st, &x) in states.iter_mut().zip(&start) {
            lp.steady_state(x, st);
        }
        for i in 0..500 {
            let x: Vec<f64> = (0..n)
                .map(|c| ((i * 7 + c * 13) % 29) as f64 - 14.0)
                .collect();
            let mut y = x.clone();
            bank.step(&mut y);
            for c in 0..n {
                let single = lp.step(x[c], &mut states[c]);
                assert_eq!(y[c].to_bits(), single.to_bits(), "channel {c}, sample {i}");
            }
        }
    }

    #[test]
    fn passes_low_and_stops_high_frequencies() {
        let lp = Butterworth::lowpass(8, 60.0, 10_000.0);
        assert!((response(&lp, 5.0, false) - 1.0).abs() < 0.01);
        assert!((response(&lp, 60.0, false) - std::f64::consts::FRAC_1_SQRT_2).abs() < 0.02);
        assert!(response(&lp, 500.0, false) < 1e-6);
        for f in [5.0, 60.0, 100.0] {
            assert!(
                (response(&lp, f, false) - lp.gain(f)).abs() < 0.01,
                "{f} Hz"
            );
        }
        let mut st = vec![0.0; 8];
        lp.steady_state(3.0, &mut st);
        assert!((lp.step(3.0, &mut st) - 3.0).abs() < 1e-12);
    }

    /// A ramp and a slow sine come through a low cut-off unchanged to the very ends.
    #[test]
    fn zero_phase_keeps_the_ends_of_slow_signals() {
        let lp = Butterworth::lowpass(4, 0.4, 200.0);
        let x: Vec<f64> = (0..6000)
            .map(|i| {
                let t = i as f64 / 200.0;
                2.0 * t + (2.0 * std::f64::consts::PI * 0.1 * t).sin()
            })
            .collect();
        let y = lp.filtfilt(&x);
        let worst = x
            .iter()
            .zip(&y)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(worst < 0.02, "{worst}");
    }

    /// The assessment's 20 Hz filter (4th order, forward and backward at 200 Hz): its
    /// attenuation at 10 and 40 Hz is the closed form squared.
    #[test]
    fn zero_phase_20_hz_attenuation() {
        let lp = Butterworth::lowpass(4, 20.0, 200.0);
        for f in [10.0, 40.0] {
            let w = (std::f64::consts::PI * f / 200.0).tan() / (std::f64::consts::PI * 0.1).tan();
            let expect = 1.0 / (1.0 + w.powi(8));
            let got = response(&lp, f, true);
            assert!((got - expect).abs() < 2e-3, "{f} Hz: {got} vs {expect}");
        }
        // 10 Hz passes nearly whole (−0.03 dB), 40 Hz is down by about 40 dB.
        assert!(20.0 * response(&lp, 10.0, true).log10() > -0.1);
        assert!(20.0 * response(&lp, 40.0, true).log10() < -38.0);
    }
}
