"""The four railforce networks as PyTorch modules, loading `railforce export` files.

    import railforce_nets
    net = railforce_nets.load("models/demo/model.safetensors")   # eval mode
    forces_n = net(x)   # x: [batch, window, channels] in physical units, channels in
                        # net.channels order; returns [batch, targets] in N

The layers are the engine's (assets/docs/learning.md §3): an optional stem
Conv1d(C, C, 1) → LeakyReLU → BatchNorm1d → Conv1d(C, 128, 1) → LeakyReLU → BatchNorm1d →
MaxPool1d(2, stride 1); then a BiLSTM (20 per direction, final states of both directions),
a GRU (20, final state) or the flattened stem; then the head Linear(F, 64) → LeakyReLU →
Dropout → Linear(64, 8) → LeakyReLU → Linear(8, outputs) (dropout also before fc1). Inputs
are z-scored and outputs un-scaled with the statistics stored beside the weights. A network
trained with quantile heads (metadata `quantile_coverage`) returns `3 × targets` columns: the
targets, their lower and their upper quantiles (uncalibrated; `railforce calibrate` fits the
intervals `identify` reports).

Reading the file needs `safetensors` (pip install safetensors) or nothing but this file:
`read_safetensors` below parses the format with the standard library and numpy.
"""
import json
import struct

import numpy as np

try:  # the module needs torch; the reader below does not
    import torch
    from torch import nn
except ImportError:  # pragma: no cover
    torch = None
    nn = None

LEAKY_SLOPE = 0.01
STEM_WIDTH = 128
HIDDEN = 20


def read_safetensors(path):
    """(tensors as numpy float32 arrays by name, metadata dict) of a safetensors file."""
    with open(path, "rb") as f:
        raw = f.read()
    (n,) = struct.unpack("<Q", raw[:8])
    header = json.loads(raw[8 : 8 + n])
    meta = header.pop("__metadata__", {})
    base = 8 + n
    out = {}
    for name, t in header.items():
        if t["dtype"] != "F32":
            raise ValueError(f"{path}: {name} is {t['dtype']}, expected F32")
        a, b = t["data_offsets"]
        out[name] = np.frombuffer(raw[base + a : base + b], dtype="<f4").reshape(t["shape"])
    return out, meta


if nn is not None:

    class RailforceNet(nn.Module):
        """One of cnn-bilstm, cnn, bilstm, gru with the engine's layer table."""

        def __init__(self, architecture, window, channels, outputs, dropout=0.0, targets=None):
            super().__init__()
            self.architecture = architecture
            self.window, self.n_in, self.outputs = window, channels, outputs
            self.stem = architecture in ("cnn-bilstm", "cnn")
            if self.stem:
                self.conv1 = nn.Conv1d(channels, channels, 1)
                self.bn1 = nn.BatchNorm1d(channels)
                self.conv2 = nn.Conv1d(channels, STEM_WIDTH, 1)
                self.bn2 = nn.BatchNorm1d(STEM_WIDTH)
                self.pool = nn.MaxPool1d(2, stride=1)
            d = STEM_WIDTH if self.stem else channels
            if architecture in ("cnn-bilstm", "bilstm"):
                self.lstm = nn.LSTM(d, HIDDEN, batch_first=True, bidirectional=True)
                feat = 2 * HIDDEN
            elif architecture == "gru":
                self.gru = nn.GRU(d, HIDDEN, batch_first=True)
                feat = HIDDEN
            elif architecture == "cnn":
                feat = (window - 1) * STEM_WIDTH
            else:
                raise ValueError(f"unknown architecture {architecture!r}")
            self.drop = nn.Dropout(dropout)
            self.fc1 = nn.Linear(feat, 64)
            self.fc2 = nn.Linear(64, 8)
            self.out = nn.Linear(8, outputs)
            self.targets_n = targets or outputs
            for name, size in (("input", channels), ("target", self.targets_n)):
                self.register_buffer(f"{name}_mean", torch.zeros(size))
                self.register_buffer(f"{name}_std", torch.ones(size))

        def forward(self, x):
            z = (x - self.input_mean) / self.input_std
            act = lambda v: nn.functional.leaky_relu(v, LEAKY_SLOPE)
            if self.stem:
                h = z.transpose(1, 2)  # [B, C, T]
                h = self.bn1(act(self.conv1(h)))
                h = self.bn2(act(self.conv2(h)))
                seq = self.pool(h).transpose(1, 2)  # [B, T-1, 128]
            else:
                seq = z
            if self.architecture in ("cnn-bilstm", "bilstm"):
                _, (h_n, _) = self.lstm(seq)
                feat = torch.cat([h_n[0], h_n[1]], dim=1)
            elif self.architecture == "gru":
                _, h_n = self.gru(seq)
                feat = h_n[0]
            else:
                feat = seq.reshape(seq.shape[0], -1)  # time-major, as the engine
            h = act(self.fc1(self.drop(feat)))
            h = act(self.fc2(self.drop(h)))
            k = self.outputs // self.targets_n  # 1, or 3 with quantile heads
            return self.out(h) * self.target_std.repeat(k) + self.target_mean.repeat(k)

    def load(path):
        """The network of a `railforce export` file, in eval mode, with `.channels` and
        `.targets` (names in input and output order), `.label_at` and `.quantile_coverage`
        (None without quantile heads)."""
        tensors, meta = read_safetensors(path)
        channels = meta["channels"].split(",")
        targets = meta["targets"].split(",")
        outputs = int(meta.get("outputs", len(targets)))
        net = RailforceNet(
            meta["architecture"], int(meta["window"]), len(channels), outputs, targets=len(targets)
        )
        state = {k: torch.from_numpy(v.copy()) for k, v in tensors.items()}
        missing, unexpected = net.load_state_dict(state, strict=False)
        if unexpected or any(not k.endswith("num_batches_tracked") for k in missing):
            raise ValueError(f"{path}: missing {missing}, unexpected {unexpected}")
        net.channels, net.targets, net.label_at = channels, targets, meta.get("label_at")
        c = meta.get("quantile_coverage")
        net.quantile_coverage = float(c) if c is not None else None
        return net.eval()
