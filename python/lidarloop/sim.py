"""The simulator: synthetic LiDAR sequences with ground truth and drifting odometry."""

from ._lidarloop import (
    SimulationSummary,
    Simulator,
    write_simulation,
)

__all__ = [
    "SimulationSummary",
    "Simulator",
    "write_simulation",
]
