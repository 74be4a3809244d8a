"""Shared fixtures: the command-line binary (to compare with), a small data set generated
once (the built-in demo plan with 6 dB noisy copies) and a model trained on it."""

import os
import pathlib
import subprocess

import pytest

import railforce

ROOT = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def cli() -> pathlib.Path:
    """The railforce binary: $RAILFORCE_BIN, else target/release/railforce (built if absent)."""
    path = pathlib.Path(os.environ.get("RAILFORCE_BIN", ROOT / "target/release/railforce"))
    if not path.exists():
        subprocess.run(["cargo", "build", "--release", "--locked"], cwd=ROOT, check=True)
    return path


@pytest.fixture(scope="session")
def demo_data(tmp_path_factory) -> pathlib.Path:
    out = tmp_path_factory.mktemp("data") / "demo"
    railforce.generate("demo", out, snr_db=6.0, settle_s=1.0)
    return out


@pytest.fixture(scope="session")
def demo_model(cli, demo_data, tmp_path_factory) -> pathlib.Path:
    out = tmp_path_factory.mktemp("models") / "tree"
    subprocess.run(
        [str(cli), "train", "--data", str(demo_data), "--model", "tree", "--out", str(out)],
        check=True,
        capture_output=True,
    )
    return out
