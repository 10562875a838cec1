"""The run layer: detect, evaluate and optimise against the CLI on a small simulated sequence
(80 VLP-16 scans out and back along a street: 27 scans revisit a place), and the guarantees of
a results folder."""

import json
import shutil
import subprocess

import numpy as np
import pytest

import lidarloop


@pytest.fixture(scope="module")
def sequence(tmp_path_factory):
    folder = tmp_path_factory.mktemp("data") / "street"
    simulator = lidarloop.Simulator(scene="urban", route="uturn", sensor="vlp16", scans=80,
                                    horizontal_steps=512)
    lidarloop.write_simulation(simulator, folder)
    return folder


@pytest.fixture(scope="module")
def cli_verified(cli, sequence, tmp_path_factory):
    """`lidarloop detect --top-k 1` (with verification) once for the tests that need it."""
    out = tmp_path_factory.mktemp("cli") / "verified"
    run_cli(cli, "detect", sequence, "--method", "range", "--top-k", "1", "--out", out)
    return out


def run_cli(cli, *args):
    subprocess.run([str(cli), *map(str, args), "--quiet"], check=True, capture_output=True)


def read_csv(path):
    lines = path.read_text().splitlines()
    header = lines[0].split(",")
    return [dict(zip(header, line.split(","))) for line in lines[1:]]


def without_timings(value):
    """metrics.json without the figures that measure time (they differ run to run)."""
    if isinstance(value, dict):
        return {k: without_timings(v) for k, v in value.items()
                if not (k.endswith("_ms") or k.endswith("_s") or "ms_per" in k or k in
                        ("seconds", "ns_per_comparison", "verification_times"))}
    if isinstance(value, list):
        return [without_timings(v) for v in value]
    return value


def test_detect_without_verification_matches_the_cli(cli, sequence, tmp_path):
    run_cli(cli, "detect", sequence, "--method", "range", "--no-verify", "--out", tmp_path / "cli")
    result = lidarloop.detect(sequence, out=tmp_path / "py", method="range", verify=False)
    for name in ("loops.csv", "candidates.csv", "config.yaml", "similarity.bin"):
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), \
            name
    rows = read_csv(tmp_path / "cli" / "loops.csv")
    loops = result.loops
    assert len(rows) == len(loops["query"]) > 40
    np.testing.assert_array_equal(loops["query"], [int(r["query"]) for r in rows])
    np.testing.assert_array_equal(loops["match"], [int(r["match"]) for r in rows])
    np.testing.assert_allclose(loops["distance"], [float(r["distance"]) for r in rows], rtol=1e-8)
    np.testing.assert_array_equal(loops["accepted"], [r["accepted"] == "1" for r in rows])
    assert result.accepted == sum(r["accepted"] == "1" for r in rows)
    assert result.method == "range" and np.isnan(loops["T_match_query"]).all()
    run = json.loads((tmp_path / "py" / "run.json").read_text())
    assert run["status"] == "complete" and run["command_line"].startswith("lidarloop.detect(")
    assert "loops.csv" in run["files"]


def test_an_opened_dataset_runs_as_its_folder(sequence, tmp_path):
    by_path = lidarloop.detect(sequence, out=tmp_path / "path", verify=False)
    dataset = lidarloop.open_dataset(sequence)
    by_dataset = lidarloop.detect(dataset, out=tmp_path / "dataset", verify=False)
    assert (tmp_path / "path" / "loops.csv").read_bytes() == \
        (tmp_path / "dataset" / "loops.csv").read_bytes()
    assert by_dataset.accepted == by_path.accepted
    with pytest.raises(lidarloop.ConfigError, match="open_dataset"):
        lidarloop.detect(dataset, out=tmp_path / "x", format="kitti")
    with pytest.raises(TypeError, match="lidarloop.Dataset"):
        lidarloop.evaluate(42, out=tmp_path / "y")


def test_verified_detect_matches_the_cli(cli_verified, sequence, tmp_path):
    calls = []
    result = lidarloop.detect(sequence, out=tmp_path / "py", method="range", top_k=1,
                              progress=lambda *args: calls.append(args))
    assert (tmp_path / "py" / "loops.csv").read_bytes() == \
        (cli_verified / "loops.csv").read_bytes()
    stages = {stage: [] for stage, _, _ in calls}
    for stage, done, total in calls:
        stages[stage].append((done, total))
    assert "verifying" in stages
    for told in stages.values():  # each stage told in rising order, ending with all done
        assert [done for done, _ in told] == sorted({done for done, _ in told})
        assert told[-1][0] == told[-1][1]
    from_file = lidarloop.read_loops_csv(cli_verified / "loops.csv", 80)
    assert len(result.accepted_loops) == len(from_file) > 10
    for ours, theirs in zip(result.accepted_loops, from_file):
        assert (ours.query, ours.match) == (theirs.query, theirs.match)
        np.testing.assert_allclose(ours.T_match_query, theirs.T_match_query, atol=1e-6)
    accepted = result.loops["accepted"]
    verdicts = [v for v, a in zip(result.loops["verification"], accepted) if a]
    assert all(v.accepted and v.reason == "none" for v in verdicts)
    np.testing.assert_array_equal(result.loops["T_match_query"][accepted],
                                  [v.T_match_query for v in verdicts])


def test_evaluate_matches_the_cli(cli, sequence, tmp_path):
    run_cli(cli, "evaluate", sequence, "--method", "range", "--method", "height", "--no-verify",
            "--fixed-thresholds", "0.01,0.02", "--out", tmp_path / "cli")
    result = lidarloop.evaluate(sequence, out=tmp_path / "py", methods=["range", "height"],
                                verify=False, fixed_thresholds=[0.01, 0.02])
    cli_metrics = json.loads((tmp_path / "cli" / "metrics.json").read_text())
    py_metrics = json.loads(result.metrics_path.read_text())
    assert without_timings(py_metrics) == without_timings(cli_metrics)
    assert without_timings(result.metrics) == without_timings(cli_metrics)
    assert list(result.methods) == ["range", "height"]
    for name, evaluation in result.methods.items():
        assert without_timings(evaluation.metrics) == \
            without_timings(cli_metrics["methods"][name])
        similarity = evaluation.similarity
        assert similarity.shape == (80, 80)
        np.testing.assert_array_equal(similarity, similarity.T)
    range_eval = result.methods["range"]
    # The attributes carry the same figures as the JSON.
    cli_range = cli_metrics["methods"]["range"]
    assert range_eval.pairwise.best_mcc.score == pytest.approx(cli_range["best_mcc"])
    assert range_eval.pairwise.best_mcc.threshold == pytest.approx(cli_range["tau_best_mcc"])
    assert range_eval.pairwise.roc_auc == pytest.approx(cli_range["roc_auc"])
    assert range_eval.per_scan.zero_error.recall == pytest.approx(cli_range["recall_at_zero_fp"])
    assert range_eval.retrieval.recall_at_1 == pytest.approx(0.59375)  # the CLI printed 59.375 %
    assert range_eval.retrieval_verified is None
    assert result.truth.overlapping_count == 53  # as printed, with the default 50 m path rule
    for name in ("metrics.json", "roc.csv", "pr.csv", "report.md", "config.yaml"):
        assert (tmp_path / "py" / name).is_file(), name


def test_evaluate_reports_the_scans_it_could_not_read(sequence, tmp_path):
    copy = tmp_path / "copy"
    shutil.copytree(sequence, copy)
    scan = copy / "velodyne" / "000005.bin"
    scan.write_bytes(scan.read_bytes()[:1000])
    result = lidarloop.evaluate(copy, out=tmp_path / "eval", methods=["height"], verify=False,
                                skip_bad=True)
    assert len(result.skipped) == 1 and result.skipped[0].startswith("scan 5: ")
    assert result.metrics["skipped_scans"] == 1
    assert "000005.bin" in (tmp_path / "eval" / "skipped.txt").read_text()
    assert any("1 scan could not be read" in note for note in result.notes)


def test_evaluate_with_odometry_verifies_submaps_as_the_cli(cli, sequence, tmp_path):
    odometry = sequence / "poses_odometry.txt"
    run_cli(cli, "evaluate", sequence, "--method", "range", "--top-k", "1", "--odometry",
            odometry, "--out", tmp_path / "cli")
    result = lidarloop.evaluate(sequence, out=tmp_path / "py", methods=["range"], top_k=1,
                                odometry=odometry)
    cli_metrics = json.loads((tmp_path / "cli" / "metrics.json").read_text())
    assert without_timings(result.metrics) == without_timings(cli_metrics)
    assert result.methods["range"].retrieval_verified is not None
    # Verified with submaps (config.yaml records the window), not scan by scan.
    assert "submap_path_m: 10" in (tmp_path / "py" / "config.yaml").read_text()


def test_evaluate_learns_on_another_dataset_as_the_cli(cli, sequence, tmp_path):
    other = tmp_path / "other"
    lidarloop.write_simulation(lidarloop.Simulator(scene="urban", route="uturn", sensor="vlp16",
                                                   scans=60, seed=2, horizontal_steps=256), other)
    run_cli(cli, "evaluate", sequence, "--method", "range", "--no-verify", "--train-on", other,
            "--out", tmp_path / "cli")
    result = lidarloop.evaluate(sequence, out=tmp_path / "py", methods=["range"], verify=False,
                                train_on=lidarloop.open_dataset(other))
    cli_metrics = json.loads((tmp_path / "cli" / "metrics.json").read_text())
    assert without_timings(result.metrics) == without_timings(cli_metrics)
    learning = cli_metrics["methods"]["range"]["threshold_learning"]
    assert learning["trained_on"] != "first part" and str(other) in learning["trained_on"]
    assert result.methods["range"].learnt.threshold == pytest.approx(learning["tau"])


def test_optimise_matches_the_cli(cli, cli_verified, sequence, tmp_path):
    loops = cli_verified / "loops.csv"
    odometry = sequence / "poses_odometry.txt"
    run_cli(cli, "optimise", sequence, "--odometry", odometry, "--loops", loops, "--out",
            tmp_path / "cli")
    result = lidarloop.optimise(sequence, odometry=odometry, loops=loops, out=tmp_path / "py")
    assert (tmp_path / "py" / "poses_optimised.txt").read_bytes() == \
        (tmp_path / "cli" / "poses_optimised.txt").read_bytes()
    cli_metrics = json.loads((tmp_path / "cli" / "metrics.json").read_text())
    py_metrics = json.loads(result.metrics_path.read_text())
    assert without_timings(py_metrics) == without_timings(cli_metrics)
    assert result.optimised_metrics["ate_rmse_m"] == cli_metrics["ate_rmse_m_optimised"]
    assert result.optimised_metrics["ate_rmse_m"] < result.odometry_metrics["ate_rmse_m"]
    assert result.result.loops_used == cli_metrics["loops"]["used"] > 10
    assert all(result.loop_is_true)
    kitti = np.loadtxt(tmp_path / "py" / "poses_optimised.txt").reshape(-1, 3, 4)
    np.testing.assert_allclose(result.poses[:, :3, :], kitti, atol=1e-6)
    assert json.loads((tmp_path / "py" / "run.json").read_text())["status"] == "complete"
    with pytest.raises(lidarloop.WriteError):  # inside the dataset, as detect
        lidarloop.optimise(sequence, odometry=odometry, loops=loops, out=sequence / "opt")
    for name in ("map_odometry.ply", "map_optimised.ply", "map.png"):
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes()
    assert result.maps["points_optimised"] == py_metrics["maps"]["points_optimised"] > 1000


def test_map_matches_the_cli(cli, sequence, tmp_path):
    odometry = sequence / "poses_odometry.txt"
    run_cli(cli, "map", sequence, "--poses", odometry, "--voxel", "0.5", "--out",
            tmp_path / "cli.ply")
    written = lidarloop.write_map(sequence, trajectory=odometry, voxel_m=0.5,
                                  out=tmp_path / "py.ply")
    assert (tmp_path / "py.ply").read_bytes() == (tmp_path / "cli.ply").read_bytes()
    built = lidarloop.build_map(sequence, trajectory=odometry, voxel_m=0.5)
    assert built["points"].shape == (written["points"], 3) and written["scans"] == 80
    assert built["colors"].dtype == np.uint8 and built["times_s"].shape == (written["points"],)
    # The same trajectory as an array (times: the scan index, as poses_odometry.txt's).
    kitti = np.loadtxt(odometry).reshape(-1, 3, 4)
    transforms = np.tile(np.eye(4), (len(kitti), 1, 1))
    transforms[:, :3, :] = kitti
    from_array = lidarloop.build_map(sequence, trajectory=transforms, voxel_m=0.5)
    np.testing.assert_allclose(from_array["points"], built["points"], atol=1e-9)
    some = lidarloop.build_map(sequence, scans=[3, 4, 5], voxel_m=0.5)  # the ground truth
    assert some["scans"] == 3 and 0 < len(some["points"]) < len(built["points"])
    with pytest.raises(lidarloop.ConfigError, match="map.voxel_m"):
        lidarloop.build_map(sequence, voxel_m=0.0)
    with pytest.raises(lidarloop.ConfigError, match="holds 79 poses for 80 scans"):
        lidarloop.build_map(sequence, trajectory=transforms[1:])
    with pytest.raises(lidarloop.WriteError, match="lies inside the input"):
        lidarloop.write_map(sequence, out=sequence / "map.ply")
    (tmp_path / "mine.ply").write_text("my map")
    with pytest.raises(lidarloop.WriteError, match="pass overwrite=True"):
        lidarloop.write_map(sequence, out=tmp_path / "mine.ply")
    assert (tmp_path / "mine.ply").read_text() == "my map"


def test_map_of_a_camera_frame_trajectory_matches_the_cli(cli, sequence, tmp_path):
    # The odometry in KITTI's camera frame, P_i = Tr T_i Tr^-1, and the calib that converts it.
    tr = np.array([[0, -1, 0, 0], [0, 0, -1, 0.1], [1, 0, 0, -0.3], [0, 0, 0, 1]], float)
    (tmp_path / "calib.txt").write_text("Tr: " + " ".join(map(str, tr[:3].ravel())) + "\n")
    lidar = np.loadtxt(sequence / "poses_odometry.txt").reshape(-1, 3, 4)
    poses = np.tile(np.eye(4), (len(lidar), 1, 1))
    poses[:, :3, :] = lidar
    camera = tr @ poses @ np.linalg.inv(tr)
    np.savetxt(tmp_path / "camera.txt", camera[:, :3, :].reshape(len(camera), 12), "%.17g")
    run_cli(cli, "map", sequence, "--poses", tmp_path / "camera.txt", "--calib",
            tmp_path / "calib.txt", "--voxel", "0.5", "--out", tmp_path / "cli.ply")
    converted = lidarloop.write_map(sequence, trajectory=tmp_path / "camera.txt",
                                    trajectory_calib=tmp_path / "calib.txt", voxel_m=0.5,
                                    out=tmp_path / "py.ply")
    assert (tmp_path / "py.ply").read_bytes() == (tmp_path / "cli.ply").read_bytes()
    assert not any("y axis" in note for note in converted["notes"])
    sideways = lidarloop.write_map(sequence, trajectory=tmp_path / "camera.txt", voxel_m=0.5,
                                   out=tmp_path / "sideways.ply")
    assert any("turns about its y axis" in note for note in sideways["notes"])


def test_results_folders_are_guarded(sequence, tmp_path):
    with pytest.raises(lidarloop.WriteError):  # inside the dataset: its files would be scans
        lidarloop.detect(sequence, out=sequence / "results", verify=False)
    foreign = tmp_path / "foreign"
    foreign.mkdir()
    (foreign / "notes.txt").write_text("mine")
    with pytest.raises(lidarloop.WriteError, match="pass overwrite=True"):
        lidarloop.detect(sequence, out=foreign, verify=False)
    lidarloop.detect(sequence, out=foreign, verify=False, overwrite=True)
    assert (foreign / "notes.txt").read_text() == "mine" and (foreign / "loops.csv").is_file()
    # A run again into its own folder replaces the run before.
    lidarloop.detect(sequence, out=foreign, verify=False, method="height")
    assert "method: height" in (foreign / "config.yaml").read_text()


def test_no_run_replaces_its_own_input_or_an_earlier_result(sequence, tmp_path):
    """Issue 25 (2, 3): inputs inside `out` are refused; a failed rerun keeps the results."""
    res = tmp_path / "res"
    lidarloop.detect(sequence, out=res, top_k=1)
    before = {p.name: p.read_bytes() for p in res.iterdir()}
    odometry = sequence / "poses_odometry.txt"
    with pytest.raises(lidarloop.WriteError, match="holds the input"):
        lidarloop.optimise(sequence, odometry=odometry, loops=res / "loops.csv", out=res)
    with pytest.raises(lidarloop.WriteError, match="holds the input"):
        lidarloop.evaluate(sequence, out=res, results=[res / "loops.csv"], methods=["range"])
    # A Dataset object opened with poses from `out` names them as inputs too, even with overwrite.
    (res / "poses_copy.txt").write_bytes((sequence / "poses.txt").read_bytes())
    opened = lidarloop.open_dataset(sequence, poses=res / "poses_copy.txt")
    with pytest.raises(lidarloop.WriteError, match="holds the input"):
        lidarloop.detect(opened, out=res, verify=False, overwrite=True)
    with pytest.raises(lidarloop.WriteError, match="holds the input"):  # the training data too
        lidarloop.evaluate(sequence, train_on=opened, out=res, overwrite=True, methods=["range"])
    assert (res / "poses_copy.txt").is_file()
    before["poses_copy.txt"] = (res / "poses_copy.txt").read_bytes()

    def interrupt(stage, done, total):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        lidarloop.detect(sequence, out=res, verify=False, progress=interrupt)
    assert {p.name: p.read_bytes() for p in res.iterdir()} == before


def test_a_failed_run_leaves_only_run_json(sequence, tmp_path):
    def interrupt(stage, done, total):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        lidarloop.detect(sequence, out=tmp_path / "out", verify=False, progress=interrupt)
    assert [p.name for p in (tmp_path / "out").iterdir()] == ["run.json"]
    run = json.loads((tmp_path / "out" / "run.json").read_text())
    assert run["status"] == "failed" and "progress" in run["message"]
    with pytest.raises(lidarloop.ConfigError, match="no_such_method"):
        lidarloop.detect(sequence, out=tmp_path / "bad", method="no_such_method")
    with pytest.raises(lidarloop.ReadError):
        lidarloop.evaluate(tmp_path / "missing", out=tmp_path / "eval")


@pytest.mark.parametrize("area", ["registration", "posegraph", "eval", "sim", "app"])
def test_stubs_match_the_module(area):
    """Every exported name has a stub, and every public member of a class a stub entry."""
    import ast
    import importlib
    from pathlib import Path

    module = importlib.import_module(f"lidarloop.{area}")
    stub = Path(module.__file__).with_suffix(".pyi")
    tree = ast.parse(stub.read_text())
    stubbed = {n.name: n for n in tree.body if isinstance(n, (ast.ClassDef, ast.FunctionDef))}
    assert set(module.__all__) == set(stubbed)
    for name, node in stubbed.items():
        if not isinstance(node, ast.ClassDef):
            continue
        members = {getattr(m, "name", None) or getattr(getattr(m, "target", None), "id", None)
                   for m in node.body}
        public = {a for a in dir(getattr(module, name)) if not a.startswith("_")}
        assert public <= members, f"{name}: no stub for {public - members}"


@pytest.mark.parametrize("command", ["detect", "evaluate", "optimise"])
def test_stubs_list_the_run_options(command):
    """The stub of each run command lists exactly its run options as keywords."""
    import ast
    from pathlib import Path

    import lidarloop.app

    tree = ast.parse(Path(lidarloop.app.__file__).with_suffix(".pyi").read_text())
    stub = next(n for n in tree.body if isinstance(n, ast.FunctionDef) and n.name == command)
    keywords = {a.arg for a in stub.args.kwonlyargs}
    options = {o["keyword"] for o in lidarloop.run_options(command)}
    assert options <= keywords, f"{command}: no stub keyword for {options - keywords}"


def test_stopping_at_the_first_loop_closes_the_same_scans(cli, sequence, tmp_path):
    """stop_at_first_loop (the default; --all-candidates turns it off): the scans closed with
    every candidate registered, fewer candidates registered (the rest 'not_needed'), as the
    CLI."""
    run_cli(cli, "detect", sequence, "--method", "range", "--top-k", "3", "--all-candidates",
            "--out", tmp_path / "cli_every")
    first = lidarloop.detect(sequence, out=tmp_path / "py", method="range", top_k=3)
    every = lidarloop.detect(sequence, out=tmp_path / "every", method="range", top_k=3,
                             stop_at_first_loop=False)
    assert (tmp_path / "every" / "candidates.csv").read_bytes() == \
        (tmp_path / "cli_every" / "candidates.csv").read_bytes()
    assert first.accepted == every.accepted > 10
    reasons = [r["reason"] for r in read_csv(tmp_path / "py" / "candidates.csv")]
    assert "not_needed" in reasons
    registered = sum(r != "not_needed" for r in reasons)
    assert registered < len(read_csv(tmp_path / "every" / "candidates.csv"))


def test_a_gap_in_metres_and_min_path_match_the_cli(cli, sequence, tmp_path):
    odometry = sequence / "poses_odometry.txt"
    run_cli(cli, "detect", sequence, "--method", "range", "--no-verify", "--min-gap", "20",
            "--min-gap-unit", "metres", "--odometry", odometry, "--out", tmp_path / "cli")
    result = lidarloop.detect(sequence, out=tmp_path / "py", method="range", verify=False,
                              min_gap=20, min_gap_unit="metres", odometry=odometry)
    for name in ("loops.csv", "candidates.csv", "config.yaml"):
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), \
            name
    rows = read_csv(tmp_path / "cli" / "loops.csv")
    assert len(rows) > 10 and all(float(r["path_m"]) > 20 for r in rows)
    np.testing.assert_allclose(result.loops["path_m"], [float(r["path_m"]) for r in rows],
                               rtol=1e-8)
    # Half the path: the revisits near the U-turn are too little path back.
    positions = np.loadtxt(sequence / "poses.txt").reshape(-1, 3, 4)[:, :, 3]
    min_path = round(0.5 * np.linalg.norm(np.diff(positions, axis=0), axis=1).sum())
    run_cli(cli, "evaluate", sequence, "--method", "range", "--no-verify", "--min-path", min_path,
            "--out", tmp_path / "cli_eval")
    evaluated = lidarloop.evaluate(sequence, out=tmp_path / "py_eval", methods=["range"],
                                   verify=False, min_path_m=min_path)
    cli_metrics = json.loads((tmp_path / "cli_eval" / "metrics.json").read_text())
    assert without_timings(evaluated.metrics) == without_timings(cli_metrics)
    assert cli_metrics["ground_truth"]["min_path_m"] == min_path
    assert 0 < evaluated.truth.overlapping_count < 55  # fewer revisits than without the rule


def test_odometry_in_kittis_camera_frame_is_converted_as_the_cli(cli, sequence, tmp_path):
    """The odometry written in KITTI's camera frame (Tr T Tr^-1) and given with its calib: the
    CLI and Python convert it back, so the path and loops are those of the LiDAR-frame file."""
    lidar = np.loadtxt(sequence / "poses_odometry.txt").reshape(-1, 3, 4)
    tr = np.array([[0, -1, 0, 0], [0, 0, -1, 0.1], [1, 0, 0, -0.3], [0, 0, 0, 1]], float)
    calib = tmp_path / "calib.txt"
    calib.write_text("Tr: " + " ".join(map(str, tr[:3].ravel())) + "\n")
    square = np.tile(np.eye(4), (len(lidar), 1, 1))
    square[:, :3] = lidar
    camera = tr @ square @ np.linalg.inv(tr)
    camera_file = tmp_path / "odometry_camera.txt"
    np.savetxt(camera_file, camera[:, :3].reshape(-1, 12), fmt="%.15g")
    flags = ("--method", "range", "--no-verify", "--min-gap", "20", "--min-gap-unit", "metres")
    run_cli(cli, "detect", sequence, *flags, "--odometry", sequence / "poses_odometry.txt",
            "--out", tmp_path / "lidar")
    run_cli(cli, "detect", sequence, *flags, "--odometry", camera_file, "--odometry-calib", calib,
            "--out", tmp_path / "cli")
    lidarloop.detect(sequence, out=tmp_path / "py", method="range", verify=False, min_gap=20,
                     min_gap_unit="metres", odometry=camera_file, odometry_calib=calib)
    expected = read_csv(tmp_path / "lidar" / "loops.csv")
    assert len(expected) > 10
    for run in ("cli", "py"):
        rows = read_csv(tmp_path / run / "loops.csv")
        assert [r["match"] for r in rows] == [r["match"] for r in expected], run
        np.testing.assert_allclose([float(r["path_m"]) for r in rows],
                                   [float(r["path_m"]) for r in expected], rtol=1e-9)
    with pytest.raises(lidarloop.ConfigError, match="TUM"):
        tum = tmp_path / "odometry.tum"
        tum.write_text("".join(f"{i} 0 0 0 0 0 0 1\n" for i in range(len(lidar))))
        lidarloop.detect(sequence, out=tmp_path / "tum", verify=False, odometry=tum,
                         odometry_calib=calib)


def test_keep_freed_memory_for_reuse_is_taken_by_glibc():
    # What the CLI does first; opt-in for a Python process (docs/python.md).
    assert lidarloop.keep_freed_memory_for_reuse() is True


def test_numpy_scalars_are_the_numbers_they_hold(sequence, tmp_path):
    plain = lidarloop.detect(sequence, out=tmp_path / "plain", verify=False, top_k=3,
                             config={"histogram": {"bins": 50}})
    numpy = lidarloop.detect(sequence, out=tmp_path / "numpy", verify=False, top_k=np.int64(3),
                             config={"histogram": {"bins": np.int64(50)}})
    assert (tmp_path / "numpy" / "loops.csv").read_bytes() == \
        (tmp_path / "plain" / "loops.csv").read_bytes()
    assert numpy.accepted == plain.accepted
    with pytest.raises(TypeError, match="is no number"):
        lidarloop.detect(sequence, out=tmp_path / "bad", config={"histogram": {"bins": object()}})


def test_a_path_with_a_null_byte_is_a_value_error_naming_the_argument(sequence, tmp_path):
    # As Python's own open() refuses it; not pybind11's "Unable to cast".
    with pytest.raises(ValueError, match="^dataset: embedded null byte in the path"):
        lidarloop.detect("a\x00b", out=tmp_path / "out")
    with pytest.raises(ValueError, match="^points: embedded null byte in the path"):
        lidarloop.describe("scan\x00.bin")
    with pytest.raises(ValueError, match="^train_on: embedded null byte in the path"):
        lidarloop.evaluate(sequence, out=tmp_path / "out", train_on="a\x00b")
    with pytest.raises(ValueError, match="^dataset: not a path this system can encode"):
        lidarloop.detect("\ud800", out=tmp_path / "out")
