import os
from typing import Any, Callable, Mapping, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

from .eval import (
    DifferenceThreshold,
    GroundTruth,
    LoopRetrievalEvaluation,
    PairwiseEvaluation,
    PerScanEvaluation,
    TaxonomyCounts,
    ThresholdTransfer,
    Confusion,
)
from .io import Dataset
from .posegraph import LoopConstraint, OptimisationResult

PathLike = Union[str, os.PathLike]
Config = Union[None, Mapping[str, Any], PathLike]
"""None (the defaults), a dict nested like the YAML file, or a YAML file's path."""
# `dataset`: a folder (opened with format, poses and calib, as the CLI's DATASET) or a Dataset
# from open_dataset (then without those).
Progress = Callable[[str, int, int], Any]
"""progress(stage, done, total), called from worker threads (with the GIL), one call at a time
with done rising to total in each stage; if it raises, the run's folder is abandoned as failed
and the exception raised when the run returns."""

class DetectResult:
    """What `lidarloop detect` found and wrote."""

    @property
    def out(self) -> os.PathLike: ...
    @property
    def method(self) -> str: ...
    @property
    def threshold(self) -> float: ...
    @property
    def accepted(self) -> int:
        """Scans whose best match was accepted."""
    @property
    def skipped(self) -> list[str]: ...
    @property
    def total_s(self) -> float: ...
    @property
    def loops(self) -> dict[str, Any]:
        """loops.csv's rows as columns: query, match, distance, second_ratio (NaN: none),
        accepted (bool), rank (1-based verified candidate, 0: not verified), T_match_query
        ((R, 4, 4), NaN when not verified), verification (list of Verification or None),
        path_m (the path between query and match, metres; NaN when no poses or odometry)."""
    @property
    def accepted_loops(self) -> list[LoopConstraint]:
        """The accepted, verified loops, ready for build_pose_graph."""
    @property
    def candidates(self) -> dict[str, npt.NDArray[Any]]:
        """candidates.csv's query, rank (1-based), match, distance."""

def detect(
    dataset: Union[PathLike, Dataset],
    *,
    out: PathLike,
    method: Optional[str] = None,
    config: Config = None,
    overwrite: bool = False,
    progress: Optional[Progress] = None,
    format: str = "auto",
    poses: Optional[PathLike] = None,
    calib: Optional[PathLike] = None,
    odometry: Optional[PathLike] = None,
    odometry_calib: Optional[PathLike] = None,
    # The run options of detect (lidarloop.run_options("detect"); app/run_options.hpp).
    threshold: Optional[float] = None,
    min_gap: Optional[float] = None,
    min_gap_unit: Optional[str] = None,
    min_path_m: Optional[float] = None,
    top_k: Optional[int] = None,
    verify: Optional[bool] = None,
    stop_at_first_loop: Optional[bool] = None,
    skip_bad: Optional[bool] = None,
) -> DetectResult:
    """`lidarloop detect DATASET --out OUT` (None keeps the config's value; verification is on
    by default). `out` is a results folder with run.json (refused inside the dataset, or when it
    holds other files unless overwrite=True; a failed run leaves only run.json).
    min_gap_unit: 'scans', 'seconds' or 'metres' of path, measured on `odometry` (KITTI or TUM,
    one pose per scan) when given, else on the dataset's poses. odometry_calib: a KITTI
    calib.txt whose Tr converts `odometry`'s KITTI poses from KITTI's camera frame (as calib does
    for poses); ConfigError without odometry or with a TUM file."""

class MethodEvaluation:
    """Everything `lidarloop evaluate` computed for one method."""

    @property
    def name(self) -> str: ...
    @property
    def default_threshold(self) -> Optional[float]: ...
    @property
    def similarity(self) -> Optional[npt.NDArray[np.float32]]:
        """(n, n) descriptor distances (W or sigma'), diagonal 0; None beyond
        output.similarity_matrix_mib."""
    @property
    def pairwise(self) -> PairwiseEvaluation: ...
    @property
    def learnt(self) -> Optional[ThresholdTransfer]: ...
    @property
    def learnt_on(self) -> str: ...
    @property
    def at_default(self) -> Optional[Confusion]: ...
    @property
    def fixed_thresholds(self) -> list[float]: ...
    @property
    def at_fixed(self) -> list[Confusion]: ...
    @property
    def per_scan(self) -> PerScanEvaluation: ...
    @property
    def per_scan_at_default(self) -> Optional[TaxonomyCounts]: ...
    @property
    def em(self) -> DifferenceThreshold: ...
    @property
    def retrieval(self) -> Optional[LoopRetrievalEvaluation]: ...
    @property
    def retrieval_verified(self) -> Optional[LoopRetrievalEvaluation]: ...
    @property
    def describe_ms_per_scan_median(self) -> float: ...
    @property
    def ns_per_comparison(self) -> float: ...
    @property
    def metrics(self) -> dict[str, Any]:
        """This method's entry of metrics.json."""

class EvaluateResult:
    @property
    def out(self) -> os.PathLike: ...
    @property
    def metrics_path(self) -> os.PathLike: ...
    @property
    def truth(self) -> GroundTruth: ...
    @property
    def methods(self) -> dict[str, MethodEvaluation]: ...
    @property
    def notes(self) -> list[str]: ...
    @property
    def skipped(self) -> list[str]:
        """'scan 17: <reason>' per scan that could not be read (skip_bad=True)."""
    @property
    def metrics(self) -> dict[str, Any]:
        """The whole metrics.json."""

def evaluate(
    dataset: Union[PathLike, Dataset],
    *,
    out: PathLike,
    methods: Optional[Sequence[str]] = None,
    config: Config = None,
    results: Sequence[PathLike] = ...,
    overwrite: bool = False,
    progress: Optional[Progress] = None,
    format: str = "auto",
    poses: Optional[PathLike] = None,
    calib: Optional[PathLike] = None,
    train_on: Union[None, PathLike, Dataset] = None,
    odometry: Optional[PathLike] = None,
    odometry_calib: Optional[PathLike] = None,
    # The run options of evaluate (lidarloop.run_options("evaluate")).
    threshold: Optional[float] = None,
    min_gap: Optional[float] = None,
    min_gap_unit: Optional[str] = None,
    min_path_m: Optional[float] = None,
    top_k: Optional[int] = None,
    verify: Optional[bool] = None,
    stop_at_first_loop: Optional[bool] = None,
    skip_bad: Optional[bool] = None,
    distance_m: Optional[float] = None,
    max_heading_deg: Optional[float] = None,
    train_fraction: Optional[float] = None,
    criterion: Optional[str] = None,
    fixed_thresholds: Optional[Sequence[float]] = None,
) -> EvaluateResult:
    """`lidarloop evaluate DATASET --out OUT`: every method (default all) on one ground truth
    (distance_m default 10 m, max_heading_deg 0: any, the config's min gap and min_path_m: pairs
    must be more than that much path apart too, 0: no path rule); train_on: learn
    each method's threshold on that dataset (with poses) instead of the first part; odometry
    (KITTI or TUM, never the ground truth): verification with submaps and the odometry gate,
    as detect's (odometry_calib as detect's); without it the scans' registrations to their
    neighbours place the submaps, as detect's (a sequence of dense scans: none either way)."""

class OptimiseResult:
    @property
    def out(self) -> os.PathLike: ...
    @property
    def metrics_path(self) -> os.PathLike: ...
    @property
    def loops(self) -> list[LoopConstraint]: ...
    @property
    def result(self) -> OptimisationResult: ...
    @property
    def poses(self) -> npt.NDArray[np.float64]:
        """(N, 4, 4) optimised T_world_sensor."""
    @property
    def loop_is_true(self) -> list[bool]: ...
    @property
    def odometry_metrics(self) -> Optional[dict[str, float]]:
        """ate_rmse_m, rpe_translation_percent, rpe_rotation_deg_per_100m, rpe_segments."""
    @property
    def optimised_metrics(self) -> Optional[dict[str, float]]: ...
    @property
    def maps(self) -> dict[str, float]:
        """map_odometry.ply, map_optimised.ply: voxel_m, points_odometry, points_optimised, seconds."""
    @property
    def notes(self) -> list[str]: ...
    @property
    def total_s(self) -> float: ...

def optimise(
    dataset: Union[PathLike, Dataset],
    *,
    odometry: PathLike,
    out: PathLike,
    loops: Optional[PathLike] = None,
    pose_format: str = "kitti",
    method: Optional[str] = None,
    config: Config = None,
    overwrite: bool = False,
    progress: Optional[Progress] = None,
    format: str = "auto",
    poses: Optional[PathLike] = None,
    calib: Optional[PathLike] = None,
    odometry_calib: Optional[PathLike] = None,
    # The run options of optimise (lidarloop.run_options("optimise")).
    threshold: Optional[float] = None,
    min_gap: Optional[float] = None,
    min_gap_unit: Optional[str] = None,
    min_path_m: Optional[float] = None,
    top_k: Optional[int] = None,
    stop_at_first_loop: Optional[bool] = None,
    skip_bad: Optional[bool] = None,
    max_odometry_step_m: Optional[float] = None,
) -> OptimiseResult:
    """`lidarloop optimise DATASET --odometry FILE --out OUT [--loops loops.csv]`
    (odometry_calib as detect's)."""

def build_map(
    dataset: Union[PathLike, Dataset],
    *,
    trajectory: Union[None, PathLike, npt.ArrayLike] = None,
    voxel_m: Optional[float] = None,
    max_points: Optional[int] = None,
    config: Config = None,
    scans: Sequence[int] = (),
    skip_bad: bool = False,
    progress: Optional[Progress] = None,
    format: str = "auto",
    poses: Optional[PathLike] = None,
    calib: Optional[PathLike] = None,
) -> dict[str, Any]:
    """Every scan (or `scans`, in that order) placed with `trajectory` and averaged into voxels.

    trajectory: None (the dataset's poses), a KITTI or TUM file (T_world_sensor, read as optimise
    reads odometry), or an (N, 4, 4) array of T_world_sensor (times: the scan index). voxel_m and
    max_points override the config's `map.voxel_m` (default 0.2) and `map.max_points` (2000000).
    Returns points (M, 3) float64, times_s (M,), colors (M, 3) uint8 (viridis of the scan time),
    voxel_m (coarser than asked when max_points capped it), scans, input_points, skipped.
    """

def write_map(
    dataset: Union[PathLike, Dataset],
    *,
    out: PathLike,
    trajectory: Optional[PathLike] = None,
    voxel_m: Optional[float] = None,
    max_points: Optional[int] = None,
    config: Config = None,
    overwrite: bool = False,
    progress: Optional[Progress] = None,
    format: str = "auto",
    poses: Optional[PathLike] = None,
    calib: Optional[PathLike] = None,
    trajectory_calib: Optional[PathLike] = None,
) -> dict[str, Any]:
    """`lidarloop map DATASET --poses TRAJECTORY --calib TRAJECTORY_CALIB --out OUT`: a binary
    PLY coloured by scan time.

    `trajectory_calib` (a KITTI calib.txt) converts the trajectory's KITTI poses from KITTI's
    camera frame; `calib` is the dataset's, as for every dataset. A trajectory that turns about
    its y axis (the camera frame) gets a note. Returns out, points, voxel_m, scans,
    input_points, notes, total_s.
    """

def keep_freed_memory_for_reuse() -> bool:
    """What the lidarloop tool does first: glibc keeps up to 64 MiB of freed memory for the next
    scan (a dense scan's pages are not faulted in again). For the whole process; True when the
    allocator took the settings."""

def run_options(command: str) -> list[dict[str, str]]:
    """The run options of detect, evaluate, optimise or bench as declared once: 'keyword',
    'flag', 'value_name', 'type', 'help', 'sets', 'default'."""

__all__ = [
    "DetectResult",
    "EvaluateResult",
    "MethodEvaluation",
    "OptimiseResult",
    "build_map",
    "detect",
    "evaluate",
    "keep_freed_memory_for_reuse",
    "optimise",
    "write_map",
    "run_options",
]
