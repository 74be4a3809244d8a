"""railforce from Python: simulate a C80 heavy-haul wagon, generate data sets per working
condition, draw training windows for PyTorch, identify wheel–rail forces from measurements and
assess runs as acceptance engineers do.

Every function runs the Rust library (the extension module ``railforce._native``) with the
interpreter released, so Python threads run simulations in parallel. Errors raise
``ValueError`` (a bad name or value), ``FileNotFoundError`` or ``OSError``, with the command
line's messages. Vehicles, tracks and plans are named as on the command line: a file path, or a
built-in name (``c80``, ``c80_empty``, ``tangent``, ``curve_r400``, ``paper34`` …; see
:func:`builtins`).

Units: SI unless a name says otherwise (``speed_kmh``, ``duration_s``, ``*_N``, ``*_kn``).
Forces are those of the rail on the wheel in the track frame (Y lateral, + left; Q vertical,
+ up); wheels 1L…4R are numbered from the front.
"""

from __future__ import annotations

import json
import os
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _native
from ._native import Dataset

__version__: str = _native.__version__

PathLike = Union[str, "os.PathLike[str]"]

__all__ = [
    "Dataset",
    "assess",
    "builtins",
    "contact",
    "generate",
    "identify",
    "merge",
    "open_dataset",
    "simulate",
    "windows",
]


def builtins() -> List[str]:
    """The names that stand for built-in plans, vehicles and tracks, in that order."""
    return list(_native.builtins())


def _frame(columns: Mapping[str, np.ndarray], as_frame: bool):
    if not as_frame:
        return dict(columns)
    try:
        import pandas as pd
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise ImportError("as_frame=True needs pandas: pip install pandas") from e
    return pd.DataFrame(dict(columns))


def simulate(
    *,
    track: PathLike,
    vehicle: PathLike = "c80",
    speed_kmh: float = 60.0,
    duration_s: float = 60.0,
    seed: Optional[int] = None,
    channels: Optional[Sequence[str]] = None,
    settle_s: float = 3.0,
    dt: Optional[float] = None,
    integrator: Optional[str] = None,
    keep_going: bool = False,
    as_frame: bool = False,
    consist: str = "none",
    position: Optional[float] = None,
    rail_support: Optional[str] = None,
    roughness: Optional[str] = None,
):
    """One run of ``vehicle`` on ``track``, exactly as ``railforce simulate`` makes it.

    Returns a dict of float64 NumPy arrays, one per recorded channel at 200 Hz (``time_s``
    first), or a pandas DataFrame with ``as_frame=True``. ``channels`` keeps only those (and
    ``time_s``); ``seed`` overrides the track file's irregularity seed. A derailment stops
    the run with ``ValueError`` unless ``keep_going``. ``integrator`` (default
    ``"linearly-implicit-hertz"``; ``"linearly-implicit"``, ``"semi-implicit"``, ``"heun"``) and
    ``dt`` (default the integrator's own step: 5/6 ms, 0.5 ms, or 0.2 ms for the last two) as
    the command line takes them. ``consist`` (``"none"``: the wagon alone; ``"daqin_10kt"``,
    ``"daqin_20kt"``, their ``_empty`` forms, or a consist file) and ``position`` (the
    wagon's place as a fraction of the train from the head) as ``--consist`` and
    ``--position`` take them; a run in a train adds the ``coupler_*`` channels.
    ``rail_support`` (``"rigid"``, ``"lumped"``, ``"discrete"``: rails on sleepers, 0.2 ms
    unless ``dt``) as ``--rail-support`` chooses it over the track file's; ``roughness``
    (``"iso3095"``, ``"cnossos_m"``, ``"none"``) as ``--roughness`` puts rail roughness on the
    rails (the step then follows it: 62.5 µs).
    """
    cols = _native.simulate(
        os.fspath(track),
        os.fspath(vehicle),
        float(speed_kmh),
        float(duration_s),
        None if seed is None else int(seed),
        None if channels is None else [str(c) for c in channels],
        float(settle_s),
        None if dt is None else float(dt),
        integrator,
        bool(keep_going),
        str(consist),
        None if position is None else float(position),
        None if rail_support is None else str(rail_support),
        None if roughness is None else str(roughness),
    )
    return _frame(cols, as_frame)


def _shard(shard) -> Optional[str]:
    if shard is None:
        return None
    if isinstance(shard, str):
        return shard
    i, n = shard
    return f"{int(i)}/{int(n)}"


def generate(
    plan: PathLike,
    out: PathLike,
    shard: Union[None, str, Tuple[int, int]] = None,
    *,
    format: str = "npz",
    jobs: Optional[int] = None,
    snr_db: Optional[float] = None,
    snr_reference: str = "std",
    settle_s: float = 3.0,
    integrator: Optional[str] = None,
    dt: Optional[float] = None,
) -> Dict[str, Any]:
    """Generates the data set of ``plan`` into the folder ``out`` (``railforce generate``).

    ``shard`` (``"i/N"`` or ``(i, N)``, 1-based) makes only runs ``k`` with
    ``k % N == i - 1`` and writes ``manifest.shard-i-of-N.json``; :func:`merge` joins the
    shards. Runs already in ``out`` with the same inputs are kept (resume). ``snr_db`` adds
    noisy copies of the 21 input channels. Returns the manifest as a dict.
    """
    m = _native.generate(
        os.fspath(plan),
        os.fspath(out),
        _shard(shard),
        format,
        jobs,
        None if snr_db is None else float(snr_db),
        snr_reference,
        float(settle_s),
        integrator,
        None if dt is None else float(dt),
    )
    return json.loads(m)


def merge(out: PathLike) -> Dict[str, Any]:
    """Joins the shard manifests in ``out`` into ``manifest.json`` (``generate --merge``):
    byte for byte the manifest one process writes. Returns it as a dict."""
    return json.loads(_native.merge(os.fspath(out)))


def open_dataset(path: PathLike) -> Dataset:
    """Reads a data set written by :func:`generate` (its manifest and every run).

    The :class:`Dataset` has ``path``, ``channels``, ``labels`` (FL, FQ), ``runs``
    ((condition, seed, rows) per run), ``manifest`` (dict), ``split`` (the leak-free
    default: seeds per part), ``snr_db``, ``run(i)`` (dict of arrays) and ``len()``.
    """
    return _native.open_dataset(os.fspath(path))


def windows(
    dataset: Union[Dataset, PathLike],
    split: str = "train",
    channels: Optional[Sequence[str]] = None,
    window: int = 20,
    label: str = "centre",
    *,
    targets: str = "both",
    stride: int = 1,
    noise: Optional[str] = None,
) -> Dict[str, Any]:
    """The windows of one part (``train``, ``val``, ``test``) of the leak-free split, ready
    for PyTorch: ``x`` float32 ``[n, window, channels]`` and ``y`` float32 ``[n, targets]``,
    standardised with the training part's statistics (``input_mean``, ``input_std``,
    ``target_mean``, ``target_std``), with each window's ``run`` and ``start``.

    Windows never cross a run boundary. ``channels`` defaults to the paper's 21; ``label`` is
    ``centre`` (the paper's) or ``last`` (causal); ``noise`` is the protocol (``matched`` when
    the data set has noisy copies, else ``clean``).
    """
    return _windows(dataset, split, channels, window, label, targets, stride, noise, False)


def _windows(dataset, split, channels, window, label, targets, stride, noise, source):
    ds = dataset if isinstance(dataset, Dataset) else open_dataset(dataset)
    return _native.windows(
        ds, split, None if channels is None else list(channels), int(window), label, targets,
        int(stride), noise, bool(source),
    )


def _columns(frame) -> List[Tuple[str, np.ndarray]]:
    if hasattr(frame, "columns") and hasattr(frame, "to_numpy"):  # a pandas DataFrame
        items = [(str(c), frame[c].to_numpy()) for c in frame.columns]
    elif isinstance(frame, Mapping):
        items = [(str(k), v) for k, v in frame.items()]
    else:
        raise ValueError("give a pandas DataFrame or a dict of column name → array")
    return [(n, np.ascontiguousarray(v, dtype=np.float64)) for n, v in items]


def identify(
    model_dir: PathLike,
    frame,
    *,
    coverage: float = 0.9,
    resample: bool = False,
    channel_map: Optional[PathLike] = None,
    static_wheel_load_kn: Optional[float] = None,
    vehicle: PathLike = "c80",
    as_frame: Optional[bool] = None,
):
    """Identifies wheel–rail forces from measured columns with a model from ``railforce
    train`` (what ``railforce identify --input FILE`` does for a file).

    ``frame`` is a pandas DataFrame or a dict of arrays with a time column (``time_s``) and the
    model's channels (or a ``channel_map`` TOML for a recorder's own names, units and signs).
    Returns ``(forces, report)``: the columns of identify's CSV at full precision
    (``time_s``, ``<target>_N`` with ``_lo_N``/``_hi_N`` at ``coverage``, the safety indices,
    ``ood_channels``), as a DataFrame when ``frame`` was one (or ``as_frame``); and the
    exceedance reports and out-of-distribution stretches as a dict.
    """
    if as_frame is None:
        as_frame = hasattr(frame, "to_numpy")
    cols, report = _native.identify(
        os.fspath(model_dir), _columns(frame), "<frame>", float(coverage), bool(resample),
        None if channel_map is None else os.fspath(channel_map),
        static_wheel_load_kn, os.fspath(vehicle),
    )
    return _frame(cols, as_frame), json.loads(report)


def assess(
    run,
    *,
    track: Optional[PathLike] = None,
    criteria: Optional[PathLike] = None,
    static_wheel_load_kn: Optional[float] = None,
    vehicle: PathLike = "c80",
    coverage: float = 0.9,
) -> Dict[str, Any]:
    """Assesses a run as ``railforce assess`` does: ``run`` is a run file (simulate, generate
    or identify output), a DataFrame or a dict of arrays. With ``track`` each section is
    judged apart. Returns the assessment: ``rows`` (section, quantity, place, value, limit,
    unit, statistic, pass, criterion), the criteria with their sources, and per row the
    interval and P(exceed) where the run carries identified forces' bounds."""
    if isinstance(run, (str, os.PathLike)):
        file, cols = os.fspath(run), None
    else:
        file, cols = None, _columns(run)
    a = _native.assess(
        file, cols, None if track is None else os.fspath(track),
        None if criteria is None else os.fspath(criteria),
        static_wheel_load_kn, os.fspath(vehicle), float(coverage),
    )
    return json.loads(a)


def contact(
    *,
    vehicle: PathLike = "c80",
    y_mm: float = 0.0,
    yaw_mrad: float = 0.0,
    load_kn: Optional[float] = None,
    speed_kmh: float = 60.0,
    extra_roll_mrad: float = 0.0,
    spin: Optional[float] = None,
    lateral_velocity: float = 0.0,
    yaw_rate: float = 0.0,
) -> Dict[str, Any]:
    """The quasi-static contact of ``vehicle``'s wheelset shifted ``y_mm`` and yawed
    ``yaw_mrad`` with ``load_kn`` per wheel (default: the vehicle's static wheel load), as
    ``railforce contact --vehicle`` computes it: roll, height, and per wheel its Y, Q,
    |Y|/Q and every patch (normal force, ellipse, creepages, creep forces)."""
    return json.loads(
        _native.contact(
            os.fspath(vehicle), float(y_mm), float(yaw_mrad), load_kn, float(speed_kmh),
            float(extra_roll_mrad), spin, float(lateral_velocity), float(yaw_rate),
        )
    )
