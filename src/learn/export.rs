//! Export of a network's weights as safetensors (<https://github.com/huggingface/safetensors>:
//! an 8-byte little-endian header length, a JSON header naming each tensor's dtype, shape and
//! byte range, then the raw little-endian data), named and laid out as the PyTorch module of
//! the same layers in `assets/python/railforce_nets.py` expects (`load_state_dict(strict=True)`).
//!
//! The engine keeps a dense layer's weight as `W[in, out]` (`y = x·W + b`); PyTorch's
//! `Linear` and `Conv1d(k=1)` keep `[out, in]` (and `[out, in, 1]`); recurrent layers keep
//! each direction's `[4H, in]` (LSTM, gates i f g o) or `[3H, in]` (GRU, gates r z n).
//! The z-score statistics of the inputs and targets go along as buffers, so the module takes
//! physical inputs and returns forces in N, as `railforce identify` does.

use super::model::{Engine, Model};
use super::neural::network::Architecture;
use crate::error::{Error, Result};
use std::collections::BTreeMap;

/// One tensor to write: name, shape, values (f32, row-major).
struct Tensor {
    name: String,
    shape: Vec<usize>,
    data: Vec<f32>,
}

/// `w[rows, cols]` (row-major) transposed to `[cols, rows]`.
fn transpose(w: &[f32], rows: usize, cols: usize) -> Vec<f32> {
    let mut t = vec![0.0; w.len()];
    for r in 0..rows {
        for c in 0..cols {
            t[c * rows + r] = w[r * cols + c];
        }
    }
    t
}

/// Columns `from..to` of `w[rows, cols]`.
fn columns(w: &[f32], rows: usize, cols: usize, from: usize, to: usize) -> Vec<f32> {
    (0..rows)
        .flat_map(|r| w[r * cols + from..r * cols + to].iter().copied())
        .collect()
}

fn tensor(name: impl Into<String>, shape: Vec<usize>, data: Vec<f32>) -> Tensor {
    Tensor {
        name: name.into(),
        shape,
        data,
    }
}

/// The PyTorch state dict of a network model, in the module's names: dense layers first,
/// then batch norms, the recurrent layer and the z-score buffers.
fn tensors(model: &Model) -> Result<Vec<Tensor>> {
    let Engine::Net(net) = &model.engine else {
        return Err(Error::Domain(format!(
            "{} is a classical model: only the networks (cnn-bilstm, cnn, bilstm, gru) export to safetensors",
            model.meta.kind.name()
        )));
    };
    let p = &net.params;
    let get = |name: &str| -> Result<(&[f32], &[usize])> {
        let s = p
            .slots
            .iter()
            .find(|s| s.name == name)
            .ok_or_else(|| Error::Domain(format!("the network has no tensor '{name}'")))?;
        Ok((&p.value[s.range()], &s.shape))
    };
    let arch = net.config.architecture;
    let stem = matches!(arch, Architecture::CnnBiLstm | Architecture::Cnn);
    let mut out = Vec::new();
    // Dense layers: ours `[in, out]`, PyTorch `[out, in]` (`[out, in, 1]` for a Conv1d).
    let convs: &[(&str, &str, bool)] = if stem {
        &[("conv1", "conv1", true), ("conv2", "conv2", true)]
    } else {
        &[]
    };
    let heads = [
        ("head.fc1", "fc1", false),
        ("head.fc2", "fc2", false),
        ("head.out", "out", false),
    ];
    for &(ours, theirs, conv) in convs.iter().chain(&heads) {
        let (w, shape) = get(&format!("{ours}.weight"))?;
        let (din, dout) = (shape[0], shape[1]);
        let shape = if conv {
            vec![dout, din, 1]
        } else {
            vec![dout, din]
        };
        out.push(tensor(
            format!("{theirs}.weight"),
            shape,
            transpose(w, din, dout),
        ));
        let bias = get(&format!("{ours}.bias"))?.0.to_vec();
        out.push(tensor(format!("{theirs}.bias"), vec![dout], bias));
    }
    if stem {
        for bn in ["bn1", "bn2"] {
            for part in ["weight", "bias", "running_mean", "running_var"] {
                let (v, shape) = get(&format!("{bn}.{part}"))?;
                out.push(tensor(format!("{bn}.{part}"), shape.to_vec(), v.to_vec()));
            }
        }
    }
    match arch {
        Architecture::CnnBiLstm | Architecture::BiLstm => {
            let (w_ih, s) = get("bilstm.w_ih")?;
            let (din, g8) = (s[0], s[1]);
            let g4 = g8 / 2;
            let h = g4 / 4;
            let (w_hh, _) = get("bilstm.w_hh")?;
            let (b_ih, _) = get("bilstm.b_ih")?;
            let (b_hh, _) = get("bilstm.b_hh")?;
            for (dir, suffix) in [(0, ""), (1, "_reverse")] {
                let gates = dir * g4..(dir + 1) * g4;
                let wi = columns(w_ih, din, g8, gates.start, gates.end);
                let wh = &w_hh[dir * h * g4..(dir + 1) * h * g4];
                out.extend([
                    tensor(
                        format!("lstm.weight_ih_l0{suffix}"),
                        vec![g4, din],
                        transpose(&wi, din, g4),
                    ),
                    tensor(
                        format!("lstm.weight_hh_l0{suffix}"),
                        vec![g4, h],
                        transpose(wh, h, g4),
                    ),
                    tensor(
                        format!("lstm.bias_ih_l0{suffix}"),
                        vec![g4],
                        b_ih[gates.clone()].to_vec(),
                    ),
                    tensor(
                        format!("lstm.bias_hh_l0{suffix}"),
                        vec![g4],
                        b_hh[gates].to_vec(),
                    ),
                ]);
            }
        }
        Architecture::Gru => {
            let (w_ih, s) = get("gru.w_ih")?;
            let (din, g3) = (s[0], s[1]);
            let (w_hh, s) = get("gru.w_hh")?;
            let h = s[0];
            out.extend([
                tensor("gru.weight_ih_l0", vec![g3, din], transpose(w_ih, din, g3)),
                tensor("gru.weight_hh_l0", vec![g3, h], transpose(w_hh, h, g3)),
                tensor("gru.bias_ih_l0", vec![g3], get("gru.b_ih")?.0.to_vec()),
                tensor("gru.bias_hh_l0", vec![g3], get("gru.b_hh")?.0.to_vec()),
            ]);
        }
        Architecture::Cnn => {}
    }
    let m = &model.meta;
    for (which, stats) in [("input", &m.input_stats), ("target", &m.target_stats)] {
        for (part, v) in [("mean", &stats.mean), ("std", &stats.std)] {
            let data: Vec<f32> = v.iter().map(|&x| x as f32).collect();
            out.push(tensor(format!("{which}_{part}"), vec![data.len()], data));
        }
    }
    Ok(out)
}

/// The safetensors bytes of a network model. The header's `__metadata__` names the
/// architecture, window, label position, channels and targets (what the Python module and
/// a reader need to rebuild the network and its inputs).
pub fn to_safetensors(model: &Model) -> Result<Vec<u8>> {
    let tensors = tensors(model)?;
    let Engine::Net(net) = &model.engine else {
        unreachable!("tensors() refuses classical models");
    };
    let spec = &model.meta.data;
    let mut header = serde_json::Map::new();
    let mut meta = BTreeMap::new();
    meta.insert("format", "pt".to_string());
    meta.insert("architecture", net.config.architecture.name().to_string());
    meta.insert("window", spec.window.to_string());
    meta.insert("channels", spec.channels.join(","));
    meta.insert("targets", spec.targets.join(","));
    meta.insert(
        "label_at",
        serde_json::to_value(spec.label_at)
            .ok()
            .and_then(|v| v.as_str().map(String::from))
            .unwrap_or_default(),
    );
    meta.insert("outputs", net.config.outputs.to_string());
    if let Some(c) = net.config.quantiles {
        // The output rows are then the targets' means, lower and upper quantiles at this
        // central coverage, each block un-scaled with the target statistics.
        meta.insert("quantile_coverage", c.to_string());
    }
    meta.insert(
        "note",
        "written by railforce export; module: assets/python/railforce_nets.py".into(),
    );
    header.insert("__metadata__".into(), serde_json::to_value(&meta).unwrap());
    let mut offset = 0usize;
    for t in &tensors {
        let bytes = 4 * t.data.len();
        header.insert(
            t.name.clone(),
            serde_json::json!({
                "dtype": "F32",
                "shape": t.shape,
                "data_offsets": [offset, offset + bytes],
            }),
        );
        offset += bytes;
    }
    let mut head = serde_json::to_string(&header)
        .map_err(|e| Error::Domain(format!("safetensors header: {e}")))?
        .into_bytes();
    // Pad the header with spaces so the data starts 8-byte aligned.
    while (8 + head.len()) % 8 != 0 {
        head.push(b' ');
    }
    let mut out = Vec::with_capacity(8 + head.len() + offset);
    out.extend_from_slice(&(head.len() as u64).to_le_bytes());
    out.extend_from_slice(&head);
    for t in &tensors {
        for v in &t.data {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    Ok(out)
}
