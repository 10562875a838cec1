import os
from typing import Any, Mapping, Optional, Union

import numpy as np
import numpy.typing as npt

PathLike = Union[str, os.PathLike]
Config = Union[None, Mapping[str, Any], PathLike]

class Descriptor:
    """The place descriptor of one scan (fields as `lidarloop describe` prints them)."""

    @property
    def method(self) -> str: ...
    @property
    def bins(self) -> npt.NDArray[Any]:
        """Histograms: bucket masses h_k (sum 1), float64; read-only view, no copy.
        Scan Context: (rings, sectors) float32 max heights, metres; a copy."""
    @property
    def ring_key(self) -> list[float]:
        """Scan Context: per ring the share of occupied sectors."""
    @property
    def min(self) -> float:
        """Histograms: v_min, metres."""
    @property
    def max(self) -> float:
        """Histograms: v_max, metres."""
    @property
    def up(self) -> npt.NDArray[np.float64]:
        """Height histograms: unit up vector, sensor frame, shape (3, 1)."""
    @property
    def points_used(self) -> int: ...
    @property
    def points_skipped(self) -> int: ...
    @property
    def points_out_of_range(self) -> int: ...
    @property
    def descriptors(self) -> list[dict[str, Any]]:
        """NDT: per rotation candidate 'F' (float32 counts), 'cells', 'R_aligned_sensor'."""
    @property
    def sparse_cells(self) -> int: ...
    @property
    def degenerate_cells(self) -> int: ...
    def to_dict(self) -> dict[str, Any]:
        """Exactly the JSON `lidarloop describe` prints."""
    def distance(self, other: Descriptor) -> float: ...

def describe(
    points: Union[npt.NDArray[np.floating], PathLike],
    method: Optional[str] = None,
    *,
    config: Config = None,
    bins: Optional[int] = None,
    min: Optional[float] = None,
    max: Optional[float] = None,
    up: Optional[str] = None,
    sensor_height: Optional[float] = None,
    out_of_range: Optional[str] = None,
    skip_non_finite: bool = False,
    **parameters: Any,
) -> Descriptor:
    """The descriptor of an (N, 3)/(N, 4) scan (sensor frame, metres) or a scan file.

    **parameters: the keys of the method's section (method_parameters(method)), e.g. rings=30
    (scancontext), cell_size_m=1.0 (ndt), height_max_m=5.0 (height)."""

def distance(a: Descriptor, b: Descriptor) -> float:
    """W (histograms), sigma' (NDT) or d (Scan Context) between two descriptors of one method
    and config."""

def scancontext_match(query: Descriptor, candidate: Descriptor) -> dict[str, Any]:
    """Scan Context: {'distance', 'shift', 'yaw_rad' (of T_candidate_query)}."""

def method_parameters(method: str) -> list[dict[str, Any]]:
    """The parameters of a method's section (histogram for height and range) as declared: 'key',
    'type', 'default', 'min', 'max', 'open', 'unit', 'help'."""

def method_names() -> list[str]: ...
def default_threshold(method: str) -> float: ...
def is_match(method: str, distance: float, threshold: float) -> bool: ...
def dump_config(config: Config = None) -> str:
    """The effective configuration as YAML."""

__all__ = [
    "Descriptor",
    "default_threshold",
    "describe",
    "distance",
    "dump_config",
    "is_match",
    "method_names",
    "method_parameters",
    "scancontext_match",
]
