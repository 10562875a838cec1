"""The pose graph: odometry and loop edges, optimised with Ceres; g2o and loops.csv files."""

from ._lidarloop import (
    Edge,
    LoopConstraint,
    LoopResult,
    OptimisationResult,
    PoseGraph,
    build_pose_graph,
    optimise_pose_graph,
    read_loops_csv,
    write_g2o,
)

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
