"""Geometric verification of a scan pair: is the query a revisit of the match, and at what pose."""

from ._lidarloop import (
    PairVerification,
    PreparedScan,
    Verification,
    prepare_scan,
    verify,
    verify_pair,
    verify_scan_files,
)

__all__ = [
    "PairVerification",
    "PreparedScan",
    "Verification",
    "prepare_scan",
    "verify",
    "verify_pair",
    "verify_scan_files",
]
