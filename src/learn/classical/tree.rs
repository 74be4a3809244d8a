//! Regression trees grown on binned features with gradient histograms (the histogram method of
//! LightGBM / XGBoost `hist`): per node, sums of gradients and counts per bin; the larger child's
//! histogram is the parent's minus the smaller child's. Squared loss, so the hessian is the
//! count and a leaf's value is `−G/(n + λ)`.

use super::binning::Bins;
use serde::{Deserialize, Serialize};

/// A node: a split (`x[feature] <= threshold` goes left) or a leaf (`feature == u32::MAX`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Node {
    /// Split feature, or `u32::MAX` for a leaf.
    pub feature: u32,
    /// Split threshold (a bin edge).
    pub threshold: f32,
    /// The same split in bins: bins `<= bin` go left.
    pub bin: u8,
    /// Left child.
    pub left: u32,
    /// Right child.
    pub right: u32,
    /// Leaf value.
    pub value: f32,
}

/// A tree as a flat node array (root first).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Tree {
    /// Nodes.
    pub nodes: Vec<Node>,
}

/// Growth settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TreeParams {
    /// Maximum depth.
    pub max_depth: usize,
    /// Minimum rows per leaf.
    pub min_leaf: usize,
    /// L2 penalty on leaf values.
    pub lambda: f64,
}

impl Tree {
    /// Prediction for one row of raw features.
    #[inline]
    pub fn predict(&self, x: &[f32]) -> f32 {
        self.walk(|n| x[n.feature as usize] <= n.threshold)
    }

    /// Prediction for one binned row (`bin ≤ b ⇔ x ≤ edge[b]`).
    #[inline]
    pub fn predict_binned(&self, row: &[u8]) -> f32 {
        self.walk(|n| row[n.feature as usize] <= n.bin)
    }

    /// Leaf value reached from the root, going left where `go_left(split)`.
    #[inline]
    fn walk(&self, go_left: impl Fn(&Node) -> bool) -> f32 {
        let mut i = 0usize;
        loop {
            let n = &self.nodes[i];
            if n.feature == u32::MAX {
                return n.value;
            }
            i = if go_left(n) { n.left } else { n.right } as usize;
        }
    }

    /// Grows a tree fitting `−grad` on the rows `rows` of the binned matrix `xb[n × f]`.
    /// Leaf values are `−G/(n + λ)`; the caller scales them (learning rate).
    pub fn grow(
        xb: &[u8],
        f: usize,
        bins: &Bins,
        grad: &[f32],
        rows: &mut [u32],
        p: &TreeParams,
    ) -> Tree {
        let nb = 256;
        let mut nodes = vec![leaf(0.0)];
        struct Open {
            node: usize,
            from: usize,
            to: usize,
            depth: usize,
            hist: Hist,
        }
        // Histogram buffers are recycled: each is f × 256 bins (1.3 MB for 420 features).
        let mut pool: Vec<Hist> = Vec::new();
        let root = Hist::build(xb, f, nb, grad, rows, &mut pool);
        let mut open = vec![Open {
            node: 0,
            from: 0,
            to: rows.len(),
            depth: 0,
            hist: root,
        }];
        while let Some(o) = open.pop() {
            let (g, c) = o.hist.totals(nb);
            nodes[o.node].value = (-g / (c as f64 + p.lambda)) as f32;
            if o.depth >= p.max_depth || c < 2 * p.min_leaf as u64 {
                pool.push(o.hist);
                continue;
            }
            let Some((feat, bin)) = o.hist.best_split(f, nb, bins, p) else {
                pool.push(o.hist);
                continue;
            };
            // Partition rows in place: bins ≤ `bin` first.
            let slice = &mut rows[o.from..o.to];
            let mut mid = 0;
            for i in 0..slice.len() {
                if xb[slice[i] as usize * f + feat] <= bin {
                    slice.swap(i, mid);
                    mid += 1;
                }
            }
            let mid = o.from + mid;
            let (l, r) = (nodes.len(), nodes.len() + 1);
            nodes.push(leaf(0.0));
            nodes.push(leaf(0.0));
            nodes[o.node] = Node {
                feature: feat as u32,
                threshold: bins.edges[feat][bin as usize],
                bin,
                left: l as u32,
                right: r as u32,
                value: nodes[o.node].value,
            };
            let left_small = mid - o.from <= o.to - mid;
            let small = if left_small {
                &rows[o.from..mid]
            } else {
                &rows[mid..o.to]
            };
            let hs = Hist::build(xb, f, nb, grad, small, &mut pool);
            let mut hl = o.hist;
            hl.subtract(&hs);
            let (hleft, hright) = if left_small { (hs, hl) } else { (hl, hs) };
            open.push(Open {
                node: l,
                from: o.from,
                to: mid,
                depth: o.depth + 1,
                hist: hleft,
            });
            open.push(Open {
                node: r,
                from: mid,
                to: o.to,
                depth: o.depth + 1,
                hist: hright,
            });
        }
        Tree { nodes }
    }
}

fn leaf(value: f32) -> Node {
    Node {
        feature: u32::MAX,
        threshold: 0.0,
        bin: 0,
        left: 0,
        right: 0,
        value,
    }
}

/// Gradient sums and counts per (feature, bin), interleaved (one cache line per update).
struct Hist {
    gc: Vec<[f32; 2]>,
}

impl Hist {
    fn build(
        xb: &[u8],
        f: usize,
        nb: usize,
        grad: &[f32],
        rows: &[u32],
        pool: &mut Vec<Hist>,
    ) -> Hist {
        let mut gc = pool.pop().map(|h| h.gc).unwrap_or_default();
        gc.clear();
        gc.resize(f * nb, [0.0; 2]);
        for &r in rows {
            let row = &xb[r as usize * f..(r as usize + 1) * f];
            let gr = grad[r as usize];
            for (j, &b) in row.iter().enumerate() {
                let e = &mut gc[j * nb + b as usize];
                e[0] += gr;
                e[1] += 1.0;
            }
        }
        Hist { gc }
    }

    /// `self −= other` (parent minus the smaller child gives the larger child).
    fn subtract(&mut self, other: &Hist) {
        for (a, b) in self.gc.iter_mut().zip(&other.gc) {
            a[0] -= b[0];
            a[1] -= b[1];
        }
    }

    fn totals(&self, nb: usize) -> (f64, u64) {
        let g = self.gc[..nb].iter().map(|e| e[0] as f64).sum();
        let c = self.gc[..nb].iter().map(|e| e[1] as f64).sum::<f64>();
        (g, c.round() as u64)
    }

    /// Best (feature, last left bin) by the gain `G_L²/(n_L+λ) + G_R²/(n_R+λ) − G²/(n+λ)`.
    fn best_split(&self, f: usize, nb: usize, bins: &Bins, p: &TreeParams) -> Option<(usize, u8)> {
        let (gt, ct) = self.totals(nb);
        let ct = ct as f64;
        let parent = gt * gt / (ct + p.lambda);
        let min_leaf = p.min_leaf as f64;
        let (mut best_gain, mut best) = (1e-12f64, None);
        for j in 0..f {
            let (mut gl, mut cl) = (0.0f64, 0.0f64);
            let nbins = bins.edges[j].len(); // splits after bins 0..nbins-1
            for (b, e) in self.gc[j * nb..j * nb + nbins].iter().enumerate() {
                if e[1] < 0.5 {
                    // An empty bin: the same split as the previous one.
                    continue;
                }
                gl += e[0] as f64;
                cl += e[1] as f64;
                let cr = ct - cl;
                if cl < min_leaf {
                    continue;
                }
                if cr < min_leaf {
                    break;
                }
                let gr = gt - gl;
                let gain = gl * gl / (cl + p.lambda) + gr * gr / (cr + p.lambda) - parent;
                if gain > best_gain {
                    best_gain = gain;
                    best = Some((j, b as u8));
                }
            }
        }
        best
    }
}
