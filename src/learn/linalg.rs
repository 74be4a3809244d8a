//! Dense f32 kernels for the learners: one GEMM entry point (matrixmultiply's packed,
//! runtime-dispatched AVX2/FMA kernels) and small helpers.

/// `C[m×n] = op(A)·op(B) + beta·C`, all row-major. `op(A)` is `A[m×k]`, or `Aᵀ` of a stored
/// `[k×m]` when `ta`; likewise `op(B)` is `B[k×n]` or `Bᵀ` of a stored `[n×k]` when `tb`.
#[allow(clippy::too_many_arguments)]
pub fn gemm(
    m: usize,
    k: usize,
    n: usize,
    a: &[f32],
    ta: bool,
    b: &[f32],
    tb: bool,
    c: &mut [f32],
    beta: f32,
) {
    let lda = if ta { m } else { k };
    let ldb = if tb { k } else { n };
    gemm_strided(m, k, n, a, lda, ta, b, ldb, tb, c, n, beta);
}

/// [`gemm`] where consecutive rows of the stored `A`, `B` and `C` are `lda`, `ldb` and `ldc`
/// apart (a view of every row of a wider matrix, as the recurrent cells use for the gate block
/// of one time step).
#[allow(clippy::too_many_arguments)]
pub fn gemm_strided(
    m: usize,
    k: usize,
    n: usize,
    a: &[f32],
    lda: usize,
    ta: bool,
    b: &[f32],
    ldb: usize,
    tb: bool,
    c: &mut [f32],
    ldc: usize,
    beta: f32,
) {
    if m == 0 || n == 0 {
        return;
    }
    let (a_rows, a_cols) = if ta { (k, m) } else { (m, k) };
    assert!(a_cols <= lda && a.len() >= (a_rows - 1) * lda + a_cols);
    let (b_rows, b_cols) = if tb { (n, k) } else { (k, n) };
    assert!(b_cols <= ldb && b.len() >= (b_rows - 1) * ldb + b_cols);
    assert!(n <= ldc && c.len() >= (m - 1) * ldc + n);
    let (rsa, csa) = if ta {
        (1, lda as isize)
    } else {
        (lda as isize, 1)
    };
    let (rsb, csb) = if tb {
        (1, ldb as isize)
    } else {
        (ldb as isize, 1)
    };
    // SAFETY: the asserts above bound every index the strides reach.
    unsafe {
        matrixmultiply::sgemm(
            m,
            k,
            n,
            1.0,
            a.as_ptr(),
            rsa,
            csa,
            b.as_ptr(),
            rsb,
            csb,
            beta,
            c.as_mut_ptr(),
            ldc as isize,
            1,
        );
    }
}

/// Rows through an affine map: `y[rows×dout] = x·W + b`, `W[din×dout]` (dense layers and the
/// input projections of the recurrent layers).
pub fn affine(x: &[f32], rows: usize, din: usize, w: &[f32], b: &[f32], y: &mut Vec<f32>) {
    let dout = b.len();
    y.clear();
    for _ in 0..rows {
        y.extend_from_slice(b);
    }
    // The bias rows are C's initial value: one pass less than zeroing and adding afterwards.
    gemm(rows, din, dout, x, false, w, false, y, 1.0);
}

/// Backward of [`affine`] for the weight and the input: `dW += xᵀ·dy`, and `dx = dy·Wᵀ` when
/// asked (the bias gradient is the column sums of `dy`: [`add_col_sums`]).
#[allow(clippy::too_many_arguments)]
pub fn affine_backward(
    x: &[f32],
    dy: &[f32],
    rows: usize,
    din: usize,
    dout: usize,
    w: &[f32],
    dw: &mut [f32],
    dx: Option<&mut Vec<f32>>,
) {
    gemm(din, rows, dout, x, true, dy, false, dw, 1.0);
    if let Some(dx) = dx {
        // β = 0: the product overwrites `dx` and never reads it, so a buffer kept from the
        // last step needs no zeroing.
        dx.resize(rows * din, 0.0);
        gemm(rows, dout, din, dy, false, w, true, dx, 0.0);
    }
}

/// Whether the CPU has AVX2 and FMA (checked once by the standard library, then cached).
#[cfg(target_arch = "x86_64")]
#[inline]
pub fn has_avx2_fma() -> bool {
    std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
}

/// Defines `fn $name(&self, args…)` that runs `$body` compiled with AVX2 + FMA where the CPU
/// has them (through a `#[target_feature]` twin `$fast`) and as baseline code otherwise. The
/// body must be `#[inline(always)]` so that each twin gets its own code generation.
macro_rules! avx2_dispatch {
    ($(#[$meta:meta])* fn $name:ident / $fast:ident => $body:ident (&self, $($arg:ident: $ty:ty),* $(,)?)) => {
        $(#[$meta])*
        #[allow(clippy::too_many_arguments)]
        fn $name(&self, $($arg: $ty),*) {
            #[cfg(target_arch = "x86_64")]
            if $crate::learn::linalg::has_avx2_fma() {
                // SAFETY: the CPU has AVX2 and FMA (checked just above).
                unsafe { self.$fast($($arg),*) };
                return;
            }
            self.$body($($arg),*);
        }

        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2,fma")]
        #[allow(clippy::too_many_arguments)]
        fn $fast(&self, $($arg: $ty),*) {
            self.$body($($arg),*);
        }
    };
}
pub(crate) use avx2_dispatch;

/// Adds the column sums of `x[rows×cols]` to `out[cols]`.
pub fn add_col_sums(x: &[f32], cols: usize, out: &mut [f32]) {
    for row in x.chunks_exact(cols) {
        for (o, v) in out.iter_mut().zip(row) {
            *o += v;
        }
    }
}

/// Adds `bias[cols]` to every row of `x`.
pub fn add_bias(x: &mut [f32], bias: &[f32]) {
    for row in x.chunks_exact_mut(bias.len()) {
        for (v, b) in row.iter_mut().zip(bias) {
            *v += b;
        }
    }
}

/// Logistic sigmoid.
#[inline]
pub fn sigmoid(x: f32) -> f32 {
    1.0 / (1.0 + fast_exp(-x))
}

/// Saturation bound of [`fast_exp`]'s argument.
pub(crate) const EXP_LIMIT: f32 = 87.0;
/// 1.5·2^23: adding it rounds to an integer held in the low mantissa bits.
pub(crate) const EXP_ROUND: f32 = 12_582_912.0;
/// ln 2 split for the Cody–Waite reduction (high part exact in a few bits).
pub(crate) const LN2_HI: f32 = 0.693_359_4;
/// Low part of ln 2.
pub(crate) const LN2_LO: f32 = -2.121_944_4e-4;
/// Horner coefficients of `(e^r − 1 − r)/r²` on |r| ≤ ln2/2, highest degree first (Cephes).
pub(crate) const EXP_POLY: [f32; 6] = [
    1.987_569_1e-4,
    1.398_199_9e-3,
    8.333_452e-3,
    4.166_579_6e-2,
    1.666_666_5e-1,
    0.5,
];

/// `e^x` to about 2 ulp for |x| < 87 (saturating beyond), branch-free so loops over slices
/// vectorise: `e^x = 2^n·e^r`, `n = round(x/ln 2)`, `r = x − n·ln 2` (Cody–Waite split), and a
/// degree-6 Taylor polynomial for `e^r` on |r| ≤ ln2/2 (Cephes `expf`). The recurrent cells
/// spend most of their time in exp: libm's call per element is several times slower.
#[inline(always)]
pub fn fast_exp(x: f32) -> f32 {
    let x = x.clamp(-EXP_LIMIT, EXP_LIMIT);
    // Round to nearest by the 1.5·2^23 trick (vectorises, unlike f32::round): the sum's low
    // mantissa bits are n itself, so 2^n is built with integer arithmetic only (a float →
    // int `as` cast saturates and does not vectorise).
    let shifted = x * std::f32::consts::LOG2_E + EXP_ROUND;
    let n = shifted - EXP_ROUND;
    let r = x - n * LN2_HI - n * LN2_LO;
    let p = EXP_POLY[1..].iter().fold(EXP_POLY[0], |p, &c| p * r + c);
    let e = p * r * r + r + 1.0;
    let two_n = (shifted
        .to_bits()
        .wrapping_sub(EXP_ROUND.to_bits())
        .wrapping_add(127))
        << 23;
    e * f32::from_bits(two_n)
}

/// `dst = σ(src)` elementwise.
#[inline(always)]
pub fn sigmoid_into(src: &[f32], dst: &mut [f32]) {
    for (d, &s) in dst.iter_mut().zip(src) {
        *d = 1.0 / (1.0 + fast_exp(-s));
    }
}

/// `dst = tanh(src)` elementwise, as `1 − 2/(e^{2x} + 1)` (absolute error ~1e-7).
#[inline(always)]
pub fn tanh_into(src: &[f32], dst: &mut [f32]) {
    for (d, &s) in dst.iter_mut().zip(src) {
        *d = 1.0 - 2.0 / (fast_exp(2.0 * s) + 1.0);
    }
}

/// Leaky ReLU slope below zero (assets/docs/learning.md §3).
pub const LEAKY_SLOPE: f32 = 0.01;

/// Leaky ReLU of one value, as a select (not a conditional store) so that loops over it run
/// as vector blends: the signs of activations are random and a branch on them mispredicts.
#[inline(always)]
pub fn leaky(v: f32) -> f32 {
    if v < 0.0 { v * LEAKY_SLOPE } else { v }
}

/// In-place leaky ReLU ([`leaky`] on each value).
pub fn leaky_relu(x: &mut [f32]) {
    for v in x {
        *v = leaky(*v);
    }
}

/// Backward of leaky ReLU given its output `y` (the sign is preserved): `dx = dy·f'(y)` (a
/// select, as [`leaky_relu`]).
pub fn leaky_relu_backward(y: &[f32], dy: &mut [f32]) {
    for (d, &v) in dy.iter_mut().zip(y) {
        let a = *d;
        *d = if v < 0.0 { a * LEAKY_SLOPE } else { a };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fast_exp_and_tanh_are_accurate() {
        let mut worst_exp = 0.0f64;
        let mut worst_tanh = 0.0f64;
        for i in -80_000..=80_000 {
            let x = i as f32 * 1e-3;
            let e = fast_exp(x) as f64;
            let want = (x as f64).exp();
            worst_exp = worst_exp.max(((e - want) / want).abs());
            let mut t = [0.0f32];
            tanh_into(&[x], &mut t);
            worst_tanh = worst_tanh.max((t[0] as f64 - (x as f64).tanh()).abs());
        }
        assert!(worst_exp < 5e-7, "exp relative error {worst_exp}");
        assert!(worst_tanh < 3e-7, "tanh absolute error {worst_tanh}");
        assert_eq!(fast_exp(-1000.0), fast_exp(-87.0));
        assert!(sigmoid(-200.0) >= 0.0 && sigmoid(200.0) == 1.0);
    }

    #[test]
    fn gemm_transposes_agree_with_loops() {
        let (m, k, n) = (3, 4, 5);
        let a: Vec<f32> = (0..m * k).map(|i| (i as f32 * 0.37).sin()).collect();
        let b: Vec<f32> = (0..k * n).map(|i| (i as f32 * 0.91).cos()).collect();
        let mut want = vec![0.0; m * n];
        for i in 0..m {
            for j in 0..n {
                for l in 0..k {
                    want[i * n + j] += a[i * k + l] * b[l * n + j];
                }
            }
        }
        let at: Vec<f32> = (0..k * m).map(|x| a[(x % m) * k + x / m]).collect();
        let bt: Vec<f32> = (0..n * k).map(|x| b[(x % k) * n + x / k]).collect();
        for (ta, tb) in [(false, false), (true, false), (false, true), (true, true)] {
            let mut c = vec![1.0; m * n];
            let aa = if ta { &at } else { &a };
            let bb = if tb { &bt } else { &b };
            gemm(m, k, n, aa, ta, bb, tb, &mut c, 1.0);
            for (x, y) in c.iter().zip(&want) {
                assert!((x - 1.0 - y).abs() < 1e-5, "{ta} {tb}");
            }
        }
    }
}
