"""Verification of a scan pair: parity with `lidarloop verify`, on the bundled samples and on
real KITTI scans when present, and the errors of bad input."""

import json
import subprocess
from pathlib import Path

import numpy as np
import pytest

import lidarloop

KITTI_SAMPLES = Path(__file__).resolve().parents[2] / ".." / "shared" / "data" / "kitti-samples"


def cli_verify(cli, query, match, config=None):
    command = [str(cli), "verify", str(query), str(match)]
    if config is not None:
        command += ["--config", str(config)]
    return json.loads(subprocess.run(command, check=True, capture_output=True, text=True).stdout)


def assert_same_verdict(python, printed):
    """Every key of the CLI's verdict, the times aside (they differ run to run)."""
    python_json = python.to_dict()
    for key, value in printed.items():
        if key in ("query", "match", "time_ms"):
            continue
        if isinstance(value, float):
            assert python_json[key] == pytest.approx(value, rel=1e-9, abs=1e-12), key
        elif key == "T_match_query":
            np.testing.assert_allclose(python.verdict.T_match_query, value, rtol=0, atol=1e-12)
        else:
            assert python_json[key] == value, key


def read_kitti_bin(path):
    return np.fromfile(path, dtype=np.float32).reshape(-1, 4)


def test_verify_scan_files_matches_the_cli(cli, data_dir):
    query, match = data_dir / "samples" / "corner_a.pcd", data_dir / "samples" / "corner_b.ply"
    python = lidarloop.verify_scan_files(query, match)
    assert_same_verdict(python, cli_verify(cli, query, match))


def test_verify_pair_of_arrays_matches_the_cli_on_a_file(cli, data_dir, tmp_path):
    points = read_kitti_bin(data_dir / "samples" / "courtyard.bin")
    # The match: the same scan turned by 30 degrees and moved; saved for the CLI.
    yaw = np.radians(30.0)
    T_match_query = np.eye(4)
    T_match_query[:2, :2] = [[np.cos(yaw), -np.sin(yaw)], [np.sin(yaw), np.cos(yaw)]]
    T_match_query[:3, 3] = [1.5, -0.5, 0.0]
    moved = points.copy()
    moved[:, :3] = (points[:, :3].astype(np.float64) @ T_match_query[:3, :3].T
                    + T_match_query[:3, 3]).astype(np.float32)
    match_file = tmp_path / "moved.bin"
    moved.tofile(match_file)
    python = lidarloop.verify_pair(points, moved)
    assert python.query_points == len(points) and python.match_points == len(points)
    assert_same_verdict(python, cli_verify(cli, data_dir / "samples" / "courtyard.bin",
                                           match_file))


def test_verify_of_prepared_scans_equals_verify_pair(data_dir):
    points = read_kitti_bin(data_dir / "samples" / "courtyard.bin")
    shifted = points.copy()
    shifted[:, 0] += 0.8
    pair = lidarloop.verify_pair(points, shifted)
    query, match = lidarloop.prepare_scan(points), lidarloop.prepare_scan(shifted)
    verdict = lidarloop.verify(query, match)
    assert verdict.to_dict() == pair.verdict.to_dict()
    assert query.input_points == len(points)
    assert query.structure_points.shape[1] == 3 and query.structure_points.dtype == np.float32


def test_a_config_dict_reaches_the_verification(data_dir):
    points = read_kitti_bin(data_dir / "samples" / "courtyard.bin")
    # No point is within 1 m of the sensor and beyond it: nothing usable is left.
    strict = {"verification": {"reduction": {"max_range_m": 1.0, "min_range_m": 0.5}}}
    verdict = lidarloop.verify_pair(points, points, config=strict).verdict
    assert not verdict.accepted and verdict.reason == "too_few_points"
    with pytest.raises(lidarloop.ReadError, match="no_such_key"):
        lidarloop.verify_pair(points, points, config={"detection": {"no_such_key": 1}})
    # Values out of range are refused by the config reader, naming the key.
    with pytest.raises(lidarloop.ReadError, match="voxel_m"):
        lidarloop.verify_pair(points, points,
                              config={"verification": {"reduction": {"voxel_m": -1.0}}})


def test_bad_input_raises_typed_errors(tmp_path):
    good = np.zeros((10, 3), np.float32)
    good[:, 0] = np.arange(10) + 10.0  # 10-19 m ahead: within the range limits
    with pytest.raises(lidarloop.ShapeError):
        lidarloop.verify_pair(np.zeros((10, 2), np.float32), good)
    with pytest.raises(lidarloop.DtypeError):
        lidarloop.verify_pair(good, np.zeros((10, 3), np.int32))
    nan = good.copy()
    nan[3, 1] = np.nan
    with pytest.raises(lidarloop.NonFiniteError):
        lidarloop.prepare_scan(nan)
    prepared = lidarloop.prepare_scan(nan, skip_non_finite=True)
    assert (prepared.input_points, prepared.usable_points) == (10, 9)
    with pytest.raises(lidarloop.ReadError) as error:
        lidarloop.verify_scan_files(tmp_path / "missing.bin", tmp_path / "missing.bin")
    assert "missing.bin" in str(error.value)


@pytest.mark.skipif(not KITTI_SAMPLES.is_dir(),
                    reason=f"real KITTI samples not found at {KITTI_SAMPLES} (not bundled: "
                           "CC BY-NC-SA; see the lead's shared data)")
@pytest.mark.parametrize("sequence,query,match,accepted", [
    ("08", 1684, 209, True),     # a true loop, driven the other way
    ("00", 198, 94, False),      # 58 m apart: not the same place
])
def test_real_kitti_pairs_match_the_cli(cli, sequence, query, match, accepted):
    folder = KITTI_SAMPLES.resolve() / sequence / "velodyne"
    query_file, match_file = folder / f"{query:06d}.bin", folder / f"{match:06d}.bin"
    python = lidarloop.verify_pair(read_kitti_bin(query_file), read_kitti_bin(match_file))
    assert python.verdict.accepted == accepted
    assert_same_verdict(python, cli_verify(cli, query_file, match_file))
