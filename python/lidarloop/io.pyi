import os
from typing import Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

PathLike = Union[str, os.PathLike]

def read_scan(file: PathLike) -> npt.NDArray[np.float32]:
    """One scan file (or a bag's message, 'BAG:TOPIC:INDEX') as an (N, 3) float32 array: sensor
    frame, metres."""

def is_scan_file(file: PathLike) -> bool: ...
def reads_bags() -> bool:
    """Whether this lidarloop was built with ROS 1 bag support."""

def read_poses(
    file: PathLike, calib: Optional[PathLike] = None, times: Optional[PathLike] = None
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """(times_s (N,), T_world_sensor (N, 4, 4)) of a KITTI or TUM poses file."""

class Dataset:
    def __len__(self) -> int: ...
    def __getitem__(self, index: int) -> npt.NDArray[np.float32]: ...
    @property
    def format(self) -> str: ...
    @property
    def root(self) -> os.PathLike: ...
    @property
    def topic(self) -> str: ...
    @property
    def times(self) -> npt.NDArray[np.float64]: ...
    @property
    def names(self) -> list[str]: ...
    @property
    def has_poses(self) -> bool: ...
    @property
    def poses(self) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
    @property
    def path_m(self) -> Optional[list[float]]:
        """Metres travelled from the first scan; the drive's for some KITTI frames."""

def open_dataset(
    folder: PathLike,
    format: str = "auto",
    poses: Optional[PathLike] = None,
    calib: Optional[PathLike] = None,
    topic: Optional[str] = None,
) -> Dataset: ...

__all__ = ["Dataset", "is_scan_file", "open_dataset", "read_poses", "read_scan", "reads_bags"]
