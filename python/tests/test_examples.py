"""examples/python: the scripts run on a small simulated sequence and write what they say."""

import os
import subprocess
import sys
from pathlib import Path

import matplotlib.image
import pytest

import lidarloop

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "python"


@pytest.fixture(scope="module")
def sequence(tmp_path_factory):
    folder = tmp_path_factory.mktemp("data") / "street"
    lidarloop.write_simulation(lidarloop.Simulator(scene="urban", route="uturn", sensor="vlp16",
                                                   scans=80, horizontal_steps=512), folder)
    return folder


def test_detect_and_evaluate_writes_results_and_plots(sequence, tmp_path):
    out = tmp_path / "out"
    printed = subprocess.run(
        [sys.executable, str(EXAMPLES / "detect_and_evaluate.py"), str(sequence), "--out",
         str(out), "--method", "range", "--no-verify"],
        check=True, capture_output=True, text=True, env=dict(os.environ)).stdout
    assert "80 scans" in printed and "best MCC" in printed
    assert (out / "detection" / "loops.csv").is_file()
    assert (out / "evaluation" / "metrics.json").is_file()
    for name in ("similarity.png", "trajectory.png"):
        image = matplotlib.image.imread(out / name)
        assert image.shape[0] > 300 and image.shape[1] > 300, name
        assert image[..., :3].std() > 0.05, f"{name} is blank"
