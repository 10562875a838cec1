"""The run layer: detect, evaluate and optimise a dataset into a results folder, as the CLI does."""

from ._lidarloop import (
    DetectResult,
    EvaluateResult,
    MethodEvaluation,
    OptimiseResult,
    detect,
    evaluate,
    optimise,
    run_options,
)

__all__ = [
    "DetectResult",
    "EvaluateResult",
    "MethodEvaluation",
    "OptimiseResult",
    "detect",
    "evaluate",
    "optimise",
    "run_options",
]
