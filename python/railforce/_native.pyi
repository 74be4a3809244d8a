# Type stubs of the extension module railforce._native (src/python/). Call the documented
# wrappers in railforce/__init__.py; these are their positional, all-arguments forms.
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np
import numpy.typing as npt

__version__: str

class Dataset:
    """A data set written by `generate`, loaded into memory."""

    @property
    def path(self) -> str: ...
    @property
    def channels(self) -> List[str]: ...
    @property
    def labels(self) -> List[str]: ...
    @property
    def runs(self) -> List[Tuple[str, int, int]]: ...
    @property
    def manifest(self) -> Dict[str, Any]: ...
    @property
    def snr_db(self) -> Optional[float]: ...
    @property
    def split(self) -> Dict[str, Any]: ...
    def run(self, i: int) -> Dict[str, npt.NDArray[np.float64]]: ...
    def __len__(self) -> int: ...

def builtins() -> List[str]: ...
def simulate(
    track: str, vehicle: str, speed_kmh: float, duration_s: float, seed: Optional[int],
    channels: Optional[List[str]], settle_s: float, dt: Optional[float], integrator: Optional[str],
    keep_going: bool, consist: str = "none", position: Optional[float] = None,
    rail_support: Optional[str] = None,
) -> Dict[str, npt.NDArray[np.float64]]: ...
def generate(
    plan: str, out: str, shard: Optional[str], format: str, jobs: Optional[int],
    snr_db: Optional[float], snr_reference: str, settle_s: float, integrator: Optional[str], dt: Optional[float],
) -> str: ...
def merge(out: str) -> str: ...
def open_dataset(path: str) -> Dataset: ...
def windows(
    dataset: Dataset, split: str, channels: Optional[List[str]], window: int, label: str,
    targets: str, stride: int, noise: Optional[str], source: bool,
) -> Dict[str, Any]: ...
def identify(
    model: str, columns: Sequence[Tuple[str, npt.NDArray[np.float64]]], source: str,
    coverage: float, resample: bool, channel_map: Optional[str],
    static_wheel_load_kn: Optional[float], vehicle: str,
) -> Tuple[Dict[str, npt.NDArray[np.float64]], str]: ...
def assess(
    file: Optional[str], columns: Optional[Sequence[Tuple[str, npt.NDArray[np.float64]]]],
    track: Optional[str], criteria: Optional[str], static_wheel_load_kn: Optional[float],
    vehicle: str, coverage: float,
) -> str: ...
def contact(
    vehicle: str, y_mm: float, yaw_mrad: float, load_kn: Optional[float], speed_kmh: float,
    extra_roll_mrad: float, spin: Optional[float], lateral_velocity: float, yaw_rate: float,
) -> str: ...
