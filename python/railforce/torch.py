"""A PyTorch-style dataset of railforce windows, in pure Python.

``WindowDataset`` serves the windows of one part of a data set's leak-free split (whole runs
by seed: a seed never serves two parts, and a window never crosses a run boundary), each a
``(x, y)`` pair: ``x`` float32 ``[window, channels]``, ``y`` float32 ``[targets]``,
standardised with the training part's statistics as ``railforce train`` does.

Under the matched noise protocol (a data set generated with ``snr_db``), the training part
reads the clean inputs plus fresh white Gaussian noise drawn per epoch with each run's and
channel's σ (the trainer's noise model, assets/docs/learning.md §1.4); validation and test read
the data set's fixed noisy copies. Call ``set_epoch(e)`` at the start of every epoch: the
noise is a function of (seed, epoch, window), so runs are reproducible and workers agree.

torch is imported only if it is installed: ``WindowDataset`` then subclasses
``torch.utils.data.Dataset`` and returns tensors; without torch it returns NumPy arrays and
works with any loop (see ``batches``).
"""

from __future__ import annotations

from typing import Iterator, Optional, Sequence, Tuple

import numpy as np

from . import _windows

try:  # pragma: no cover - depends on the environment
    import torch as _torch

    _Base = _torch.utils.data.Dataset
except ImportError:  # pragma: no cover - depends on the environment
    _torch = None
    _Base = object

__all__ = ["WindowDataset", "batches"]


class WindowDataset(_Base):  # type: ignore[misc, valid-type]
    """Windows of one part (``train``, ``val``, ``test``) of a railforce data set.

    Args:
        dataset: a data set folder or a :class:`railforce.Dataset`.
        split: ``train``, ``val`` or ``test``.
        channels: input channels (default: the paper's 21).
        window: steps per window (20 at 200 Hz: 0.1 s).
        label: ``centre`` (the paper's) or ``last`` (causal).
        targets: ``FL``, ``FQ``, ``both``, a wheel (``2R``) or channel names.
        stride: step between training windows.
        noise: ``matched``, ``clean`` or ``train-clean-test-noisy`` (default: matched when
            the data set has noisy copies).
        seed: seed of the per-epoch noise.
    """

    def __init__(
        self,
        dataset,
        split: str = "train",
        channels: Optional[Sequence[str]] = None,
        window: int = 20,
        label: str = "centre",
        targets: str = "both",
        stride: int = 1,
        noise: Optional[str] = None,
        seed: int = 0,
    ) -> None:
        src = _windows(dataset, split, channels, window, label, targets, stride, noise, True)
        self.inputs = src["inputs"]  # per run, [rows, channels] float32
        self.target_rows = src["target_rows"]  # per run, [rows, targets] float32
        self.sigma = src["sigma"]  # [runs, channels] or None: no fresh noise
        self.run = src["run"]
        self.start = src["start"]
        self.window = int(window)
        self.label_offset = int(src["label_offset"])
        self.channels = list(src["channels"])
        self.targets = list(src["targets"])
        self.input_mean, self.input_std = src["input_mean"], src["input_std"]
        self.target_mean, self.target_std = src["target_mean"], src["target_std"]
        self.split = split
        self.seed = int(seed)
        self.epoch = 0

    def set_epoch(self, epoch: int) -> None:
        """Draws the training noise of ``epoch`` from now on (call it once per epoch)."""
        self.epoch = int(epoch)

    def __len__(self) -> int:
        return len(self.run)

    def _item(self, i: int) -> Tuple[np.ndarray, np.ndarray]:
        r, s = int(self.run[i]), int(self.start[i])
        x = self.inputs[r][s : s + self.window]  # a view: no copy
        if self.sigma is not None:
            rng = np.random.default_rng((self.seed, self.epoch, i))
            x = x + self.sigma[r] * rng.standard_normal(x.shape, dtype=np.float32)
        y = self.target_rows[r][s + self.label_offset]
        return x, y

    def __getitem__(self, i: int):
        x, y = self._item(i)
        if _torch is not None:
            return _torch.from_numpy(np.ascontiguousarray(x)), _torch.from_numpy(y.copy())
        return x, y

    def to_newtons(self, y: np.ndarray) -> np.ndarray:
        """Standardised targets back in N."""
        return np.asarray(y) * self.target_std + self.target_mean


def batches(
    ds: WindowDataset, batch_size: int, shuffle: bool = True, seed: int = 0
) -> Iterator[Tuple[np.ndarray, np.ndarray]]:
    """NumPy mini-batches ``(x[b, window, channels], y[b, targets])`` of ``ds`` for the
    epoch ``ds.epoch``: what ``torch.utils.data.DataLoader`` gives, without torch."""
    order = np.arange(len(ds))
    if shuffle:
        np.random.default_rng((seed, ds.epoch)).shuffle(order)
    for k in range(0, len(order), batch_size):
        items = [ds._item(int(i)) for i in order[k : k + batch_size]]
        yield np.stack([x for x, _ in items]), np.stack([y for _, y in items])
