"""Distributed generation (Dask), the Slurm recipe, and the PyTorch-style window dataset."""

import filecmp
import os
import pathlib
import runpy
import subprocess
import sys

import numpy as np
import pytest

import railforce
from railforce.torch import WindowDataset, batches

ROOT = pathlib.Path(__file__).resolve().parents[2]


def _same_files(a: pathlib.Path, b: pathlib.Path) -> int:
    names = sorted(p.name for p in a.iterdir())
    assert "manifest.json" in names
    for n in names:
        assert filecmp.cmp(a / n, b / n, shallow=False), n
    return len(names)


def test_the_dask_run_equals_a_single_generate_byte_for_byte(tmp_path, capsys):
    pytest.importorskip("dask.distributed")
    single = tmp_path / "single"
    railforce.generate("demo", single, settle_s=1.0)
    sys.path.insert(0, str(ROOT / "examples/python"))
    try:
        dask_generate = __import__("dask_generate")
        dask_generate.main(["--plan", "demo", "--out", str(tmp_path / "dask"), "--workers", "2",
                            "--settle", "1"])
    finally:
        sys.path.pop(0)
    assert "merged" in capsys.readouterr().out
    assert _same_files(single, tmp_path / "dask") == 13  # 12 runs + manifest.json


def test_the_slurm_array_body_run_for_every_task_equals_one_process(cli):
    out = subprocess.run(["bash", str(ROOT / "examples/slurm/check.sh"), "demo", "3"],
                         check=True, capture_output=True, text=True,
                         env={**os.environ, "RAILFORCE": str(cli)})
    assert "equal to one process's" in out.stdout


def test_window_dataset_keeps_the_split_and_draws_fresh_noise_per_epoch(demo_data):
    train = WindowDataset(demo_data, "train", window=20, label="centre")
    test = WindowDataset(demo_data, "test", window=20, label="centre")
    ds = railforce.open_dataset(demo_data)
    seeds = ds.split
    assert {ds.runs[r][1] for r in set(train.run.tolist())} <= set(seeds["train"])
    assert {ds.runs[r][1] for r in set(test.run.tolist())} <= set(seeds["test"])
    x0, y0 = train._item(5)
    assert x0.shape == (20, 21) and y0.shape == (2,)
    # Training noise: the same within an epoch, new in the next; its σ is the data set's
    # noise (6 dB: σ ≈ 0.5 std, in standardised units about 0.5 of each channel's spread).
    again, _ = train._item(5)
    np.testing.assert_array_equal(x0, again)
    train.set_epoch(1)
    x1, y1 = train._item(5)
    assert not np.array_equal(x0, x1)
    np.testing.assert_array_equal(y0, y1)
    assert 0.2 < float(np.median(train.sigma)) < 1.0
    # Test windows read the fixed noisy copies: what `windows` gives, no fresh draw.
    w = railforce.windows(ds, "test", window=20, label="centre")
    xt, yt = next(batches(test, len(test), shuffle=False))
    np.testing.assert_allclose(xt, w["x"], atol=1e-6)
    np.testing.assert_allclose(yt, w["y"], atol=1e-6)


def test_the_training_example_runs(demo_data, capsys):
    sys_argv = sys.argv
    sys.argv = ["train_windows.py", str(demo_data)]
    try:
        runpy.run_path(str(ROOT / "examples/python/train_windows.py"), run_name="__main__")
    finally:
        sys.argv = sys_argv
    out = capsys.readouterr().out
    r2 = [float(line.split("R² ")[1].split(",")[0]) for line in out.splitlines() if "R²" in line]
    assert len(r2) == 2 and all(r > 0.5 for r in r2), out
