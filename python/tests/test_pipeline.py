"""The descriptor database, its index and the online detector: parity with `lidarloop detect`
on a simulated sequence, brute force for the index, save/load round trips."""

import csv
import subprocess

import numpy as np
import pytest

import lidarloop

MIN_GAP = 10


@pytest.fixture(scope="module")
def sequence(cli, tmp_path_factory):
    """60 small simulated VLP-16 scans (KITTI layout) with revisits, made by the CLI."""
    folder = tmp_path_factory.mktemp("sequence")
    subprocess.run(
        [str(cli), "simulate", "--scans", "60", "--sensor", "vlp16", "--horizontal-steps", "450",
         "--quiet", "--out", str(folder)],
        check=True, capture_output=True)
    return lidarloop.open_dataset(folder)


@pytest.fixture(scope="module")
def detected(cli, sequence, tmp_path_factory):
    """`lidarloop detect --no-verify` on the sequence: its results folder."""
    out = tmp_path_factory.mktemp("detect")
    subprocess.run(
        [str(cli), "detect", str(sequence.root), "--method", "range", "--no-verify",
         "--min-gap", str(MIN_GAP), "--out", str(out)],
        check=True, capture_output=True)
    return out


@pytest.fixture(scope="module")
def descriptors(sequence):
    return [lidarloop.describe(sequence[i], "range") for i in range(len(sequence))]


@pytest.fixture(scope="module")
def database(sequence, descriptors):
    times, _ = sequence.poses
    database = lidarloop.DescriptorDatabase(method="range")
    for descriptor, time_s in zip(descriptors, times):
        database.add(descriptor, time_s)
    return database


def test_database_distances_are_the_pairwise_distances(database, descriptors):
    assert len(database) == len(descriptors) and database.method == "range"
    for i, j in [(0, 1), (5, 40), (59, 3)]:
        assert database.distance(i, j) == pytest.approx(lidarloop.distance(descriptors[i], descriptors[j]), rel=1e-6)
    to_all = database.distances(descriptors[7])
    assert to_all.shape == (len(descriptors),)
    assert to_all[7] == pytest.approx(0.0, abs=1e-7)
    np.testing.assert_allclose(to_all, [database.distance(7, j) for j in range(len(database))], rtol=1e-6)


def test_database_matches_the_one_detect_saves(database, detected):
    saved = lidarloop.DescriptorDatabase.load(detected / "database.lldb")
    assert len(saved) == len(database)
    np.testing.assert_array_equal(saved.times_s, database.times_s)
    for i, j in [(0, 1), (5, 40), (59, 3)]:
        assert saved.distance(i, j) == database.distance(i, j)


def test_database_save_load_round_trip(descriptors, tmp_path):
    database = lidarloop.DescriptorDatabase(method="range")
    for descriptor in descriptors[:20]:
        database.add(descriptor)
    database.add_missing(1000.0)
    database.save(tmp_path / "db.lldb")
    loaded = lidarloop.DescriptorDatabase.load(tmp_path / "db.lldb")
    assert len(loaded) == len(database)
    assert not loaded.is_valid(len(loaded) - 1) and loaded.is_valid(0)
    np.testing.assert_array_equal(loaded.times_s, database.times_s)
    assert loaded.distance(0, len(loaded) - 1) == np.inf
    n = len(loaded) - 1
    expected = [[database.distance(i, j) for j in range(n)] for i in range(n)]
    np.testing.assert_array_equal([[loaded.distance(i, j) for j in range(n)] for i in range(n)], expected)


def test_loading_a_damaged_database_raises_read_error(database, tmp_path):
    file = tmp_path / "db.lldb"
    database.save(file)
    file.write_bytes(file.read_bytes()[:-5])
    with pytest.raises(lidarloop.ReadError) as error:
        lidarloop.DescriptorDatabase.load(file)
    assert error.value.file == str(file)
    with pytest.raises(lidarloop.ReadError):
        lidarloop.DescriptorDatabase.load(tmp_path / "missing.lldb")


def test_adding_another_method_raises_config_error(database, sequence):
    with pytest.raises(lidarloop.ConfigError):
        database.add(lidarloop.describe(sequence[0], "height"))


def test_index_search_is_the_brute_force_top_k(database, descriptors):
    index = database.index()
    index.insert_all()
    eligible = np.arange(len(database)) < 30
    for query in (descriptors[45], descriptors[50]):
        distances = database.distances(query)
        order = sorted(range(len(database)), key=lambda j: (distances[j], j))
        found = index.search(query, 5)
        assert [n.index for n in found] == order[:5]
        np.testing.assert_allclose([n.distance for n in found], distances[order[:5]], rtol=1e-6)
        restricted = index.search(query, 5, eligible=eligible)
        assert [n.index for n in restricted] == [j for j in order if eligible[j]][:5]
    with pytest.raises(lidarloop.ShapeError):
        index.search(descriptors[0], 3, eligible=np.ones(3, bool))


def test_ndt_has_no_index(sequence):
    database = lidarloop.DescriptorDatabase(method="ndt")
    database.add(lidarloop.describe(sequence[0], "ndt"))
    assert database.index() is None


def read_loops(results):
    with open(results / "loops.csv") as file:
        return {int(row["query"]): row for row in csv.DictReader(file)}


def test_online_detector_finds_the_loops_detect_finds(sequence, detected):
    detector = lidarloop.LoopDetector(method="range", min_gap=MIN_GAP, verify=False)
    times, poses = sequence.poses  # detect measures the path rule on them
    queries = [detector.process(sequence[i], times[i], odometry=poses[i])
               for i in range(len(sequence))]
    expected = read_loops(detected)
    assert len(detector) == len(sequence)
    assert {q.query for q in queries if q.candidates} == set(expected)
    for query in queries:
        if not query.candidates:
            continue
        row = expected[query.query]
        best = query.candidates[0]
        assert best.index == int(row["match"])
        assert best.distance == pytest.approx(float(row["distance"]), rel=1e-6)
        assert query.accepted == (row["accepted"] == "1")
        assert (query.match == best.index) == query.accepted


def test_detector_save_load_continues_the_map(sequence, tmp_path):
    detector = lidarloop.LoopDetector(method="range", min_gap=MIN_GAP, verify=False)
    for i in range(40):
        detector.process(sequence[i])
    detector.save(tmp_path / "map.lldb")
    loaded = lidarloop.LoopDetector.load(tmp_path / "map.lldb")
    assert len(loaded) == 40 and loaded.threshold == detector.threshold and not loaded.verify
    query = lidarloop.describe(sequence[45], "range")
    assert [(n.index, n.distance) for n in loaded.query(query).candidates] == [
        (n.index, n.distance) for n in detector.query(query).candidates
    ]


def test_verifying_detector_keeps_and_saves_its_scans(sequence, tmp_path):
    detector = lidarloop.LoopDetector(method="range", min_gap=MIN_GAP, top_k=2)
    results = [detector.process(sequence[i]) for i in range(15)]
    assert detector.verify
    assert all(r.verified == bool(r.candidates) for r in results)
    detector.save(tmp_path / "map.lldb")
    assert (tmp_path / "map.scans").is_file()
    assert len(lidarloop.LoopDetector.load(tmp_path / "map.lldb")) == 15
    # A map without scans saved over it removes the earlier scans, which would be taken for its.
    plain = lidarloop.LoopDetector(method="range", min_gap=MIN_GAP, verify=False)
    for i in range(15, 30):
        plain.process(sequence[i])
    plain.save(tmp_path / "map.lldb")
    assert not (tmp_path / "map.scans").exists()
    # A file of that name that is no map's prepared scans stays; a map is no .scans file.
    (tmp_path / "map.scans").write_text("mine")
    plain.save(tmp_path / "map.lldb")
    assert (tmp_path / "map.scans").read_text() == "mine"
    with pytest.raises(lidarloop.ConfigError, match="save the map as a .lldb file"):
        detector.save(tmp_path / "other.scans")


def test_a_detectors_database_and_times_are_copies(sequence):
    detector = lidarloop.LoopDetector(method="range", min_gap=MIN_GAP, verify=False)
    for i in range(5):
        detector.process(sequence[i])
    database = detector.database
    times = database.times_s
    database.add(lidarloop.describe(sequence[6], "range"))
    assert len(database) == 6 and len(detector) == 5  # the detector's own is unchanged
    for i in range(5, 40):  # the database grows (and reallocates) under the copies
        detector.process(sequence[i])
    np.testing.assert_array_equal(times, detector.database.times_s[:5])


def test_stopping_at_the_first_loop_closes_the_same_scans(sequence):
    """stop_at_first_loop: each query's loop is its first candidate that registering every one
    accepts, with the same verdict; the candidates after it are not registered."""
    every = lidarloop.LoopDetector(method="range", min_gap=MIN_GAP, top_k=3,
                                   stop_at_first_loop=False)
    first = lidarloop.LoopDetector(method="range", min_gap=MIN_GAP, top_k=3)
    assert first.stop_at_first_loop and not every.stop_at_first_loop
    not_needed = closed = 0
    for i in range(len(sequence)):
        a, b = every.process(sequence[i]), first.process(sequence[i])
        assert a.accepted == b.accepted, i
        closed += b.accepted
        reasons = [v.reason for v in b.verifications]
        not_needed += reasons.count("not_needed")
        if b.accepted:
            loop = next(c for c, v in enumerate(a.verifications) if v.accepted)
            assert b.loop == loop, i
            np.testing.assert_allclose(b.verifications[loop].T_match_query,
                                       a.verifications[loop].T_match_query)
            assert reasons[loop + 1:] == ["not_needed"] * (len(reasons) - loop - 1)
    assert not_needed > 0 and closed > 3  # the sequence revisits: there are loops to stop at


def test_detector_rejects_bad_points_and_config():
    detector = lidarloop.LoopDetector(method="range", verify=False)
    with pytest.raises(lidarloop.ShapeError):
        detector.process(np.zeros((5, 2)))
    with pytest.raises(lidarloop.NonFiniteError):
        detector.process(np.full((5, 3), np.nan))
    assert len(detector) == 0
    with pytest.raises(lidarloop.ConfigError, match="top_k"):
        lidarloop.LoopDetector(top_k=0)


def test_online_detector_with_odometry_counts_the_gap_in_metres(cli, sequence, tmp_path):
    """Online with each scan's odometry pose: the candidates `detect --odometry` gives with the
    gap in metres of path."""
    out = tmp_path / "detect"
    subprocess.run(
        [str(cli), "detect", str(sequence.root), "--method", "range", "--no-verify",
         "--min-gap", "20", "--min-gap-unit", "metres",
         "--odometry", str(sequence.root / "poses_odometry.txt"), "--out", str(out)],
        check=True, capture_output=True)
    expected = read_loops(out)
    times, odometry = lidarloop.read_poses(sequence.root / "poses_odometry.txt")
    detector = lidarloop.LoopDetector(method="range", min_gap=20, min_gap_unit="metres", verify=False)
    queries = [detector.process(sequence[i], times[i], odometry=odometry[i]) for i in range(len(sequence))]
    assert {q.query for q in queries if q.candidates} == set(expected)
    for query in queries:
        if query.candidates:
            assert query.candidates[0].index == int(expected[query.query]["match"])
    with pytest.raises(lidarloop.ConfigError, match="odometry"):
        lidarloop.LoopDetector(method="range", min_gap_unit="metres").process(sequence[0])


def test_online_detector_rejects_the_loops_its_odometry_contradicts(sequence):
    """The pose graph's gate online: with the true poses as odometry the verified loops stay; with
    the revisits' odometry turned 30 degrees they are registered and rejected as odometry_mismatch;
    with it 100 m off their earlier scans are out of a loop's reach and no candidates at all."""
    times, truth = sequence.poses

    def run(odometry):
        detector = lidarloop.LoopDetector(method="range", min_gap=MIN_GAP, top_k=3)
        return [detector.process(sequence[i], times[i], odometry=odometry[i]) for i in range(len(sequence))]

    agreeing = run(truth)
    across = [q for q in agreeing if q.query >= 40 and q.loop is not None and q.match < 40]
    assert across, "the sequence has verified loops from scans 40.. back to scans before 40"
    turned = truth.copy()
    c, s = np.cos(np.radians(30.0)), np.sin(np.radians(30.0))
    turned[40:, :3, :3] = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]) @ truth[40:, :3, :3]
    contradicted = run(turned)
    for query in contradicted[40:]:
        assert query.loop is None or query.match >= 40, query.query
    for query in across:
        reasons = [v.reason for v in contradicted[query.query].verifications]
        assert "odometry_mismatch" in reasons, query.query
    shifted = truth.copy()
    shifted[40:, 0, 3] += 100.0  # the odometry jumps 100 m at scan 40
    for query in run(shifted)[40:]:
        assert all(c.index >= 40 for c in query.candidates), query.query
    with pytest.raises(lidarloop.ShapeError):
        lidarloop.LoopDetector(method="range").process(sequence[0], odometry=np.eye(3))


def test_a_loaded_map_continues_with_odometry(sequence, tmp_path):
    """A map saved by a session with odometry, loaded and fed the rest with odometry: its scans
    stay candidates (another session), and scans with and without a pose still do not mix."""
    times, odometry = lidarloop.read_poses(sequence.root / "poses_odometry.txt")
    first = lidarloop.LoopDetector(method="range", min_gap=20, min_gap_unit="metres", verify=False)
    for i in range(30):
        first.process(sequence[i], times[i], odometry=odometry[i])
    first.save(tmp_path / "map.lldb")
    loaded = lidarloop.LoopDetector.load(tmp_path / "map.lldb")
    queries = [loaded.process(sequence[i], times[i], odometry=odometry[i]) for i in range(30, 40)]
    assert all(n.index < 30 for n in queries[0].candidates) and queries[0].candidates
    with pytest.raises(lidarloop.ConfigError, match="no odometry pose"):
        loaded.process(sequence[40], times[40])
