"""The simulator: determinism by seed, arrays equal to the files, parity with `lidarloop
simulate`."""

import subprocess

import numpy as np
import pytest

import lidarloop

SMALL = dict(scene="urban", route="grid", sensor="vlp16", scans=12, seed=3, horizontal_steps=256)


def test_same_seed_same_sequence_other_seed_other_sequence():
    a, b = lidarloop.Simulator(**SMALL), lidarloop.Simulator(**SMALL)
    other = lidarloop.Simulator(**{**SMALL, "seed": 4})
    assert len(a) == 12 and (a.scene, a.route, a.sensor, a.seed) == ("urban", "grid", "vlp16", 3)
    scan = a.scan(5)
    assert scan.dtype == np.float32 and scan.shape[1] == 3 and len(scan) > 1000
    np.testing.assert_array_equal(scan, b.scan(5))
    other_scan = other.scan(5)
    assert len(other_scan) != len(scan) or not np.array_equal(scan, other_scan)
    np.testing.assert_array_equal(a.ground_truth_poses()[1], b.ground_truth_poses()[1])
    assert not np.allclose(a.ground_truth_poses()[1], other.ground_truth_poses()[1])


def test_poses_frames_and_odometry():
    simulator = lidarloop.Simulator(**SMALL)
    times, truth = simulator.ground_truth_poses()
    odometry_times, odometry = simulator.odometry_poses()
    np.testing.assert_allclose(times, np.arange(12) * simulator.scan_period_s)
    np.testing.assert_array_equal(odometry_times, times)
    np.testing.assert_allclose(odometry[0], truth[0], atol=1e-12)  # equal at scan 0
    assert not np.allclose(odometry[-1], truth[-1])  # then it drifts
    rotations = truth[:, :3, :3]
    np.testing.assert_allclose(rotations @ rotations.transpose(0, 2, 1),
                               np.broadcast_to(np.eye(3), rotations.shape), atol=1e-9)
    no_drift = lidarloop.Simulator(**SMALL, drift=0.0)
    np.testing.assert_allclose(no_drift.odometry_poses()[1], no_drift.ground_truth_poses()[1],
                               atol=1e-9)


def test_write_simulation_matches_the_cli_byte_for_byte(cli, tmp_path):
    subprocess.run([str(cli), "simulate", "--scene", "urban", "--route", "grid", "--sensor",
                    "vlp16", "--scans", "12", "--seed", "3", "--horizontal-steps", "256",
                    "--out", str(tmp_path / "cli"), "--quiet"], check=True, capture_output=True)
    calls = []
    summary = lidarloop.write_simulation(lidarloop.Simulator(**SMALL), tmp_path / "python",
                                         progress=lambda *args: calls.append(args))
    assert summary.min_points <= summary.mean_points <= summary.max_points
    assert calls == [("simulate", done, 12) for done in range(1, 13)]  # in order, one by one
    cli_files = sorted(p.relative_to(tmp_path / "cli") for p in (tmp_path / "cli").rglob("*")
                       if p.is_file())
    python_files = sorted(p.relative_to(tmp_path / "python")
                          for p in (tmp_path / "python").rglob("*") if p.is_file())
    assert cli_files == python_files and len(cli_files) >= 12 + 3
    for name in cli_files:
        if str(name) == "run.json":  # the command line and the times differ
            continue
        assert (tmp_path / "cli" / name).read_bytes() == (tmp_path / "python" / name).read_bytes(), name
    # The arrays are the scans written.
    written = np.fromfile(tmp_path / "python" / "velodyne" / "000007.bin", np.float32)
    np.testing.assert_array_equal(written.reshape(-1, 4)[:, :3],
                                  lidarloop.Simulator(**SMALL).scan(7))


def test_a_raising_progress_callback_raises_after_the_run(tmp_path):
    def fail(stage, done, total):
        raise RuntimeError("stop")

    with pytest.raises(RuntimeError, match="stop"):
        lidarloop.write_simulation(lidarloop.Simulator(**SMALL), tmp_path / "seq", progress=fail)
    # Issue 25 (6): the unfinished sequence is refused by readers, not read with gaps.
    assert not (tmp_path / "seq" / "velodyne").exists()
    with pytest.raises(lidarloop.ReadError, match="not finished"):
        lidarloop.open_dataset(tmp_path / "seq")


def test_bad_options_raise_typed_errors(tmp_path):
    with pytest.raises(lidarloop.ConfigError, match="urbanx"):
        lidarloop.Simulator(scene="urbanx")
    with pytest.raises(lidarloop.ConfigError):
        lidarloop.Simulator(scans=0)
    with pytest.raises(lidarloop.ConfigError, match="drift"):
        lidarloop.Simulator(drift=-1.0)
    with pytest.raises(lidarloop.ConfigError, match="drift factor .* out of its range"):
        lidarloop.Simulator(drift=1e9)
    assert len(lidarloop.Simulator(**SMALL, trajectory=None)) == SMALL["scans"]
    with pytest.raises(TypeError, match="no_such_option"):
        lidarloop.Simulator(no_such_option=1)
    with pytest.raises(IndexError):
        lidarloop.Simulator(**SMALL).scan(12)
    lidarloop.write_simulation(lidarloop.Simulator(**SMALL), tmp_path / "seq")
    with pytest.raises(lidarloop.WriteError):  # holds scans, and no overwrite
        lidarloop.write_simulation(lidarloop.Simulator(**SMALL), tmp_path / "seq")


def test_new_sensors_and_a_front_ends_thinning():
    """Issue 24: hdl32, ouster64-wide and livox-avia by name; keep_every keeps every N-th point."""
    for sensor in ("hdl32", "ouster64-wide", "livox-avia"):
        simulator = lidarloop.Simulator(**{**SMALL, "sensor": sensor})
        assert simulator.sensor == sensor and len(simulator.scan(2)) > 500
    livox = lidarloop.Simulator(**{**SMALL, "sensor": "livox-avia"}).scan(4)
    assert (livox[:, 0] > 0).all()  # forward only
    full = lidarloop.Simulator(**{**SMALL, "sensor": "hdl32"}).scan(5)
    thinned = lidarloop.Simulator(**{**SMALL, "sensor": "hdl32", "keep_every": 3}).scan(5)
    np.testing.assert_array_equal(thinned, full[::3])
    for bad in (0, -1, 1001):
        with pytest.raises(lidarloop.ConfigError, match="front_end.keep_every"):
            lidarloop.Simulator(**SMALL, keep_every=bad)
    for bad in (2**70, 1.5, "3"):  # not a 64-bit integer: named, not pybind11's bare cast error
        with pytest.raises(TypeError, match="keep_every must be a 64-bit integer"):
            lidarloop.Simulator(**SMALL, keep_every=bad)
    with pytest.raises(TypeError, match="horizontal_steps must be a 32-bit integer"):
        lidarloop.Simulator(**{**SMALL, "horizontal_steps": 2**40})


def test_writing_releases_the_gil(tmp_path):
    """Another Python thread runs while the C++ side writes (a held GIL would stall it)."""
    import threading
    import time

    ticks, done = [], threading.Event()

    def heartbeat():
        while not done.is_set():
            ticks.append(time.monotonic())
            time.sleep(0.002)

    simulator = lidarloop.Simulator(**{**SMALL, "scans": 40, "horizontal_steps": 1024})
    thread = threading.Thread(target=heartbeat)
    thread.start()
    start = time.monotonic()
    lidarloop.write_simulation(simulator, tmp_path / "seq", threads=1)
    end = time.monotonic()
    done.set()
    thread.join()
    during = [t for t in ticks if start < t < end]
    assert end - start > 0.1  # long enough to tell
    assert len(during) >= 10, f"{len(during)} heartbeats in {end - start:.2f} s"
