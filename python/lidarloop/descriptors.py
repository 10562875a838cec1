"""Describing scans and comparing descriptors."""

from ._lidarloop import (
    Descriptor,
    default_threshold,
    describe,
    distance,
    dump_config,
    is_match,
    method_names,
    method_parameters,
    scancontext_match,
)

__all__ = [
    "Descriptor",
    "default_threshold",
    "describe",
    "distance",
    "dump_config",
    "is_match",
    "method_names",
    "method_parameters",
    "scancontext_match",
]
