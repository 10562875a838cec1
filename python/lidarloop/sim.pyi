import os
from typing import Any, Callable, Optional, Union

import numpy as np
import numpy.typing as npt

PathLike = Union[str, os.PathLike]
Progress = Callable[[str, int, int], Any]
"""progress(stage, done, total), called from worker threads (with the GIL), one call at a time
with done rising to total."""

class Simulator:
    """A synthetic LiDAR sequence computed on demand (as `lidarloop simulate`). World frame z
    up; scans in the sensor frame (x forward, y left, z up), metres; scan i at i * scan_period_s.
    Same arguments, same sequence."""

    def __init__(
        self,
        scene: Optional[str] = None,
        route: Optional[str] = None,
        sensor: Optional[str] = None,
        scans: Optional[int] = None,
        seed: Optional[int] = None,
        **options: Any,
    ) -> None:
        """scene urban | rural | mine | indoor (default urban); route uturn | figure8 | grid
        (default uturn); sensor hdl64 | vlp16 | tilt180 | hdl32 | ouster64-wide | livox-avia
        (default hdl64); scans (100); seed (1). options as `lidarloop simulate`'s flags:
        noise_m, dropout, horizontal_steps, min_range_m, max_range_m, mount_height_m,
        scan_period_s, spacing_min_m, spacing_max_m, uturn_blocks, keep_every (every N-th
        returned point of each scan kept, as a LIO front end), drift (factor on the odometry
        noise), trajectory ((N, 3) or (N, 4, 4))."""
    @staticmethod
    def demo() -> Simulator:
        """The sequence of `lidarloop demo` (320 VLP-16 scans, urban grid)."""
    def __len__(self) -> int: ...
    @property
    def scene(self) -> str: ...
    @property
    def route(self) -> str: ...
    @property
    def sensor(self) -> str: ...
    @property
    def seed(self) -> int: ...
    @property
    def scan_period_s(self) -> float: ...
    @property
    def mount_height_m(self) -> float: ...
    def scan(self, index: int) -> npt.NDArray[np.float32]:
        """(N, 3) points of scan `index`, sensor frame, metres."""
    def ground_truth_poses(self) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """(times_s (N,), T_world_sensor (N, 4, 4))."""
    def odometry_poses(self) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """The drifting odometry, equal to the ground truth at scan 0."""

class SimulationSummary:
    mean_points: int
    min_points: int
    max_points: int
    revisited_scans: int
    seconds: float

def write_simulation(
    simulator: Simulator,
    out: PathLike,
    overwrite: bool = False,
    threads: int = 0,
    progress: Optional[Progress] = None,
) -> SimulationSummary:
    """The sequence in the KITTI layout (velodyne/*.bin, poses.txt, times.txt,
    poses_odometry.txt, simulation.yaml), as `lidarloop simulate --out`."""

__all__ = ["SimulationSummary", "Simulator", "write_simulation"]
