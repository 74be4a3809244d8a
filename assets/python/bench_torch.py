"""Training throughput of the four railforce networks in PyTorch (the reference beside
`railforce bench learn --burn …`): windows per second of forward + backward + Adam on
21-channel, 20-step windows, one output, dropout 0.2, as the engine's benchmark.

    python3 bench_torch.py [--device cuda|cpu] [--batches 64,256,1024] [--seconds 3]
"""
import argparse
import os
import sys
import time

import torch

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import railforce_nets  # noqa: E402


def rate(arch, batch, seconds, device):
    net = railforce_nets.RailforceNet(arch, 20, 21, 1, dropout=0.2).to(device).train()
    opt = torch.optim.Adam(net.parameters(), lr=1e-3)
    i = torch.arange(batch * 20 * 21, dtype=torch.float32, device=device)
    x = torch.sin(0.618 * i).reshape(batch, 20, 21)
    y = torch.cos(0.1 * torch.arange(batch, dtype=torch.float32, device=device)).reshape(batch, 1)

    def step():
        opt.zero_grad(set_to_none=True)
        loss = torch.mean((net(x) - y) ** 2)
        loss.backward()
        opt.step()
        return loss

    for _ in range(5):  # warm-up (cuDNN plans, allocator)
        step()
    if device == "cuda":
        torch.cuda.synchronize()
    done, t0 = 0, time.perf_counter()
    while time.perf_counter() - t0 < seconds or done == 0:
        step().item()  # one sync per step, as railforce reads each step's loss
        done += batch
    return done / (time.perf_counter() - t0)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--device", default="cuda" if torch.cuda.is_available() else "cpu")
    ap.add_argument("--batches", default="64")
    ap.add_argument("--seconds", type=float, default=3.0)
    a = ap.parse_args()
    name = torch.cuda.get_device_name(0) if a.device == "cuda" else "cpu"
    print(f"PyTorch {torch.__version__} on {name}")
    print(f"{'network':<11} {'batch':>6} {'train win/s':>12}")
    for arch in ("cnn-bilstm", "cnn", "bilstm", "gru"):
        for b in (int(v) for v in a.batches.split(",")):
            print(f"{arch:<11} {b:>6} {rate(arch, b, a.seconds, a.device):>12.0f}", flush=True)


if __name__ == "__main__":
    main()
