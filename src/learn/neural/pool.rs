//! `MaxPool1d(2, stride 1)` over time, the stem's last layer: forward (shared by training and
//! evaluation) and backward.

/// MaxPool1d(2, stride 1) over time of `x[B, T, W]` into `y[B, T−1, W]`.
pub(super) fn max_pool_pairs(x: &[f32], batch: usize, t: usize, w: usize, y: &mut Vec<f32>) {
    y.resize(batch * (t - 1) * w, 0.0);
    for b in 0..batch {
        let src = &x[b * t * w..(b + 1) * t * w];
        let dst = &mut y[b * (t - 1) * w..(b + 1) * (t - 1) * w];
        for (s, out) in dst.chunks_exact_mut(w).enumerate() {
            let (u, v) = (&src[s * w..(s + 1) * w], &src[(s + 1) * w..(s + 2) * w]);
            for ((o, &a), &c) in out.iter_mut().zip(u).zip(v) {
                *o = a.max(c);
            }
        }
    }
}

/// Backward of `MaxPool1d(2, stride 1)` over time: `dx[B, T, W]` from the pool's input
/// `x[B, T, W]` and `dy[B, T − 1, W]`. Output `s` took step `s + 1` where `x[s + 1] > x[s]`
/// (strictly: a tie went to `s`). Each input step gathers what output `s − 1` sends it, then
/// what output `s` sends it, from +0: the same sums as scattering each output to the step it
/// took, in the same order (adding +0 where nothing is sent changes no value, since a sum
/// started at +0 is never −0), as selects the compiler vectorises rather than branches on
/// random picks.
pub(super) fn max_pool_backward(
    x: &[f32],
    dy: &[f32],
    batch: usize,
    t: usize,
    w: usize,
    dx: &mut Vec<f32>,
) {
    // What output `s` sends step `s + 1` (`took`) or step `s` (not): the gradient or +0.
    let to_next = |a: f32, b: f32, d: f32| if b > a { d } else { 0.0 };
    let to_this = |a: f32, b: f32, d: f32| if b > a { 0.0 } else { d };
    dx.resize(batch * t * w, 0.0);
    for b in 0..batch {
        let x = &x[b * t * w..(b + 1) * t * w];
        let dy = &dy[b * (t - 1) * w..(b + 1) * (t - 1) * w];
        let dx = &mut dx[b * t * w..(b + 1) * t * w];
        for s in 0..t {
            let out = &mut dx[s * w..(s + 1) * w];
            let here = &x[s * w..(s + 1) * w];
            if s == 0 {
                let (next, d) = (&x[w..2 * w], &dy[..w]);
                for (((o, &a), &n), &d) in out.iter_mut().zip(here).zip(next).zip(d) {
                    *o = 0.0 + to_this(a, n, d);
                }
            } else if s + 1 == t {
                let (prev, d) = (&x[(s - 1) * w..s * w], &dy[(s - 1) * w..s * w]);
                for (((o, &a), &p), &d) in out.iter_mut().zip(here).zip(prev).zip(d) {
                    *o = 0.0 + to_next(p, a, d);
                }
            } else {
                let (prev, next) = (&x[(s - 1) * w..s * w], &x[(s + 1) * w..(s + 2) * w]);
                let (dp, dn) = (&dy[(s - 1) * w..s * w], &dy[s * w..(s + 1) * w]);
                for (((((o, &a), &p), &n), &dp), &dn) in
                    out.iter_mut().zip(here).zip(prev).zip(next).zip(dp).zip(dn)
                {
                    *o = (0.0 + to_next(p, a, dp)) + to_this(a, n, dn);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::RngExt;
    use rand_chacha::rand_core::SeedableRng;

    /// The gather gives what scattering each output's gradient to the step it took gives, to
    /// the bit: ties (which go to the earlier step), signed zeros and every position of the
    /// window included.
    #[test]
    fn the_gather_equals_the_scatter_to_the_bit() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let (batch, t, w) = (3, 6, 5);
        let level = [-1.0f32, -0.0, 0.0, 0.5, 0.5, 2.0];
        let x: Vec<f32> = (0..batch * t * w)
            .map(|_| level[rng.random_range(0..6)])
            .collect();
        let dy: Vec<f32> = (0..batch * (t - 1) * w)
            .map(|i| match i % 7 {
                0 => -0.0,
                1 => 0.0,
                _ => rng.random_range(-1.0f32..1.0),
            })
            .collect();
        let mut scatter = vec![0.0f32; batch * t * w];
        for b in 0..batch {
            for s in 0..t - 1 {
                for k in 0..w {
                    let (a, c) = ((b * t + s) * w + k, (b * t + s + 1) * w + k);
                    let at = if x[c] > x[a] { c } else { a };
                    scatter[at] += dy[(b * (t - 1) + s) * w + k];
                }
            }
        }
        let mut gather = vec![f32::NAN; 3];
        max_pool_backward(&x, &dy, batch, t, w, &mut gather);
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&gather), bits(&scatter));
        assert!(
            scatter.iter().any(|v| v.to_bits() == 0),
            "no +0 was exercised"
        );
        // The forward takes, at each pair, the step the backward sends the gradient to.
        let mut y = Vec::new();
        max_pool_pairs(&x, batch, t, w, &mut y);
        for b in 0..batch {
            for s in 0..t - 1 {
                for k in 0..w {
                    let (a, c) = (x[(b * t + s) * w + k], x[(b * t + s + 1) * w + k]);
                    assert_eq!(y[(b * (t - 1) + s) * w + k], if c > a { c } else { a });
                }
            }
        }
    }
}
