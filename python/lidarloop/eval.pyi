from typing import Any, Mapping, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.floating]
Distances = FloatArray
"""An (n, n) distance matrix (its upper triangle is used) or the condensed (n(n-1)/2,) upper
triangle, row-major (i < j), as SimilarityMatrix keeps it; W or sigma', +inf: never scored."""

class Confusion:
    """A binary confusion matrix; rates are 0 when their denominator is 0 (scikit-learn)."""

    def __init__(self, tp: int = 0, fp: int = 0, tn: int = 0, fn: int = 0) -> None: ...
    tp: int
    fp: int
    tn: int
    fn: int
    @property
    def precision(self) -> float: ...
    @property
    def recall(self) -> float: ...
    @property
    def false_positive_rate(self) -> float: ...
    @property
    def f1(self) -> float:
        """Röhling eq. (9)."""
    @property
    def mcc(self) -> float:
        """Röhling eq. (10)."""

class GroundTruthConfig:
    """Same place: positions closer than distance_m (metres, strictly), headings closer than
    max_heading_deg (0: any), scans more than min_gap (min_gap_unit 'scans' | 'seconds' |
    'metres' of path) apart and more than min_path_m of path apart (0: any). Keywords override
    the C++ defaults (10 m, 0 deg, 0 scans, 0 m)."""

    def __init__(self, **fields: Any) -> None: ...
    distance_m: float
    max_heading_deg: float
    min_gap: float
    min_gap_unit: str
    min_path_m: float
    def describe(self) -> str: ...

class GroundTruth:
    """The positive pairs of a sequence under one rule."""

    @property
    def config(self) -> GroundTruthConfig: ...
    def __len__(self) -> int: ...
    @property
    def loops(self) -> npt.NDArray[np.int64]:
        """(P, 2): every positive pair i < j, sorted."""
    @property
    def loop_distances_m(self) -> npt.NDArray[np.float64]: ...
    @property
    def nearest(self) -> npt.NDArray[np.int64]:
        """Per scan the nearest comparable scan passing the heading rule; -1: none."""
    @property
    def nearest_distance_m(self) -> npt.NDArray[np.float64]: ...
    def is_loop(self, i: int, j: int) -> bool:
        """IndexError for a scan beyond the ground truth's, TypeError for a negative one (also
        comparable, overlapping)."""
    def comparable(self, i: int, j: int) -> bool: ...
    def overlapping(self, scan: int) -> bool: ...
    @property
    def overlapping_count(self) -> int: ...
    @property
    def comparable_pair_count(self) -> int: ...
    def describe(self) -> str: ...

def build_ground_truth(
    times_s: FloatArray,
    T_world_sensor: FloatArray,
    config: Optional[GroundTruthConfig] = None,
    path_m: Optional[Sequence[float]] = None,
    **rule: Any,
) -> GroundTruth:
    """From poses (times_s (N,), T_world_sensor (N, 4, 4)); the rule as config or keywords;
    path_m per scan (Dataset.path_m), None: the straight steps; ConfigError when a value is not
    finite or smaller than the one before."""

def heading_difference_deg(T_world_a: FloatArray, T_world_b: FloatArray) -> float: ...

class ScoredPairs:
    """Evaluated pairs i < j: descriptor distance (float32) and the ground truth's label."""

    def __init__(self, i: Any, j: Any, distance: Any, loop: Any) -> None: ...
    def __len__(self) -> int: ...
    @property
    def i(self) -> npt.NDArray[np.int64]: ...
    @property
    def j(self) -> npt.NDArray[np.int64]: ...
    @property
    def distance(self) -> npt.NDArray[np.float32]: ...
    @property
    def loop(self) -> npt.NDArray[np.bool_]: ...

def collect_pairs(distances: Distances, truth: GroundTruth) -> ScoredPairs: ...

class BestThreshold:
    threshold: float
    score: float
    confusion: Confusion

class PairwiseEvaluation:
    """The threshold sweep over all pairs (Röhling IV-B/C, fig. 4)."""

    pairs: int
    positives: int
    negatives: int
    distinct_thresholds: int
    @property
    def curve(self) -> dict[str, npt.NDArray[Any]]:
        """threshold (ascending, from -inf), tpr, fpr, precision, tp, fp, tn, fn."""
    roc_auc: Optional[float]
    best_mcc: BestThreshold
    best_f1: BestThreshold

def evaluate_pairs(pairs: ScoredPairs, max_curve_points: int = 1000) -> PairwiseEvaluation: ...
def confusion_at(pairs: ScoredPairs, threshold: float) -> Confusion: ...
def confusions_at(pairs: ScoredPairs, thresholds: Sequence[float]) -> list[Confusion]: ...

class ThresholdTransfer:
    criterion: str
    threshold: float
    train_score: float
    train: Confusion
    test: Confusion
    test_f1: float
    test_mcc: float

def learn_and_test(
    train: ScoredPairs, test: ScoredPairs, criterion: str = "mcc"
) -> ThresholdTransfer: ...
def learn_on_first_part(
    pairs: ScoredPairs, scan_count: int, train_fraction: float = 0.5, criterion: str = "mcc"
) -> ThresholdTransfer: ...

class BestMatches:
    """Per scan its most similar scan outside the gap (Magnusson S̄)."""

    def __len__(self) -> int: ...
    @property
    def match(self) -> npt.NDArray[np.int64]:
        """-1 when none."""
    @property
    def distance(self) -> npt.NDArray[np.float64]: ...
    @property
    def second_distance(self) -> npt.NDArray[np.float64]: ...

def best_matches(distances: Distances, truth: GroundTruth) -> BestMatches: ...
def label_scans(matches: BestMatches, truth: GroundTruth, t_d: float) -> list[str]:
    """'true_positive', 'mismatch', 'false_positive', 'true_negative', 'false_negative'."""

class TaxonomyCounts:
    true_positive: int
    mismatch: int
    false_positive: int
    true_negative: int
    false_negative: int
    @property
    def overlapping(self) -> int: ...
    @property
    def non_overlapping(self) -> int: ...
    @property
    def recall(self) -> float: ...
    @property
    def false_positive_rate(self) -> float: ...

class ZeroErrorPoint:
    t_d: float
    last_true_positive_distance: float
    counts: TaxonomyCounts
    recall: float

class PerScanEvaluation:
    overlapping: int
    non_overlapping: int
    @property
    def curve(self) -> dict[str, npt.NDArray[Any]]:
        """t_d and the count of each label (Magnusson fig. 1)."""
    zero_error: ZeroErrorPoint

def evaluate_per_scan(
    matches: BestMatches, truth: GroundTruth, mismatches_are_errors: bool = True
) -> PerScanEvaluation: ...

class EmConfig:
    def __init__(self, **fields: Any) -> None: ...
    components: int
    restarts: int
    max_iterations: int
    tolerance: float
    min_stddev_fraction: float
    seed: int

class DifferenceThreshold:
    """Magnusson's t_d: where the first two fitted Gaussians cross."""

    t_d: Optional[float]
    @property
    def fitted(self) -> bool: ...
    values_used: int
    values_skipped: int
    @property
    def weights(self) -> npt.NDArray[np.float64]: ...
    @property
    def means(self) -> npt.NDArray[np.float64]: ...
    @property
    def stddevs(self) -> npt.NDArray[np.float64]: ...
    @property
    def log_likelihood(self) -> float: ...

def estimate_difference_threshold(
    smallest_differences: Union[FloatArray, Sequence[float]], config: Optional[EmConfig] = None
) -> DifferenceThreshold: ...

class AcceptedLoop:
    query: int
    match: int
    rank: int
    score: float
    correct: bool
    wrong_pose: bool

class LoopRetrievalEvaluation:
    """Rates are NaN when their denominator is 0."""

    scans: int
    queries: int
    revisiting: int
    k: int
    hits_at_1: int
    hits_at_k: int
    recall_at_1: float
    recall_at_k: float
    true_loops: int
    false_loops: int
    precision: float
    recall: float
    loops_with_pose: int
    wrong_pose_loops: int
    @property
    def recall_at_full_precision(self) -> float: ...
    loops: list[AcceptedLoop]

def evaluate_loop_retrieval(
    ranked: Sequence[tuple[int, Sequence[Mapping[str, Any]]]],
    truth: GroundTruth,
    times_s: FloatArray,
    T_world_sensor: FloatArray,
    recall_k: int = 0,
    wrong_pose_m: Optional[float] = None,
    wrong_pose_deg: Optional[float] = None,
    detector_path_m: Optional[Sequence[float]] = None,
) -> LoopRetrievalEvaluation:
    """ranked: (query, [dict(match, distance, accepted, score=-distance, T_match_query=None)]).

    detector_path_m: the path (m per scan) the detector measured a gap in metres on (its
    odometry's); None: the truth's."""

def absolute_trajectory_rmse(estimate: FloatArray, truth: FloatArray) -> float:
    """ATE, metres: (N, 4, 4) positions rigidly aligned (no scale) onto the truth's."""

def align_rigid(estimate: FloatArray, truth: FloatArray) -> npt.NDArray[np.float64]:
    """T_truth_estimate (4, 4) from (N, 3) positions (Horn / Umeyama without scale)."""

class TrajectoryRpe:
    translation_percent: float
    rotation_deg_per_100m: float
    segments: int

def trajectory_rpe(
    estimate: FloatArray,
    truth: FloatArray,
    lengths_m: Optional[Sequence[float]] = None,
    step: Optional[int] = None,
) -> TrajectoryRpe:
    """KITTI RPE; defaults: lengths 100..800 m, every 10th pose."""

__all__ = [
    "AcceptedLoop",
    "BestMatches",
    "BestThreshold",
    "Confusion",
    "DifferenceThreshold",
    "EmConfig",
    "GroundTruth",
    "GroundTruthConfig",
    "LoopRetrievalEvaluation",
    "PairwiseEvaluation",
    "PerScanEvaluation",
    "ScoredPairs",
    "TaxonomyCounts",
    "ThresholdTransfer",
    "TrajectoryRpe",
    "ZeroErrorPoint",
    "absolute_trajectory_rmse",
    "align_rigid",
    "best_matches",
    "build_ground_truth",
    "collect_pairs",
    "confusion_at",
    "confusions_at",
    "estimate_difference_threshold",
    "evaluate_loop_retrieval",
    "evaluate_pairs",
    "evaluate_per_scan",
    "heading_difference_deg",
    "label_scans",
    "learn_and_test",
    "learn_on_first_part",
    "trajectory_rpe",
]
