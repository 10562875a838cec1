"""ROS 1 bags from Python: open_dataset(bag, topic=...), its scans, stamps and references, against
the points written into the bag (tests/tools/write_bag.py, Debian's python3-rosbag)."""

import subprocess
import sys

import numpy as np
import pytest

import lidarloop

from conftest import REPOSITORY

WRITE_BAG = REPOSITORY / "tests" / "tools" / "write_bag.py"


@pytest.fixture(scope="module")
def tiny_bag(tmp_path_factory):
    """Two scans of 3 points on /points (float32, then float64), at 100 s and 101 s, and
    /odom."""
    if not lidarloop.reads_bags():
        pytest.skip("lidarloop was built without ROS bag support")
    pytest.importorskip("rosbag")
    bag = tmp_path_factory.mktemp("bags") / "tiny.bag"
    subprocess.run([sys.executable, str(WRITE_BAG), "case", "tiny", str(bag)], check=True)
    return bag


def test_open_dataset_reads_the_clouds_of_a_bag(tiny_bag):
    dataset = lidarloop.open_dataset(tiny_bag, topic="/points")
    assert len(dataset) == 2
    assert dataset.format == "rosbag"
    assert dataset.topic == "/points"
    np.testing.assert_array_equal(dataset.times, [100.0, 101.0])
    expected = np.array([[1.0, 2.0, 0.0], [2.0, 2.0, 0.5], [3.0, 2.0, 1.0]], dtype=np.float32)
    for i in range(2):
        np.testing.assert_array_equal(dataset[i], expected)
    assert dataset.names[1] == f"{tiny_bag}:/points:1"
    np.testing.assert_array_equal(lidarloop.read_scan(dataset.names[1]), expected)
    assert not dataset.has_poses


def test_open_dataset_picks_the_only_cloud_topic(tiny_bag):
    assert lidarloop.open_dataset(tiny_bag).topic == "/points"


def test_a_topic_of_another_type_raises_read_error_naming_bag_and_topic(tiny_bag):
    with pytest.raises(lidarloop.ReadError) as error:
        lidarloop.open_dataset(tiny_bag, topic="/odom")
    assert error.value.file == str(tiny_bag)
    assert "topic '/odom' holds 'nav_msgs/Odometry'" in str(error.value)


def test_a_truncated_bag_raises_read_error(tiny_bag, tmp_path):
    cut = tmp_path / "cut.bag"
    cut.write_bytes(tiny_bag.read_bytes()[:5000])
    with pytest.raises(lidarloop.ReadError) as error:
        lidarloop.open_dataset(cut)
    assert error.value.file == str(cut)
