//! All weights of a network in one flat vector (with gradients beside them): the optimizer
//! walks one slice, saving is one write, and layers hold ranges into it.

use rand::{Rng, RngExt};
use serde::{Deserialize, Serialize};
use std::ops::Range;

/// One named tensor inside [`ParamSet`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Slot {
    /// Name, e.g. `lstm.w_ih`.
    pub name: String,
    /// Shape, row-major.
    pub shape: Vec<usize>,
    /// First index in the flat vector.
    pub offset: usize,
    /// Learned by the optimizer (false for batch-norm running statistics).
    pub trainable: bool,
}

impl Slot {
    /// Index range in the flat vector.
    pub fn range(&self) -> Range<usize> {
        self.offset..self.offset + self.shape.iter().product::<usize>()
    }
}

/// Flat parameter storage.
#[derive(Debug, Clone, Default)]
pub struct ParamSet {
    /// Values.
    pub value: Vec<f32>,
    /// Gradients (same layout).
    pub grad: Vec<f32>,
    /// Named slots.
    pub slots: Vec<Slot>,
}

impl ParamSet {
    /// Appends a tensor initialised uniformly in `[-bound, bound]` (PyTorch's default for
    /// linear and recurrent layers uses `bound = 1/√fan_in`).
    pub fn uniform<R: Rng>(
        &mut self,
        name: &str,
        shape: &[usize],
        bound: f32,
        rng: &mut R,
    ) -> Range<usize> {
        let n: usize = shape.iter().product();
        let r = self.push(name, shape, true);
        for v in &mut self.value[r.clone()] {
            *v = rng.random_range(-bound..=bound);
        }
        debug_assert_eq!(r.len(), n);
        r
    }

    /// Appends a tensor filled with `value`.
    pub fn constant(
        &mut self,
        name: &str,
        shape: &[usize],
        value: f32,
        trainable: bool,
    ) -> Range<usize> {
        let r = self.push(name, shape, trainable);
        self.value[r.clone()].fill(value);
        r
    }

    fn push(&mut self, name: &str, shape: &[usize], trainable: bool) -> Range<usize> {
        let offset = self.value.len();
        let n: usize = shape.iter().product();
        self.value.resize(offset + n, 0.0);
        self.grad.resize(offset + n, 0.0);
        self.slots.push(Slot {
            name: name.to_string(),
            shape: shape.to_vec(),
            offset,
            trainable,
        });
        offset..offset + n
    }

    /// Number of trainable values.
    pub fn trainable_count(&self) -> usize {
        self.slots
            .iter()
            .filter(|s| s.trainable)
            .map(|s| s.range().len())
            .sum()
    }

    /// Sets every gradient to zero.
    pub fn zero_grad(&mut self) {
        self.grad.fill(0.0);
    }
}
