import os
from typing import Any, Mapping, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

PathLike = Union[str, os.PathLike]
Config = Union[None, Mapping[str, Any], PathLike]
"""None (the defaults), a dict nested like the YAML file (section `posegraph`), or a YAML path."""
Transforms = npt.NDArray[np.floating]
"""(N, 4, 4) rigid transforms, metres."""

class LoopConstraint:
    """An accepted loop: scan `query` seen from scan `match`."""

    def __init__(
        self,
        query: int,
        match: int,
        T_match_query: npt.NDArray[np.floating],
        overlap: float = ...,
        rmse_m: float = ...,
    ) -> None:
        """T_match_query (4, 4) maps query points into the match frame; overlap (the smaller
        fraction) and rmse_m (metres) from the verification, NaN when unknown."""
    @property
    def query(self) -> int: ...
    @property
    def match(self) -> int: ...
    @property
    def T_match_query(self) -> npt.NDArray[np.float64]: ...
    @property
    def overlap(self) -> float: ...
    @property
    def rmse_m(self) -> float: ...

class Edge:
    """A relative-pose measurement (g2o EDGE_SE3:QUAT): the pose of `to` in the frame of `from_`."""

    @property
    def kind(self) -> str:
        """'odometry' or 'loop'."""
    @property
    def from_(self) -> int: ...
    @property
    def to(self) -> int: ...
    @property
    def T_from_to(self) -> npt.NDArray[np.float64]: ...
    @property
    def information(self) -> npt.NDArray[np.float64]:
        """(6, 6): translation (m), then the quaternion's x y z."""
    @property
    def loop(self) -> int: ...

class PoseGraph:
    @property
    def poses(self) -> npt.NDArray[np.float64]:
        """(N, 4, 4) T_world_sensor, the initial estimate."""
    @property
    def edges(self) -> list[Edge]: ...

class LoopResult:
    """What the back end did with one loop edge."""

    @property
    def loop(self) -> int: ...
    @property
    def verdict(self) -> str:
        """'used', 'rejected_by_odometry', 'rejected_by_residual' or 'rejected_by_consistency'."""
    @property
    def path_m(self) -> float: ...
    @property
    def odometry_translation_error_m(self) -> float: ...
    @property
    def odometry_rotation_error_deg(self) -> float: ...
    @property
    def gate_translation_m(self) -> float: ...
    @property
    def gate_rotation_deg(self) -> float: ...
    @property
    def initial_whitened_residual(self) -> float: ...
    @property
    def whitened_residual(self) -> float: ...
    @property
    def support(self) -> int: ...

class OptimisationResult:
    @property
    def poses(self) -> npt.NDArray[np.float64]:
        """(N, 4, 4) optimised T_world_sensor."""
    @property
    def loops(self) -> list[LoopResult]: ...
    @property
    def loops_used(self) -> int: ...
    @property
    def rejected_by_odometry(self) -> int: ...
    @property
    def rejected_by_residual(self) -> int: ...
    @property
    def rejected_by_consistency(self) -> int: ...
    @property
    def solves(self) -> int: ...
    @property
    def iterations(self) -> int: ...
    @property
    def converged(self) -> bool: ...
    @property
    def initial_cost(self) -> float: ...
    @property
    def final_cost(self) -> float: ...
    @property
    def seconds(self) -> float: ...
    @property
    def note(self) -> str: ...

def build_pose_graph(
    odometry: Transforms,
    loops: Sequence[LoopConstraint],
    config: Config = None,
    path_m: Optional[Sequence[float]] = None,
) -> PoseGraph:
    """One pose per scan (T_world_sensor), odometry edges i -> i+1, a loop edge per loop;
    path_m per scan, the path the odometry's drift grows with (None: the straight steps;
    ConfigError when a value is not finite or smaller than the one before)."""

def optimise_pose_graph(graph: PoseGraph, config: Config = None) -> OptimisationResult:
    """Optimises with Ceres (pose 0 fixed), keeping wrong loops out; releases the GIL."""

def write_g2o(
    file: PathLike,
    poses: Transforms,
    edges: Sequence[Edge],
    commented_edges: Sequence[Edge] = ...,
) -> None:
    """g2o text: VERTEX_SE3:QUAT per pose, FIX 0, EDGE_SE3:QUAT per edge."""

def read_loops_csv(file: PathLike, scan_count: int) -> list[LoopConstraint]:
    """The accepted loops of a loops.csv written by `lidarloop detect` with verification."""

__all__ = [
    "Edge",
    "LoopConstraint",
    "LoopResult",
    "OptimisationResult",
    "PoseGraph",
    "build_pose_graph",
    "optimise_pose_graph",
    "read_loops_csv",
    "write_g2o",
]
