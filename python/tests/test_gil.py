"""Long calls release the GIL: another Python thread runs while C++ works."""

import sys
import threading

import numpy as np

import lidarloop


def steps_of_another_thread_during(function, *args):
    """How many steps a spinning Python thread makes while function(*args) runs in C++ in this
    thread: 0 when the call holds the GIL throughout. With a switch interval far longer than
    the call, this thread hands the GIL over only when C++ releases it, so whatever the other
    thread counted between the two reads happened during the call."""
    interval = sys.getswitchinterval()
    sys.setswitchinterval(0.5)
    try:
        return count_steps(function, args)
    finally:
        sys.setswitchinterval(interval)


def count_steps(function, args):
    counter = [0]
    state = {"started": False, "stop": False}

    def spin():
        state["started"] = True
        while not state["stop"]:
            counter[0] += 1

    thread = threading.Thread(target=spin)
    thread.start()
    while not state["started"]:
        pass
    before = counter[0]
    function(*args)
    after = counter[0]
    state["stop"] = True
    thread.join()
    return after - before


def planes(points_count):
    rng = np.random.default_rng(1)
    points = rng.uniform(-30, 30, size=(points_count, 3)).astype(np.float32)
    points[::2, 2] = -1.7  # a ground plane and a wall, so that NDT classifies cells
    points[1::4, 0] = 12.0
    return points


def test_describe_releases_the_gil():
    points = planes(200_000)
    assert steps_of_another_thread_during(lidarloop.describe, points, "ndt") > 0


def test_detector_process_releases_the_gil():
    detector = lidarloop.LoopDetector(method="ndt", verify=False)
    points = planes(200_000)
    assert steps_of_another_thread_during(detector.process, points) > 0
