"""Calls from many Python threads in a fresh interpreter that has not imported NumPy yet: the first
array the binding makes must not import NumPy from a worker thread (that import releases the GIL
inside a C++ one-time initialisation, and the next thread waits for it holding the GIL: a
deadlock). Each case runs in its own interpreter with a timeout, so that a hang fails the test."""

import os
import shutil
import subprocess
import sys

import pytest

TIMEOUT_S = 60

PRELUDE = """
import concurrent.futures
import sys
assert "numpy" not in sys.modules, "the case needs an interpreter without NumPy"
import lidarloop
files = sys.argv[1:]
"""

WORKERS = {
    "read_scan": "lambda f: lidarloop.read_scan(f).shape",
    "describe": "lambda f: float(lidarloop.describe(f, 'range').bins.sum())",
    "verify": "lambda f: lidarloop.verify(*[lidarloop.prepare_scan(lidarloop.read_scan(f))] * 2)"
              ".T_match_query.shape",
}


def run_fresh(script, *args):
    """Runs `script` in a new interpreter; fails the test when it hangs or exits non-zero."""
    try:
        done = subprocess.run([sys.executable, "-c", PRELUDE + script, *map(str, args)],
                              capture_output=True, text=True, timeout=TIMEOUT_S)
    except subprocess.TimeoutExpired:
        pytest.fail(f"no result within {TIMEOUT_S} s (deadlock?)")
    assert done.returncode == 0, done.stderr
    return done.stdout


@pytest.mark.parametrize("call", sorted(WORKERS))
def test_eight_threads_on_a_fresh_interpreter(call, data_dir):
    scan = data_dir / "samples" / "courtyard.bin"
    script = f"""
with concurrent.futures.ThreadPoolExecutor(8) as pool:
    results = list(pool.map({WORKERS[call]}, files * 2))
print(len(results))
"""
    assert run_fresh(script, *[scan] * 8).strip() == "16"


def test_progress_callback_reads_scans(data_dir, tmp_path):
    dataset = tmp_path / "scans"
    dataset.mkdir()
    for i in range(8):
        shutil.copy(data_dir / "samples" / "courtyard.bin", dataset / f"{i:06d}.bin")
    script = f"""
calls = []
def progress(stage, done, total):
    calls.append(lidarloop.read_scan(files[0]).shape)
lidarloop.detect({str(dataset)!r}, out={str(tmp_path / "out")!r}, verify=False, min_gap=1,
                 progress=progress)
print(len(calls) > 0)
"""
    assert run_fresh(script, dataset / "000000.bin").strip() == "True"
