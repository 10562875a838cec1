"""Reading scans, poses and datasets, against NumPy's own reading of the files."""

import shutil
from pathlib import Path

import numpy as np
import pytest

import lidarloop


def test_read_scan_of_a_kitti_file_is_its_xyz_columns(data_dir):
    file = data_dir / "samples" / "courtyard.bin"
    points = lidarloop.read_scan(file)
    expected = np.fromfile(file, dtype="<f4").reshape(-1, 4)[:, :3]
    assert points.dtype == np.float32
    assert points.shape == expected.shape
    np.testing.assert_array_equal(points, expected)


def test_read_scan_accepts_str_paths_and_every_format(data_dir):
    for name in ("corner_a.pcd", "corner_b.ply"):
        points = lidarloop.read_scan(str(data_dir / "samples" / name))
        assert points.ndim == 2 and points.shape[1] == 3 and len(points) > 0


def test_read_scan_of_a_missing_file_raises_read_error_naming_it(tmp_path):
    missing = tmp_path / "missing.bin"
    with pytest.raises(lidarloop.ReadError) as error:
        lidarloop.read_scan(missing)
    assert error.value.file == str(missing)
    assert str(missing) in str(error.value)
    assert isinstance(error.value, OSError)


def test_read_scan_of_a_truncated_kitti_file_raises_read_error(tmp_path):
    truncated = tmp_path / "truncated.bin"
    truncated.write_bytes(b"\0" * 10)
    with pytest.raises(lidarloop.ReadError, match="not a multiple of 16"):
        lidarloop.read_scan(truncated)


def test_read_poses_gives_times_and_4x4_transforms(data_dir):
    times, T = lidarloop.read_poses(data_dir / "trajectories" / "lollipop_tum.txt")
    rows = np.loadtxt(data_dir / "trajectories" / "lollipop_tum.txt")
    assert T.shape == (len(rows), 4, 4)
    np.testing.assert_allclose(times, rows[:, 0])
    np.testing.assert_allclose(T[:, :3, 3], rows[:, 1:4])
    np.testing.assert_allclose(T[:, 3], np.tile([0, 0, 0, 1], (len(rows), 1)))


def test_open_dataset_reads_a_folder_of_scans_in_name_order(data_dir, tmp_path):
    for name in ("courtyard.bin", "corner_a.pcd", "corner_b.ply"):
        shutil.copy(data_dir / "samples" / name, tmp_path / name)
    dataset = lidarloop.open_dataset(tmp_path)
    assert dataset.format == "folder" and not dataset.has_poses
    assert [Path(name).name for name in dataset.names] == ["corner_a.pcd", "corner_b.ply", "courtyard.bin"]
    assert len(dataset) == 3
    np.testing.assert_array_equal(dataset[2], lidarloop.read_scan(tmp_path / "courtyard.bin"))
    np.testing.assert_array_equal(dataset[-1], dataset[2])
    assert len(list(dataset)) == 3  # iteration stops at the IndexError
    with pytest.raises(IndexError):
        dataset[3]
    with pytest.raises(IndexError, match="scan index -4 out of range for 3 scans"):
        dataset[-4]  # named as given, not as -4 + 3
    times, T = dataset.poses
    assert times.shape == (0,) and T.shape == (0, 4, 4)


def test_open_dataset_with_more_poses_than_scans_raises_read_error(data_dir):
    with pytest.raises(lidarloop.ReadError, match="1 scans but 3 poses"):
        lidarloop.open_dataset(data_dir / "kitti")


def test_some_kitti_frames_take_their_poses_and_the_drives_path(tmp_path):
    # A zigzag drive of 8 frames, each step sqrt(2) m; the scans are frames 1, 4 and 5.
    (tmp_path / "velodyne").mkdir()
    cloud = np.zeros((5, 4), dtype="<f4")
    for frame in (1, 4, 5):
        cloud.tofile(tmp_path / "velodyne" / f"{frame:06d}.bin")
    rows = np.zeros((8, 12))
    rows[:, [0, 5, 10]] = 1.0
    rows[:, 3] = np.arange(8)
    rows[:, 7] = np.arange(8) % 2
    np.savetxt(tmp_path / "poses.txt", rows)
    dataset = lidarloop.open_dataset(tmp_path)
    times, T = dataset.poses
    np.testing.assert_allclose(T[:, 0, 3], [1, 4, 5])
    np.testing.assert_allclose(dataset.path_m, [0, 3 * np.sqrt(2), 4 * np.sqrt(2)])
    # Frames 1 and 4: 4.24 m of path apart, sqrt(10) = 3.16 m in a straight line.
    truth = lidarloop.build_ground_truth(times, T, path_m=dataset.path_m, min_path_m=4.0)
    straight = lidarloop.build_ground_truth(times, T, min_path_m=4.0)
    assert truth.comparable(0, 1) and not straight.comparable(0, 1)
    with pytest.raises(ValueError, match="2 values for 3 poses"):
        lidarloop.build_ground_truth(times, T, path_m=[0.0, 1.0])
    with pytest.raises(lidarloop.ConfigError, match="path_m: scan 1's path is not finite"):
        lidarloop.build_ground_truth(times, T, path_m=[0.0, np.nan, 2.0])
    with pytest.raises(lidarloop.ConfigError, match="never shrinks"):
        lidarloop.build_ground_truth(times, T, path_m=[0.0, 3.0, 1.0])
    assert lidarloop.open_dataset(tmp_path / "velodyne").path_m is None


def test_open_dataset_of_an_empty_folder_raises_read_error(tmp_path):
    with pytest.raises(lidarloop.ReadError):
        lidarloop.open_dataset(tmp_path)


def test_open_dataset_rejects_an_unknown_format(data_dir):
    with pytest.raises(lidarloop.ConfigError, match="osnabrueck"):
        lidarloop.open_dataset(data_dir / "kitti", format="ply")
