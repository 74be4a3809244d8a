//! Adam (Kingma & Ba 2015) with bias correction, over the trainable slots of a [`ParamSet`].

use super::params::ParamSet;
use serde::{Deserialize, Serialize};

/// Optimizer state; saved in checkpoints so a resumed run continues the same trajectory.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Adam {
    /// Learning rate.
    pub lr: f32,
    /// First-moment decay.
    pub beta1: f32,
    /// Second-moment decay.
    pub beta2: f32,
    /// Denominator floor.
    pub eps: f32,
    /// Steps taken.
    pub t: u64,
    /// First moments.
    pub m: Vec<f32>,
    /// Second moments.
    pub v: Vec<f32>,
}

impl Adam {
    /// Adam with the settings of assets/docs/learning.md §3 (lr 1e-3, betas 0.9/0.999, ε 1e-8).
    pub fn new(len: usize, lr: f32) -> Self {
        Adam {
            lr,
            beta1: 0.9,
            beta2: 0.999,
            eps: 1e-8,
            t: 0,
            m: vec![0.0; len],
            v: vec![0.0; len],
        }
    }

    /// One update from the gradients in `p`.
    pub fn step(&mut self, p: &mut ParamSet) {
        self.t += 1;
        let bc1 = 1.0 - self.beta1.powi(self.t as i32);
        let bc2 = 1.0 - self.beta2.powi(self.t as i32);
        let step = self.lr / bc1;
        for slot in p.slots.iter().filter(|s| s.trainable) {
            for i in slot.range() {
                let g = p.grad[i];
                self.m[i] = self.beta1 * self.m[i] + (1.0 - self.beta1) * g;
                self.v[i] = self.beta2 * self.v[i] + (1.0 - self.beta2) * g * g;
                p.value[i] -= step * self.m[i] / ((self.v[i] / bc2).sqrt() + self.eps);
            }
        }
    }
}
