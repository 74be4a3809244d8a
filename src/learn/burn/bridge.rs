//! The one map between the engine's flat parameters and the burn module's tensors: every burn
//! tensor is a block of one engine slot. Loading, gradient read-back and the batch-norm
//! statistics all walk this map, so the two layouts cannot drift apart.
//!
//! Layouts: a dense layer's weight is `[in, out]` in both (burn's `Linear` row layout). The
//! engine's BiLSTM keeps `w_ih [D, 8H]` (direction-major, gates i f g o), `w_hh [2, H, 4H]` and
//! biases `[8H]`; burn keeps one `Linear` per gate and direction (`input_transform [D, H]`,
//! `hidden_transform [H, H]`, each with its bias). The GRU likewise (`[D, 3H]`, gates r z n,
//! to `reset_gate`, `update_gate`, `new_gate`).

use super::{BurnNet, to_vec};
use crate::error::{Error, Result};
use crate::learn::neural::ParamSet;
use crate::learn::neural::batch_norm::MOMENTUM;
use crate::learn::neural::network::HIDDEN;
use crate::learn::neural::params::Slot;
use ::burn::module::{Param, RunningState};
use ::burn::nn::{BatchNorm, GateController, Linear};
use ::burn::tensor::Gradients;
use ::burn::tensor::{Device, Tensor, TensorData};

/// A block of an engine slot viewed as a row-major matrix as wide as the slot's last
/// dimension: rows `rows.0 .. rows.0 + rows.1` and columns `cols.0 .. cols.0 + cols.1`
/// (`None`: all).
struct Block {
    slot: String,
    rows: Option<(usize, usize)>,
    cols: Option<(usize, usize)>,
}

impl Block {
    fn whole(slot: String) -> Self {
        Block {
            slot,
            rows: None,
            cols: None,
        }
    }

    /// `n` columns from `col` (rows `rows`, all when `None`).
    fn columns(slot: String, rows: Option<(usize, usize)>, col: usize, n: usize) -> Self {
        Block {
            slot,
            rows,
            cols: Some((col, n)),
        }
    }

    /// `(first index, row stride, rows, columns)` of the block in the flat vector.
    fn locate(&self, slots: &[Slot]) -> Result<(usize, usize, usize, usize)> {
        let s = slots
            .iter()
            .find(|s| s.name == self.slot)
            .ok_or_else(|| Error::Domain(format!("the network has no tensor '{}'", self.slot)))?;
        let width = *s.shape.last().unwrap_or(&1);
        let total_rows = s.range().len() / width.max(1);
        let (r0, nr) = self.rows.unwrap_or((0, total_rows));
        let (c0, nc) = self.cols.unwrap_or((0, width));
        if r0 + nr > total_rows || c0 + nc > width {
            return Err(Error::Domain(format!(
                "block rows {r0}+{nr}, columns {c0}+{nc} outside '{}' {:?}",
                self.slot, s.shape
            )));
        }
        Ok((s.offset + r0 * width + c0, width, nr, nc))
    }

    fn gather(&self, slots: &[Slot], values: &[f32]) -> Result<(Vec<f32>, usize, usize)> {
        let (start, stride, nr, nc) = self.locate(slots)?;
        let data = (0..nr)
            .flat_map(|r| {
                values[start + r * stride..start + r * stride + nc]
                    .iter()
                    .copied()
            })
            .collect();
        Ok((data, nr, nc))
    }

    fn scatter(&self, slots: &[Slot], data: &[f32], values: &mut [f32]) -> Result<()> {
        let (start, stride, nr, nc) = self.locate(slots)?;
        if data.len() != nr * nc {
            return Err(Error::Domain(format!(
                "burn gave {} values for '{}' ({nr}×{nc})",
                data.len(),
                self.slot
            )));
        }
        for (r, row) in data.chunks_exact(nc).enumerate() {
            values[start + r * stride..start + r * stride + nc].copy_from_slice(row);
        }
        Ok(())
    }
}

/// A trainable burn tensor.
enum Target<'a> {
    Matrix(&'a mut Param<Tensor<2>>),
    Vector(&'a mut Param<Tensor<1>>),
}

type Visit<'f> = dyn FnMut(Target, Block) -> Result<()> + 'f;

fn linear(prefix: &str, l: &mut Linear, f: &mut Visit) -> Result<()> {
    f(
        Target::Matrix(&mut l.weight),
        Block::whole(format!("{prefix}.weight")),
    )?;
    let bias = l.bias.as_mut().expect("every layer has a bias");
    f(Target::Vector(bias), Block::whole(format!("{prefix}.bias")))
}

/// One gate of one direction of a recurrent layer: the engine's columns `col..col + H` of the
/// input weights and biases; the recurrent weights are rows `hh_row..hh_row + H` (the
/// direction) and columns `hh_col..hh_col + H` (the gate).
fn gate(
    name: &str,
    g: &mut GateController,
    col: usize,
    hh_row: Option<usize>,
    hh_col: usize,
    f: &mut Visit,
) -> Result<()> {
    let h = HIDDEN;
    let slot = |part: &str| format!("{name}.{part}");
    f(
        Target::Matrix(&mut g.input_transform.weight),
        Block::columns(slot("w_ih"), None, col, h),
    )?;
    let b_ih = g.input_transform.bias.as_mut().expect("gates have biases");
    f(
        Target::Vector(b_ih),
        Block::columns(slot("b_ih"), None, col, h),
    )?;
    f(
        Target::Matrix(&mut g.hidden_transform.weight),
        Block::columns(slot("w_hh"), hh_row.map(|r| (r, h)), hh_col, h),
    )?;
    let b_hh = g.hidden_transform.bias.as_mut().expect("gates have biases");
    f(
        Target::Vector(b_hh),
        Block::columns(slot("b_hh"), None, col, h),
    )
}

/// Every trainable tensor of `net` with its block in the engine's parameters.
fn visit(net: &mut BurnNet, f: &mut Visit) -> Result<()> {
    let h = HIDDEN;
    if let Some(stem) = &mut net.stem {
        linear("conv1", &mut stem.conv1, f)?;
        linear("conv2", &mut stem.conv2, f)?;
        for (name, bn) in [("bn1", &mut stem.bn1), ("bn2", &mut stem.bn2)] {
            f(
                Target::Vector(&mut bn.gamma),
                Block::whole(format!("{name}.weight")),
            )?;
            f(
                Target::Vector(&mut bn.beta),
                Block::whole(format!("{name}.bias")),
            )?;
        }
    }
    if let Some(lstm) = &mut net.lstm {
        for (d, dir) in [(0, &mut lstm.forward), (1, &mut lstm.reverse)] {
            let forget = dir
                .forget_gate
                .as_mut()
                .expect("no coupled input-forget gate");
            // Engine gate order i, f, g, o.
            for (k, g) in [
                (0, &mut dir.input_gate),
                (1, forget),
                (2, &mut dir.cell_gate),
                (3, &mut dir.output_gate),
            ] {
                gate("bilstm", g, d * 4 * h + k * h, Some(d * h), k * h, f)?;
            }
        }
    }
    if let Some(gru) = &mut net.gru {
        // Engine gate order r, z, n.
        for (k, g) in [
            (0, &mut gru.reset_gate),
            (1, &mut gru.update_gate),
            (2, &mut gru.new_gate),
        ] {
            gate("gru", g, k * h, None, k * h, f)?;
        }
    }
    linear("head.fc1", &mut net.fc1, f)?;
    linear("head.fc2", &mut net.fc2, f)?;
    linear("head.out", &mut net.out, f)
}

fn batch_norms(net: &mut BurnNet) -> Vec<(&'static str, &mut BatchNorm)> {
    match &mut net.stem {
        Some(stem) => vec![("bn1", &mut stem.bn1), ("bn2", &mut stem.bn2)],
        None => Vec::new(),
    }
}

/// Copies the engine's weights and running statistics into `net` on `device`.
pub(super) fn load(net: &mut BurnNet, p: &ParamSet, device: &Device) {
    visit(net, &mut |target, block| {
        let (data, rows, cols) = block.gather(&p.slots, &p.value)?;
        match target {
            Target::Matrix(param) => {
                let t = Tensor::from_data(TensorData::new(data, [rows, cols]), device);
                *param = Param::from_tensor(t);
            }
            Target::Vector(param) => {
                let t = Tensor::from_data(TensorData::new(data, [rows * cols]), device);
                *param = Param::from_tensor(t);
            }
        }
        Ok(())
    })
    .expect("the burn module is built from the same configuration as the engine network");
    for (name, bn) in batch_norms(net) {
        for (part, state) in [
            ("running_mean", &mut bn.running_mean),
            ("running_var", &mut bn.running_var),
        ] {
            let (data, _, n) = Block::whole(format!("{name}.{part}"))
                .gather(&p.slots, &p.value)
                .expect("batch-norm statistics present");
            *state = RunningState::new(Tensor::from_data(TensorData::new(data, [n]), device));
        }
    }
}

/// Writes the gradients of a backward pass into `p.grad` (a tensor burn reports none for gets
/// zeros: it did not take part).
pub(super) fn store_gradients(
    net: &mut BurnNet,
    grads: &Gradients,
    p: &mut ParamSet,
) -> Result<()> {
    p.grad.fill(0.0);
    let (slots, grad) = (&p.slots, &mut p.grad);
    visit(net, &mut |target, block| {
        let values = match target {
            Target::Matrix(param) => param.val().grad(grads).map(to_vec),
            Target::Vector(param) => param.val().grad(grads).map(to_vec),
        };
        if let Some(values) = values {
            block.scatter(slots, &values?, grad)?;
        }
        Ok(())
    })
}

/// Reads the running statistics burn's batch norm updated in a training forward pass over
/// `rows` rows back into `p.value`. burn updates the running variance with the biased batch
/// variance; the engine (and PyTorch) with the unbiased one, so the batch's share is rescaled
/// by rows/(rows − 1).
pub(super) fn store_running_stats(net: &mut BurnNet, p: &mut ParamSet, rows: usize) -> Result<()> {
    let unbias = if rows > 1 {
        rows as f32 / (rows as f32 - 1.0)
    } else {
        1.0
    };
    let keep = 1.0 - MOMENTUM;
    let (slots, value) = (&p.slots, &mut p.value);
    for (name, bn) in batch_norms(net) {
        let mean = to_vec(bn.running_mean.value_sync())?;
        Block::whole(format!("{name}.running_mean")).scatter(slots, &mean, value)?;
        let block = Block::whole(format!("{name}.running_var"));
        let (old, _, _) = block.gather(slots, value)?;
        let updated = to_vec(bn.running_var.value_sync())?;
        // burn: v' = k·v + m·s²_biased; engine: k·v + m·s²_biased·n/(n − 1).
        let var: Vec<f32> = old
            .iter()
            .zip(&updated)
            .map(|(&o, &u)| keep * o + (u - keep * o) * unbias)
            .collect();
        block.scatter(slots, &var, value)?;
    }
    Ok(())
}
