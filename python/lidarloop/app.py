"""The run layer: detect, evaluate and optimise a dataset into a results folder, and build its map,
as the CLI does."""

from ._lidarloop import (
    DetectResult,
    EvaluateResult,
    MethodEvaluation,
    OptimiseResult,
    build_map,
    detect,
    evaluate,
    keep_freed_memory_for_reuse,
    optimise,
    write_map,
    run_options,
)

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
