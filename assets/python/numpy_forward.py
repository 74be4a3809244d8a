"""The forward pass of a `railforce export` file with numpy alone: an independent check of
the engine and of the export's names and layouts (tests/export.rs runs it).

    python3 numpy_forward.py model.safetensors run.npz out.csv

reads the run's channels in the model's order, z-scores them, slides the window one sample
at a time, and writes `time_s` (at the label position) and each target in N, as
`railforce identify` does. A model trained with quantile heads (metadata `quantile_coverage`)
also gets each target's raw lower and upper quantiles (`<target>_lower_N`, `<target>_upper_N`),
before the calibration `identify` applies to its intervals.
"""
import sys

import numpy as np

from railforce_nets import HIDDEN, LEAKY_SLOPE, read_safetensors


def leaky(v):
    return np.where(v < 0, v * LEAKY_SLOPE, v)


def sigmoid(v):
    return 1.0 / (1.0 + np.exp(-v))


def linear(t, name, x):
    return x @ t[f"{name}.weight"].T.astype(np.float64) + t[f"{name}.bias"]


def batch_norm(t, name, x):  # x [..., C]
    m, v = t[f"{name}.running_mean"], t[f"{name}.running_var"]
    return (x - m) / np.sqrt(v + 1e-5) * t[f"{name}.weight"] + t[f"{name}.bias"]


def lstm_dir(t, suffix, seq, reverse):
    wi, wh = t[f"lstm.weight_ih_l0{suffix}"], t[f"lstm.weight_hh_l0{suffix}"]
    b = t[f"lstm.bias_ih_l0{suffix}"] + t[f"lstm.bias_hh_l0{suffix}"]
    n, steps, _ = seq.shape
    h = np.zeros((n, HIDDEN))
    c = np.zeros((n, HIDDEN))
    order = range(steps - 1, -1, -1) if reverse else range(steps)
    for s in order:
        g = seq[:, s] @ wi.T + h @ wh.T + b
        i, f, gg, o = np.split(g, 4, axis=1)  # PyTorch gate order
        c = sigmoid(f) * c + sigmoid(i) * np.tanh(gg)
        h = sigmoid(o) * np.tanh(c)
    return h


def gru(t, seq):
    wi, wh = t["gru.weight_ih_l0"], t["gru.weight_hh_l0"]
    bi, bh = t["gru.bias_ih_l0"], t["gru.bias_hh_l0"]
    n, steps, _ = seq.shape
    h = np.zeros((n, HIDDEN))
    for s in range(steps):
        gi = seq[:, s] @ wi.T + bi
        gh = h @ wh.T + bh
        r = sigmoid(gi[:, :HIDDEN] + gh[:, :HIDDEN])
        z = sigmoid(gi[:, HIDDEN : 2 * HIDDEN] + gh[:, HIDDEN : 2 * HIDDEN])
        nn_ = np.tanh(gi[:, 2 * HIDDEN :] + r * gh[:, 2 * HIDDEN :])
        h = (1 - z) * nn_ + z * h
    return h


def unscale(t, y):
    """Standardised outputs [n, k·targets] (means, then any quantile blocks) in N."""
    k = y.shape[1] // len(t["target_std"])
    return y * np.tile(t["target_std"], k) + np.tile(t["target_mean"], k)


def forward(t, meta, x):
    """x [n, window, channels] physical → [n, outputs] in N (float64 throughout): the
    targets, then, with quantile heads, their lower and upper quantiles."""
    arch = meta["architecture"]
    z = (x - t["input_mean"]) / t["input_std"]
    if arch in ("cnn-bilstm", "cnn"):
        w1 = t["conv1.weight"][:, :, 0]
        w2 = t["conv2.weight"][:, :, 0]
        h = batch_norm(t, "bn1", leaky(z @ w1.T + t["conv1.bias"]))
        h = batch_norm(t, "bn2", leaky(h @ w2.T + t["conv2.bias"]))
        seq = np.maximum(h[:, :-1], h[:, 1:])  # MaxPool1d(2, stride 1) over time
    else:
        seq = z
    if arch in ("cnn-bilstm", "bilstm"):
        feat = np.concatenate([lstm_dir(t, "", seq, False), lstm_dir(t, "_reverse", seq, True)], axis=1)
    elif arch == "gru":
        feat = gru(t, seq)
    else:
        feat = seq.reshape(seq.shape[0], -1)
    h = leaky(linear(t, "fc1", feat))
    h = leaky(linear(t, "fc2", h))
    return unscale(t, linear(t, "out", h))


def main(model, run, out):
    t, meta = read_safetensors(model)
    t = {k: v.astype(np.float64) for k, v in t.items()}
    data = np.load(run)
    channels = meta["channels"].split(",")
    w = int(meta["window"])
    cols = np.stack([data[c].astype(np.float64) for c in channels], axis=1)
    time = data["time_s"]
    n = len(time) - w + 1
    windows = np.stack([cols[s : s + w] for s in range(n)])
    off = {"last": w - 1}.get(meta.get("label_at", "").lower(), w // 2)
    y = forward(t, meta, windows)
    targets = meta["targets"].split(",")
    names = [f"{c}_N" for c in targets]
    if "quantile_coverage" in meta:
        names += [f"{c}_lower_N" for c in targets] + [f"{c}_upper_N" for c in targets]
    with open(out, "w") as f:
        f.write("time_s," + ",".join(names) + "\n")
        for s in range(n):
            f.write(f"{time[s + off]:.3f}," + ",".join(f"{v:.3f}" for v in y[s]) + "\n")


if __name__ == "__main__":
    main(*sys.argv[1:4])
