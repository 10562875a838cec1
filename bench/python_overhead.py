#!/usr/bin/env python3
"""What calling lidarloop through Python adds (issue 17's targets): describing a 120k-point scan
(< 5 %) and one descriptor distance (< 1 us a call).

The same C++ calls are timed in C++ in the same process on the same data (the extension's
private _cpp_describe_seconds and _cpp_distance_seconds) and through the Python API with timeit,
in alternating rounds so that both see the same load; every figure is the fastest round, the
least disturbed by other work on the machine.

    PYTHONPATH=build/python /usr/bin/python3 bench/python_overhead.py [--cli build/cli/lidarloop]

The scan is `lidarloop simulate --sensor hdl64 --scans 1` (urban, seed 1), its points repeated to
120,000. Results go to stdout as a Markdown table (docs/BENCHMARK.md, "Python bindings").
"""

import argparse
import subprocess
import tempfile
import timeit
from pathlib import Path

import numpy as np

import lidarloop
from lidarloop import _lidarloop

POINTS = 120_000
ROUNDS = 15


def hdl64_scan(cli):
    """A simulated HDL-64E scan, its points repeated to POINTS rows, float32 (N, 3)."""
    with tempfile.TemporaryDirectory() as folder:
        subprocess.run(
            [cli, "simulate", "--sensor", "hdl64", "--scans", "1", "--quiet", "--out", folder],
            check=True, capture_output=True)
        points = lidarloop.read_scan(Path(folder) / "velodyne" / "000000.bin")
    return np.resize(points, (POINTS, 3)).astype(np.float32)  # repeats rows up to POINTS


def fastest_alternating(cpp_round, python_call, repeats):
    """(C++, Python) seconds per call: the fastest of ROUNDS alternating rounds of each."""
    cpp, python = [], []
    for _ in range(ROUNDS):
        cpp.append(cpp_round(repeats))
        python.append(timeit.timeit(python_call, number=repeats) / repeats)
    return min(cpp), min(python)


def describe_row(label, points, method, repeats):
    """Describing `points`: C++ alone, through Python, and the difference."""
    cpp, python = fastest_alternating(
        lambda n: _lidarloop._cpp_describe_seconds(points, method, n, 1),
        lambda: lidarloop.describe(points, method), repeats)
    added = python - cpp
    return (f"| describe, {method}, {label} | {cpp * 1e6:.1f} µs | {python * 1e6:.1f} µs "
            f"| {added * 1e6:+.1f} µs ({100 * added / cpp:+.1f} %) |")


def distance_row(method, a, b, repeats):
    """One distance between two descriptors: C++ alone, through Python, the difference."""
    cpp, python = fastest_alternating(
        lambda n: _lidarloop._cpp_distance_seconds(a, b, n, 1),
        lambda: lidarloop.distance(a, b), repeats)
    return (f"| distance, {method} | {cpp * 1e9:.0f} ns | {python * 1e9:.0f} ns "
            f"| {(python - cpp) * 1e9:+.0f} ns a call |")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cli", default="build/cli/lidarloop", help="the lidarloop executable")
    args = parser.parse_args()
    points = hdl64_scan(args.cli)
    print(f"{len(points)} points; fastest of {ROUNDS} alternating rounds\n")
    print("| call | C++ alone | through Python | added |")
    print("|---|---|---|---|")
    for method, repeats in (("height", 50), ("range", 50), ("ndt", 5)):
        print(describe_row("float32 (N, 3) C-contiguous", points, method, repeats))
    print(describe_row("10 points: the fixed cost of a call", points[:10].copy(), "range", 2000))
    print(describe_row("float64 (N, 3)", points.astype(np.float64), "range", 50))
    print(describe_row("float32 (N, 4) view [:, :3]", np.hstack([points, points[:, :1]])[:, :3], "range", 50))
    shifted = points + np.float32(0.5)
    for method in ("height", "range", "ndt"):
        a, b = lidarloop.describe(points, method), lidarloop.describe(shifted, method)
        print(distance_row(method, a, b, 200_000))


if __name__ == "__main__":
    main()
