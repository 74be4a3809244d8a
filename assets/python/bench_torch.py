"""Training and inference throughput of the railforce networks in PyTorch, the same-run
reference of `railforce bench learn --against-torch`: windows per second of forward +
backward + Adam on 21-channel, 20-step windows, one output, dropout 0.2, as the engine's
benchmark builds them (`railforce_nets.RailforceNet`, the module `railforce export` targets).

    python3 bench_torch.py [--device cuda|cpu] [--batches 64,256,1024] [--seconds 3]
    python3 bench_torch.py --serve --threads 1 --batch 64

`--serve` answers one measurement per line on stdin, for alternating rounds driven by
`railforce bench learn --against-torch`:

    train <architecture> <seconds>   ->  train <windows/s>
    infer <architecture> <seconds>   ->  infer <windows/s>   (eval mode, batches of 1024)

Installing the CPU build of PyTorch (no CUDA libraries):

    pip install torch --index-url https://download.pytorch.org/whl/cpu
"""
import argparse
import os
import sys
import time

import torch

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import railforce_nets  # noqa: E402

WINDOW, CHANNELS, INFER_BATCH = 20, 21, 1024


def windows(batch, device):
    """The engine's benchmark windows: sin(0.618·i) over the batch, row-major [B, T, C]."""
    i = torch.arange(batch * WINDOW * CHANNELS, dtype=torch.float32, device=device)
    return torch.sin(0.618 * i).reshape(batch, WINDOW, CHANNELS)


class Trainer:
    """One network, its optimiser and its batch, kept between rounds."""

    def __init__(self, arch, batch, device):
        self.device = device
        self.net = railforce_nets.RailforceNet(arch, WINDOW, CHANNELS, 1, dropout=0.2).to(device)
        self.opt = torch.optim.Adam(self.net.parameters(), lr=1e-3)
        self.x = windows(batch, device)
        self.batch = batch
        b = torch.arange(batch, dtype=torch.float32, device=device)
        self.y = torch.cos(0.1 * b).reshape(batch, 1)
        self.big = windows(INFER_BATCH, device)
        for _ in range(5):  # warm-up, untimed (allocator, cuDNN plans); the engine takes three
            self.step()
        with torch.no_grad():
            self.net.eval()
            self.net(self.big)
        self.sync()

    def sync(self):
        if self.device == "cuda":
            torch.cuda.synchronize()

    def step(self):
        self.net.train()
        self.opt.zero_grad(set_to_none=True)
        loss = torch.mean((self.net(self.x) - self.y) ** 2)
        loss.backward()
        self.opt.step()
        return loss

    def train_rate(self, seconds):
        done, t0 = 0, time.perf_counter()
        while time.perf_counter() - t0 < seconds or done == 0:
            self.step().item()  # one sync per step, as railforce reads each step's loss
            done += self.batch
        return done / (time.perf_counter() - t0)

    def infer_rate(self, seconds):
        self.net.eval()
        done, t0 = 0, time.perf_counter()
        with torch.no_grad():
            while time.perf_counter() - t0 < seconds or done == 0:
                self.net(self.big)
                self.sync()
                done += INFER_BATCH
        return done / (time.perf_counter() - t0)


def serve(batch, device):
    trainers = {}
    print(f"ready PyTorch {torch.__version__} on {device}, threads {torch.get_num_threads()}", flush=True)
    for line in sys.stdin:
        parts = line.split()
        if not parts:
            continue
        if parts[0] == "quit":
            break
        if len(parts) != 3 or parts[0] not in ("train", "infer"):
            print(f"error: unknown request {line.strip()!r}", flush=True)
            continue
        what, arch, seconds = parts[0], parts[1], float(parts[2])
        if arch not in trainers:
            trainers[arch] = Trainer(arch, batch, device)
        t = trainers[arch]
        rate = t.train_rate(seconds) if what == "train" else t.infer_rate(seconds)
        print(f"{what} {rate:.3f}", flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--device", default="cuda" if torch.cuda.is_available() else "cpu")
    ap.add_argument("--batches", default="64")
    ap.add_argument("--batch", type=int, default=64, help="training batch of --serve")
    ap.add_argument("--seconds", type=float, default=3.0)
    ap.add_argument("--threads", type=int, default=0, help="CPU threads (0: PyTorch's own)")
    ap.add_argument("--serve", action="store_true", help="answer requests on stdin")
    a = ap.parse_args()
    if a.threads > 0:
        torch.set_num_threads(a.threads)
        torch.set_num_interop_threads(a.threads)
    if a.serve:
        serve(a.batch, a.device)
        return
    name = torch.cuda.get_device_name(0) if a.device == "cuda" else "cpu"
    print(f"PyTorch {torch.__version__} on {name}, {torch.get_num_threads()} threads")
    print(f"{'network':<11} {'batch':>6} {'train win/s':>12}")
    for arch in ("cnn-bilstm", "cnn", "bilstm", "gru"):
        for b in (int(v) for v in a.batches.split(",")):
            rate = Trainer(arch, b, a.device).train_rate(a.seconds)
            print(f"{arch:<11} {b:>6} {rate:>12.0f}", flush=True)


if __name__ == "__main__":
    main()
