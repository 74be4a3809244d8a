//! The four networks of the paper's comparison on one skeleton: an optional convolutional stem
//! (Conv1d k=1 → LeakyReLU → BatchNorm, twice, then MaxPool1d(2, stride 1) over time), a
//! feature extractor (BiLSTM, GRU, or the flattened stem) and the shared head
//! (Dropout → Linear(F→64) → LeakyReLU → Dropout → Linear(64→8) → LeakyReLU → Linear(8→out)).
//! Forward and backward are written out by hand (fused, no per-op graph).

use super::batch_norm::BatchNorm;
use super::dense::Dense;
use super::gru::Gru;
use super::lstm::BiLstm;
use super::params::ParamSet;
use super::pool::{max_pool_backward, max_pool_pairs};
use crate::learn::linalg::{leaky, leaky_relu, leaky_relu_backward};
use rand::RngExt;
use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::SeedableRng;
use serde::{Deserialize, Serialize};

/// Network kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Architecture {
    /// The paper's CNN-BiLSTM (assets/docs/learning.md §3).
    CnnBiLstm,
    /// The convolutional stem, flattened, and the head.
    Cnn,
    /// BiLSTM(C → 20 per direction) and the head.
    BiLstm,
    /// GRU(C → 20) and the head.
    Gru,
}

impl Architecture {
    /// Command-line name.
    pub fn name(self) -> &'static str {
        match self {
            Architecture::CnnBiLstm => "cnn-bilstm",
            Architecture::Cnn => "cnn",
            Architecture::BiLstm => "bilstm",
            Architecture::Gru => "gru",
        }
    }

    /// The shortest window the network reads, steps: the convolutional stem's pool joins
    /// neighbouring steps, so it needs two.
    pub fn min_window(self) -> usize {
        match self {
            Architecture::CnnBiLstm | Architecture::Cnn => 2,
            Architecture::BiLstm | Architecture::Gru => 1,
        }
    }
}

/// Shape of a network.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NetConfig {
    /// Kind.
    pub architecture: Architecture,
    /// Steps per window.
    pub window: usize,
    /// Input channels.
    pub channels: usize,
    /// Outputs of the head (1 for FL or FQ, 2 for both; three times that with quantile heads).
    pub outputs: usize,
    /// Quantile heads: with `Some(c)`, the head gives per target its mean, then its
    /// `(1 − c)/2` and `(1 + c)/2` quantiles (`outputs` is three times the targets, in that
    /// order), trained with the pinball loss beside the mean's squared error.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub quantiles: Option<f64>,
    /// Dropout probability of the head.
    pub dropout: f32,
    /// Seed of the initial weights and of dropout.
    pub seed: u64,
}

/// Channels of the stem's second convolution.
pub const STEM_WIDTH: usize = 128;
/// Hidden units of the recurrent layers (per direction).
pub const HIDDEN: usize = 20;
/// Widths of the head's two hidden layers.
pub const HEAD: [usize; 2] = [64, 8];

struct Stem {
    c1: Dense,
    bn1: BatchNorm,
    c2: Dense,
    bn2: BatchNorm,
}

enum Recurrent {
    Lstm(BiLstm),
    Gru(Gru),
    None,
}

/// A network with its weights and the activations of the last forward pass.
pub struct Network {
    /// Shape.
    pub config: NetConfig,
    /// Weights, gradients and batch-norm statistics.
    pub params: ParamSet,
    stem: Option<Stem>,
    rnn: Recurrent,
    d1: Dense,
    d2: Dense,
    d3: Dense,
    rng: ChaCha8Rng,
    feat_width: usize,
    batch: usize,
    r1: Vec<f32>,
    n1: Vec<f32>,
    r2: Vec<f32>,
    n2: Vec<f32>,
    pooled: Vec<f32>,
    feat: Vec<f32>,
    m0: Vec<f32>,
    f0: Vec<f32>,
    h1: Vec<f32>,
    m1: Vec<f32>,
    f1: Vec<f32>,
    h2: Vec<f32>,
    out: Vec<f32>,
    /// The backward pass's gradients, kept between steps so that a step allocates nothing.
    grads: BackwardBuffers,
}

/// Gradients of the backward pass with respect to each layer's input (named as the forward
/// activations they belong to).
#[derive(Default)]
struct BackwardBuffers {
    dh2: Vec<f32>,
    dh1: Vec<f32>,
    dfeat: Vec<f32>,
    dpool: Vec<f32>,
    dn2: Vec<f32>,
    dn1: Vec<f32>,
}

impl Network {
    /// A freshly initialised network (PyTorch's default initialisation), seeded.
    pub fn new(config: NetConfig) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(config.seed);
        let mut p = ParamSet::default();
        let c = config.channels;
        let t = config.window;
        let stem = matches!(
            config.architecture,
            Architecture::CnnBiLstm | Architecture::Cnn
        )
        .then(|| Stem {
            c1: Dense::new(&mut p, "conv1", c, c, &mut rng),
            bn1: BatchNorm::new(&mut p, "bn1", c),
            c2: Dense::new(&mut p, "conv2", c, STEM_WIDTH, &mut rng),
            bn2: BatchNorm::new(&mut p, "bn2", STEM_WIDTH),
        });
        let (rnn, feat) = match config.architecture {
            Architecture::CnnBiLstm => {
                let l = BiLstm::new(&mut p, "bilstm", STEM_WIDTH, HIDDEN, &mut rng);
                let f = l.out_dim();
                (Recurrent::Lstm(l), f)
            }
            Architecture::BiLstm => {
                let l = BiLstm::new(&mut p, "bilstm", c, HIDDEN, &mut rng);
                let f = l.out_dim();
                (Recurrent::Lstm(l), f)
            }
            Architecture::Gru => {
                let g = Gru::new(&mut p, "gru", c, HIDDEN, &mut rng);
                let f = g.out_dim();
                (Recurrent::Gru(g), f)
            }
            Architecture::Cnn => (Recurrent::None, (t - 1) * STEM_WIDTH),
        };
        let d1 = Dense::new(&mut p, "head.fc1", feat, HEAD[0], &mut rng);
        let d2 = Dense::new(&mut p, "head.fc2", HEAD[0], HEAD[1], &mut rng);
        let d3 = Dense::new(&mut p, "head.out", HEAD[1], config.outputs, &mut rng);
        let dropout_rng = ChaCha8Rng::seed_from_u64(config.seed ^ 0x000D_80F0_u64);
        Network {
            config,
            params: p,
            stem,
            rnn,
            d1,
            d2,
            d3,
            rng: dropout_rng,
            feat_width: feat,
            batch: 0,
            r1: Vec::new(),
            n1: Vec::new(),
            r2: Vec::new(),
            n2: Vec::new(),
            pooled: Vec::new(),
            feat: Vec::new(),
            m0: Vec::new(),
            f0: Vec::new(),
            h1: Vec::new(),
            m1: Vec::new(),
            f1: Vec::new(),
            h2: Vec::new(),
            out: Vec::new(),
            grads: BackwardBuffers::default(),
        }
    }

    /// A copy of the weights with buffers of its own, for a second thread's predictions (the
    /// dropout stream starts afresh: a twin is for evaluation).
    pub fn twin(&self) -> Network {
        let mut n = Network::new(self.config.clone());
        n.params = self.params.clone();
        n
    }

    /// Re-seeds the dropout stream (the trainer does so per epoch for resumable runs).
    pub fn reseed_dropout(&mut self, seed: u64) {
        self.rng = ChaCha8Rng::seed_from_u64(seed);
    }

    /// Width of the features the head receives (2H, H or (window − 1)·128).
    pub fn feature_width(&self) -> usize {
        self.feat_width
    }

    /// The head's two dropout masks for `batch` windows (`[B, features]` and `[B, 64]`, each
    /// value 0 or 1/(1 − q)), drawn from the network's dropout stream exactly as a training
    /// forward pass draws them: another engine (burn) trained through [`Network`] meets the
    /// same masks.
    pub fn dropout_masks(&mut self, batch: usize) -> [Vec<f32>; 2] {
        let q = self.config.dropout;
        let mut m0 = Vec::new();
        let mut m1 = Vec::new();
        draw_mask(batch * self.feat_width, q, true, &mut self.rng, &mut m0);
        draw_mask(batch * HEAD[0], q, true, &mut self.rng, &mut m1);
        [m0, m1]
    }

    /// Forward pass of `x[B, window, channels]` (z-scored); `train` enables dropout and batch
    /// statistics and keeps what [`Network::backward`] needs. Returns `[B, outputs]`.
    pub fn forward(&mut self, x: &[f32], batch: usize, train: bool) -> &[f32] {
        if train {
            self.forward_layers(x, batch, true)
        } else {
            self.forward_eval(x, batch)
        }
    }

    /// Evaluation mode on the path training uses (layer by layer, with every cache): the
    /// reference [`Network::forward`]'s fused evaluation path is tested against.
    #[doc(hidden)]
    pub fn forward_reference(&mut self, x: &[f32], batch: usize) -> &[f32] {
        self.forward_layers(x, batch, false)
    }

    /// Evaluation mode, fused: windows in cache-sized chunks, batch norm as a per-channel
    /// affine map applied in place (no copies), no dropout, and the LSTM's fused evaluation
    /// kernel ([`BiLstm::forward_eval`]).
    fn forward_eval(&mut self, x: &[f32], batch: usize) -> &[f32] {
        let (t, c) = (self.config.window, self.config.channels);
        assert_eq!(
            x.len(),
            batch * t * c,
            "input must be [batch, window, channels]"
        );
        let p = &self.params;
        let bn = self
            .stem
            .as_ref()
            .map(|s| (s.bn1.eval_affine(p), s.bn2.eval_affine(p)));
        let mut out = std::mem::take(&mut self.out);
        out.clear();
        let mut tmp = Vec::new();
        for chunk in x.chunks(EVAL_CHUNK * t * c) {
            let n = chunk.len() / (t * c);
            let (seq, steps): (&[f32], usize) = match (&self.stem, &bn) {
                (Some(stem), Some(((s1, b1), (s2, b2)))) => {
                    let rows = n * t;
                    stem.c1.forward(p, chunk, rows, &mut self.r1);
                    leaky_affine(&mut self.r1, s1, b1);
                    stem.c2.forward(p, &self.r1, rows, &mut self.r2);
                    leaky_affine(&mut self.r2, s2, b2);
                    max_pool_pairs(&self.r2, n, t, STEM_WIDTH, &mut self.pooled);
                    (&self.pooled, t - 1)
                }
                _ => (chunk, t),
            };
            let feat: &[f32] = match &mut self.rnn {
                Recurrent::Lstm(l) => {
                    l.forward_eval(p, seq, n, steps, &mut self.n1, &mut self.feat);
                    &self.feat
                }
                Recurrent::Gru(g) => {
                    g.forward(p, seq, n, steps, &mut self.feat);
                    &self.feat
                }
                Recurrent::None => seq,
            };
            self.d1.forward(p, feat, n, &mut self.h1);
            leaky_relu(&mut self.h1);
            self.d2.forward(p, &self.h1, n, &mut self.h2);
            leaky_relu(&mut self.h2);
            self.d3.forward(p, &self.h2, n, &mut tmp);
            out.extend_from_slice(&tmp);
        }
        self.out = out;
        &self.out
    }

    fn forward_layers(&mut self, x: &[f32], batch: usize, train: bool) -> &[f32] {
        let (t, c) = (self.config.window, self.config.channels);
        assert_eq!(
            x.len(),
            batch * t * c,
            "input must be [batch, window, channels]"
        );
        self.batch = batch;
        let p = &mut self.params;
        let mut tmp = Vec::new();
        if let Some(stem) = &mut self.stem {
            let rows = batch * t;
            stem.c1.forward(p, x, rows, &mut self.r1);
            leaky_relu(&mut self.r1);
            self.n1.clone_from(&self.r1);
            stem.bn1.forward(p, &mut self.n1, train);
            stem.c2.forward(p, &self.n1, rows, &mut self.r2);
            leaky_relu(&mut self.r2);
            self.n2.clone_from(&self.r2);
            stem.bn2.forward(p, &mut self.n2, train);
            // MaxPool1d(2, stride 1) over time.
            max_pool_pairs(&self.n2, batch, t, STEM_WIDTH, &mut self.pooled);
        }
        let seq: &[f32] = if self.stem.is_some() { &self.pooled } else { x };
        let steps = if self.stem.is_some() { t - 1 } else { t };
        match &mut self.rnn {
            Recurrent::Lstm(l) => l.forward(p, seq, batch, steps, &mut self.feat),
            Recurrent::Gru(g) => g.forward(p, seq, batch, steps, &mut self.feat),
            Recurrent::None => self.feat.clone_from(&self.pooled),
        }
        let q = self.config.dropout;
        dropout(
            &self.feat,
            &mut self.f0,
            &mut self.m0,
            q,
            train,
            &mut self.rng,
        );
        self.d1.forward(p, &self.f0, batch, &mut self.h1);
        leaky_relu(&mut self.h1);
        dropout(
            &self.h1,
            &mut self.f1,
            &mut self.m1,
            q,
            train,
            &mut self.rng,
        );
        self.d2.forward(p, &self.f1, batch, &mut self.h2);
        leaky_relu(&mut self.h2);
        self.d3.forward(p, &self.h2, batch, &mut tmp);
        self.out = tmp;
        &self.out
    }

    /// Backward pass from `dout[B, outputs]` after a training forward of `x`; accumulates the
    /// gradients in `params.grad`.
    pub fn backward(&mut self, x: &[f32], dout: &[f32]) {
        let batch = self.batch;
        let (t, c) = (self.config.window, self.config.channels);
        let p = &mut self.params;
        let g = &mut self.grads;
        self.d3.backward(p, &self.h2, dout, batch, Some(&mut g.dh2));
        leaky_relu_backward(&self.h2, &mut g.dh2);
        self.d2
            .backward(p, &self.f1, &g.dh2, batch, Some(&mut g.dh1));
        mul_in_place(&mut g.dh1, &self.m1);
        leaky_relu_backward(&self.h1, &mut g.dh1);
        self.d1
            .backward(p, &self.f0, &g.dh1, batch, Some(&mut g.dfeat));
        mul_in_place(&mut g.dfeat, &self.m0);
        let Some(stem) = &mut self.stem else {
            match &mut self.rnn {
                Recurrent::Lstm(l) => l.backward(p, x, &g.dfeat, None),
                Recurrent::Gru(gru) => gru.backward(p, x, &g.dfeat, None),
                Recurrent::None => unreachable!("every network without a stem is recurrent"),
            }
            return;
        };
        let dpool = match &mut self.rnn {
            Recurrent::Lstm(l) => {
                l.backward(p, &self.pooled, &g.dfeat, Some(&mut g.dpool));
                &g.dpool
            }
            Recurrent::Gru(gru) => {
                gru.backward(p, &self.pooled, &g.dfeat, Some(&mut g.dpool));
                &g.dpool
            }
            Recurrent::None => &g.dfeat,
        };
        max_pool_backward(&self.n2, dpool, batch, t, STEM_WIDTH, &mut g.dn2);
        let rows = batch * t;
        stem.bn2.backward(p, &mut g.dn2);
        leaky_relu_backward(&self.r2, &mut g.dn2);
        stem.c2
            .backward(p, &self.n1, &g.dn2, rows, Some(&mut g.dn1));
        stem.bn1.backward(p, &mut g.dn1);
        leaky_relu_backward(&self.r1, &mut g.dn1);
        stem.c1.backward(p, x, &g.dn1, rows, None);
        debug_assert_eq!(x.len(), rows * c);
    }

    /// The targets' estimates for `x[B, window, channels]` in evaluation mode, `[B, targets]`
    /// (the mean heads of a network with quantile heads).
    pub fn predict(&mut self, x: &[f32], batch: usize) -> Vec<f32> {
        let all = self.predict_all(x, batch);
        self.means(all)
    }

    /// The mean heads of every head's output `all` (`[B, outputs]`, as
    /// [`Network::predict_all`] gives it): itself without quantile heads.
    pub fn means(&self, all: Vec<f32>) -> Vec<f32> {
        if self.config.quantiles.is_none() {
            return all;
        }
        let o = self.config.outputs / 3;
        all.chunks_exact(3 * o)
            .flat_map(|row| row[..o].iter().copied())
            .collect()
    }

    /// Every head's output for `x[B, window, channels]` in evaluation mode, `[B, outputs]`, in
    /// chunks of [`PREDICT_CHUNK`] windows.
    pub fn predict_all(&mut self, x: &[f32], batch: usize) -> Vec<f32> {
        let per = self.config.window * self.config.channels;
        let mut out = Vec::with_capacity(batch * self.config.outputs);
        for chunk in x.chunks(per * PREDICT_CHUNK) {
            let n = chunk.len() / per;
            out.extend_from_slice(self.forward(chunk, n, false));
        }
        out
    }

    /// [`Network::predict_all`] with the windows shared out between up to `threads` threads in
    /// runs of whole [`PREDICT_CHUNK`]s, each on its own [`Network::twin`]: every chunk is the
    /// one a single thread takes, through the same code, so the output is the same bit for
    /// bit. Fewer than two chunks stay on this thread.
    pub fn predict_all_on(&mut self, x: &[f32], batch: usize, threads: usize) -> Vec<f32> {
        let chunks = batch.div_ceil(PREDICT_CHUNK);
        let threads = threads.min(chunks);
        if threads < 2 {
            return self.predict_all(x, batch);
        }
        let per = self.config.window * self.config.channels;
        let share = chunks.div_ceil(threads) * PREDICT_CHUNK * per;
        let mut twins: Vec<Network> = (1..threads).map(|_| self.twin()).collect();
        std::thread::scope(|scope| {
            let mut parts = x.chunks(share);
            let first = parts.next().unwrap_or_default();
            let handles: Vec<_> = parts
                .zip(twins.iter_mut())
                .map(|(xs, net)| scope.spawn(move || net.predict_all(xs, xs.len() / per)))
                .collect();
            let mut out = self.predict_all(first, first.len() / per);
            for h in handles {
                out.extend(h.join().expect("a prediction thread panicked"));
            }
            out
        })
    }
}

/// Windows a network predicts at a time ([`Network::predict_all`]), and the unit in which
/// [`Network::predict_all_on`] shares them out between threads.
pub const PREDICT_CHUNK: usize = 1024;

/// Windows per chunk of the evaluation path: the stem's activations of one chunk
/// (64 × 20 × 128 floats, 640 KiB) stay in the L2 cache.
const EVAL_CHUNK: usize = 64;

/// Leaky ReLU then a per-channel affine map (evaluation-mode batch norm), in place on rows.
fn leaky_affine(x: &mut [f32], scale: &[f32], shift: &[f32]) {
    for row in x.chunks_exact_mut(scale.len()) {
        for ((v, a), b) in row.iter_mut().zip(scale).zip(shift) {
            *v = leaky(*v) * a + b;
        }
    }
}

/// Inverted dropout: `y = x·m`, `m ∈ {0, 1/(1−q)}`; identity (mask 1) outside training.
fn dropout(
    x: &[f32],
    y: &mut Vec<f32>,
    mask: &mut Vec<f32>,
    q: f32,
    train: bool,
    rng: &mut ChaCha8Rng,
) {
    draw_mask(x.len(), q, train, rng, mask);
    y.clear();
    y.extend(x.iter().zip(mask.iter()).map(|(a, m)| a * m));
}

/// `n` inverted-dropout multipliers: 0 with probability `q`, else 1/(1 − q); all 1 outside
/// training.
fn draw_mask(n: usize, q: f32, train: bool, rng: &mut ChaCha8Rng, mask: &mut Vec<f32>) {
    mask.clear();
    if train && q > 0.0 {
        let keep = 1.0 / (1.0 - q);
        mask.extend((0..n).map(|_| if rng.random::<f32>() < q { 0.0 } else { keep }));
    } else {
        mask.resize(n, 1.0);
    }
}

fn mul_in_place(x: &mut [f32], m: &[f32]) {
    for (a, b) in x.iter_mut().zip(m) {
        *a *= b;
    }
}
