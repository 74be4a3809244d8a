"""Where the vertical force's information goes at 6 dB: ridge regression on flattened windows.

Reproduces the ridge column of the README's FQ table (numpy only):

    railforce generate --plan tracks/paper34.plan.toml --out /tmp/sf --snr-db 6
    python3 assets/analysis/fq_information.py /tmp/sf

Same protocol as railforce: each run cut into 70 / 15 / 15 % blocks before windowing, z-scores
from the training blocks, windows of W steps x 21 channels, label at the last (or centre) step,
test R^2 on the last 15 % of every run. Noise is drawn here (numpy's generator), with the spec's
sigma = rms(clean) * 10^(-SNR/20) unless a variant says otherwise.
"""
import glob
import json
import sys

import numpy as np

SNR = 6.0
data_dir = sys.argv[1]
manifest = json.load(open(f"{data_dir}/manifest.json"))
inputs = [c["name"] for c in manifest["channels"] if c.get("kind") == "input"]
runs = [np.load(f) for f in sorted(glob.glob(f"{data_dir}/*.npz"))]
vertical = [i for i, c in enumerate(inputs) if c.endswith("acc_z")]


def runs_xy(noise=None, seed=1):
    """(inputs, [FL, FQ]) per run; `noise(X)` returns the per-channel sigma or None."""
    rng = np.random.default_rng(seed)
    out = []
    for d in runs:
        x = np.stack([d[c] for c in inputs], 1)
        y = np.stack([d["w1l_force_y"], d["w1l_force_z"]], 1)
        if noise is not None:
            x = x + rng.normal(size=x.shape) * noise(x)
        out.append((x, y))
    return out


def spec_sigma(x):
    return np.sqrt((x**2).mean(0)) * 10 ** (-SNR / 20)


def windows(x, y, w, step, centre):
    idx = np.arange(w - 1, len(y), step)
    feats = np.concatenate([x[idx - w + 1 + k] for k in range(w)], 1)
    return feats, y[idx - (w // 2 if centre else 0)]


def ridge_r2(data, w=20, centre=False, lam=1e-3):
    """Test R^2 of [FL, FQ]."""
    parts = {"train": ([], []), "test": ([], [])}
    for x, y in data:
        n = len(y)
        a, b = int(0.7 * n), int(0.85 * n)
        for name, (xs, ys), step in [("train", (x[:a], y[:a]), 3), ("test", (x[b:], y[b:]), 2)]:
            f, l = windows(xs, ys, w, step, centre)
            parts[name][0].append(f)
            parts[name][1].append(l)
    xtr, ytr = (np.concatenate(p) for p in parts["train"])
    xte, yte = (np.concatenate(p) for p in parts["test"])
    mu, sd = xtr.mean(0), xtr.std(0) + 1e-12
    xtr, xte = (xtr - mu) / sd, (xte - mu) / sd
    ym, ys = ytr.mean(0), ytr.std(0)
    a = xtr.T @ xtr + lam * len(ytr) * np.eye(xtr.shape[1])
    p = xte @ np.linalg.solve(a, xtr.T @ ((ytr - ym) / ys)) * ys + ym
    return 1 - ((yte - p) ** 2).sum(0) / ((yte - yte.mean(0)) ** 2).sum(0)


def show(label, r2):
    print(f"{label:58s} FL {r2[0]:6.3f}  FQ {r2[1]:6.3f}", flush=True)


show("clean inputs", ridge_r2(runs_xy()))
noisy = runs_xy(spec_sigma)
show(f"every input noised at {SNR} dB (the spec)", ridge_r2(noisy))
show("  label at the centre step", ridge_r2(noisy, centre=True))
for w in (40, 80, 120):
    show(f"  {w} steps", ridge_r2(noisy, w))
    show(f"  {w} steps, centre", ridge_r2(noisy, w, centre=True))


def vertical_clean(x):
    s = spec_sigma(x)
    s[vertical] = 0.0
    return s


show("vertical accelerometers clean, the rest noised", ridge_r2(runs_xy(vertical_clean)))
pooled_std = np.concatenate([x for x, _ in runs_xy()]).std(0)
show("sigma from the standard deviation (not the spec)",
     ridge_r2(runs_xy(lambda x: pooled_std * 10 ** (-SNR / 20))))

# The share of FQ's test-block variance a perfect low-pass estimate would explain.
for fc in (0.5, 2.0, 5.0, 10.0):
    n = max(1, int(200.0 / fc))
    kernel = np.ones(n) / n
    err, tot, ys = 0.0, 0.0, []
    for d in runs:
        q = d["w1l_force_z"]
        slow = np.convolve(np.pad(q, (n // 2, n - 1 - n // 2), mode="edge"), kernel, "valid")
        b = int(0.85 * len(q))
        err += ((q[b:] - slow[b:]) ** 2).sum()
        ys.append(q[b:])
    y = np.concatenate(ys)
    print(f"true FQ low-passed at {fc:4.1f} Hz explains R^2 {1 - err / ((y - y.mean()) ** 2).sum():.3f}")
