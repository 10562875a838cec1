import os
from typing import Any, Mapping, Optional, Union

import numpy as np
import numpy.typing as npt

PathLike = Union[str, os.PathLike]
Config = Union[None, Mapping[str, Any], PathLike]
"""None (the defaults), a dict nested like the YAML file, or a YAML file's path."""

class Verification:
    """The verdict on one candidate pair (the fields of `lidarloop verify`'s JSON)."""

    @property
    def accepted(self) -> bool: ...
    @property
    def reason(self) -> str:
        """'none' when accepted, else 'too_few_points', 'no_alignment', 'not_converged',
        'low_overlap', 'high_rmse', 'degenerate', 'ambiguous', 'too_far',
        'pruned', 'odometry_mismatch', 'unlike_fits' or 'unlike_revisit' (detect with odometry),
        'unlike_neighbours' or 'unlike_motion' (without odometry) or 'not_needed' (not registered: a candidate
        ranked higher is the loop, detection.stop_at_first_loop)."""
    @property
    def T_match_query(self) -> npt.NDArray[np.float64]:
        """(4, 4): maps query-frame points into the match scan's frame, metres."""
    @property
    def overlap(self) -> float:
        """The smaller of overlap_query and overlap_match, [0, 1]."""
    @property
    def overlap_query(self) -> float: ...
    @property
    def overlap_match(self) -> float: ...
    @property
    def distinctive_overlap(self) -> float: ...
    @property
    def distinctive_overlap_query(self) -> float: ...
    @property
    def distinctive_overlap_match(self) -> float: ...
    @property
    def overlapping_points_query(self) -> int: ...
    @property
    def overlapping_points_match(self) -> int: ...
    @property
    def rmse_m(self) -> float:
        """RMS plane distance of the overlapping points, both ways, metres."""
    @property
    def shifted_overlap(self) -> Optional[float]: ...
    @property
    def coarse_score(self) -> float: ...
    @property
    def icp_iterations(self) -> int: ...
    @property
    def registered_hypotheses(self) -> int: ...
    @property
    def score(self) -> float: ...
    def to_dict(self) -> dict[str, Any]:
        """The verdict's keys of `lidarloop verify`'s JSON."""

class PairVerification:
    """What `lidarloop verify` computes for one pair: the verdict, point counts and times."""

    @property
    def verdict(self) -> Verification: ...
    @property
    def query_points(self) -> int: ...
    @property
    def match_points(self) -> int: ...
    @property
    def prepare_ms(self) -> float:
        """Milliseconds to prepare both scans."""
    @property
    def verify_ms(self) -> float:
        """Milliseconds of coarse search, ICP and acceptance."""
    def to_dict(self) -> dict[str, Any]:
        """`lidarloop verify`'s JSON without the file names."""

class PreparedScan:
    """A scan reduced for registration (sensor frame, metres)."""

    @property
    def input_points(self) -> int: ...
    @property
    def usable_points(self) -> int: ...
    @property
    def structure_points(self) -> npt.NDArray[np.float32]:
        """(N, 3) voxel centroids whose normals are far from vertical."""
    @property
    def ground_points(self) -> npt.NDArray[np.float32]: ...
    @property
    def structure_roughness_m(self) -> float: ...
    @property
    def memory_bytes(self) -> int: ...

def prepare_scan(
    points: npt.NDArray[np.floating], config: Config = None, skip_non_finite: bool = False
) -> PreparedScan:
    """Reduces an (N, 3)/(N, 4) scan for registration (config section `detection.verification`)."""

def verify(query: PreparedScan, match: PreparedScan, config: Config = None) -> Verification:
    """Registers `query` to `match` without a prior pose and decides whether they are one place."""

def verify_pair(
    query: npt.NDArray[np.floating],
    match: npt.NDArray[np.floating],
    config: Config = None,
    skip_non_finite: bool = False,
) -> PairVerification:
    """`lidarloop verify` on two point arrays (each in its sensor frame, metres)."""

def verify_scan_files(
    query_file: PathLike, match_file: PathLike, config: Config = None
) -> PairVerification:
    """`lidarloop verify QUERY MATCH` on two scan files."""

__all__ = [
    "PairVerification",
    "PreparedScan",
    "Verification",
    "prepare_scan",
    "verify",
    "verify_pair",
    "verify_scan_files",
]
