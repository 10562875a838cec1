"""The pose graph and the trajectory metrics: a known-answer optimisation, loop closing on a
drifting square, g2o output, and ATE / RPE against NumPy recomputations."""

import numpy as np
import pytest

import lidarloop

# A loop sigma of 0.2 m (default 0.1), so that the answer shows the config was applied; a Cauchy
# scale of 100 sigmas (the largest allowed) keeps the loop's error nearly quadratic.
CONFIG = {"posegraph": {"information": {"loop_translation_sigma_m": 0.2},
                        "robust": {"cauchy_scale": 100.0}}}


def pose(x=0.0, y=0.0, yaw_deg=0.0, z=0.0):
    T = np.eye(4)
    c, s = np.cos(np.radians(yaw_deg)), np.sin(np.radians(yaw_deg))
    T[:2, :2] = [[c, -s], [s, c]]
    T[:3, 3] = [x, y, z]
    return T


def random_rotation(rng):
    q = rng.normal(size=4)
    q /= np.linalg.norm(q)
    w, x, y, z = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def test_two_poses_settle_at_the_information_weighted_mean():
    # Odometry says pose 1 is 1.0 m ahead, the loop says 1.2 m. The odometry step of 1 m has
    # sigma_t^2 = 0.01^2 + 0.1^2 * 1 (defaults), the loop 0.2^2 (CONFIG; no RMSE known).
    odometry = np.stack([pose(), pose(1.0)])
    loop = lidarloop.LoopConstraint(query=1, match=0, T_match_query=pose(1.2))
    graph = lidarloop.build_pose_graph(odometry, [loop], config=CONFIG)
    assert [e.kind for e in graph.edges] == ["odometry", "loop"]
    w_odometry, w_loop = 1.0 / (0.01**2 + 0.1**2 * 1.0), 1.0 / 0.2**2
    assert graph.edges[0].information[0, 0] == pytest.approx(w_odometry)
    assert graph.edges[1].information[0, 0] == pytest.approx(w_loop)
    result = lidarloop.optimise_pose_graph(graph, config=CONFIG)
    expected_x = (w_odometry * 1.0 + w_loop * 1.2) / (w_odometry + w_loop)
    assert result.loops_used == 1 and result.loops[0].verdict == "used"
    np.testing.assert_allclose(result.poses[0], np.eye(4), atol=1e-12)  # pose 0 is fixed
    assert result.poses[1][0, 3] == pytest.approx(expected_x, abs=1e-4)
    np.testing.assert_allclose(result.poses[1][:3, :3], np.eye(3), atol=1e-9)
    assert result.final_cost < result.initial_cost


def drifting_square(rng, side_m=20, step_m=1.0, yaw_drift_deg=0.02):
    """Ground truth around a square (back to the start) and its odometry: a random walk about as
    large as the default odometry information expects, plus a small yaw bias."""
    truth, T = [], np.eye(4)
    for leg in range(4):
        for _ in range(int(side_m / step_m)):
            truth.append(T.copy())
            T = T @ pose(step_m)
        T = T @ pose(yaw_deg=90)
    truth.append(T.copy())
    truth = np.stack(truth)
    odometry = [truth[0]]
    for a, b in zip(truth[:-1], truth[1:]):
        step = np.linalg.inv(a) @ b
        noise = pose(*rng.normal(0, 0.03, 2), yaw_drift_deg + rng.normal(0, 0.03))
        odometry.append(odometry[-1] @ step @ noise)
    return truth, np.stack(odometry)


def test_a_loop_closes_a_drifting_square():
    truth, odometry = drifting_square(np.random.default_rng(3))
    last = len(truth) - 1
    T_match_query = np.linalg.inv(truth[0]) @ truth[last]  # the last pose seen from the first
    loop = lidarloop.LoopConstraint(last, 0, T_match_query, overlap=0.6, rmse_m=0.05)
    graph = lidarloop.build_pose_graph(odometry, [loop])
    result = lidarloop.optimise_pose_graph(graph)
    assert result.loops[0].verdict == "used" and result.converged
    # The loop pulls the end back onto the start: its closure error shrinks to the loop's
    # own uncertainty, and the whole trajectory moves closer to the truth.
    def closure_error_m(poses):
        return np.linalg.norm((np.linalg.inv(poses[0]) @ poses[last])[:3, 3]
                              - T_match_query[:3, 3])
    before, after = closure_error_m(odometry), closure_error_m(result.poses)
    assert before > 0.2 and after < 0.1 * before  # measured: 0.24 m -> 0.009 m
    assert (lidarloop.absolute_trajectory_rmse(result.poses, truth)
            < lidarloop.absolute_trajectory_rmse(odometry, truth))


def test_write_g2o_writes_every_vertex_and_edge(tmp_path):
    odometry = np.stack([pose(), pose(1.0), pose(2.0, yaw_deg=10)])
    graph = lidarloop.build_pose_graph(
        odometry, [lidarloop.LoopConstraint(2, 0, pose(2.0, yaw_deg=10))])
    lidarloop.write_g2o(tmp_path / "graph.g2o", graph.poses, graph.edges[:2],
                        commented_edges=graph.edges[2:])
    lines = (tmp_path / "graph.g2o").read_text().splitlines()
    assert sum(line.startswith("VERTEX_SE3:QUAT") for line in lines) == 3
    assert sum(line.startswith("EDGE_SE3:QUAT") for line in lines) == 2
    assert sum(line.startswith("# rejected EDGE_SE3:QUAT 0 2") for line in lines) == 1


def test_bad_graphs_raise_typed_errors():
    odometry = np.stack([pose(), pose(1.0)])
    with pytest.raises(lidarloop.ConfigError):
        lidarloop.build_pose_graph(odometry, [lidarloop.LoopConstraint(5, 0, np.eye(4))])
    with pytest.raises(lidarloop.ShapeError):
        lidarloop.build_pose_graph(np.zeros((2, 3, 4)), [])
    with pytest.raises(lidarloop.ConfigError,
                       match="pose graph's path: scan 1's path is not finite"):
        lidarloop.build_pose_graph(odometry, [], path_m=[0.0, np.inf])
    with pytest.raises(lidarloop.ConfigError, match="never shrinks"):
        lidarloop.build_pose_graph(odometry, [], path_m=[2.0, 1.0])
    with pytest.raises(lidarloop.ShapeError):
        lidarloop.LoopConstraint(1, 0, np.zeros((4, 4)))  # last row is not 0 0 0 1
    with pytest.raises(lidarloop.ReadError):
        lidarloop.build_pose_graph(odometry, [], config={"posegraph": {"no_such_key": 1}})


def numpy_ate(estimate, truth):
    """Horn/Umeyama without scale by SVD, then the RMSE of the aligned positions."""
    p, q = estimate[:, :3, 3], truth[:, :3, 3]
    mp, mq = p.mean(0), q.mean(0)
    U, _, Vt = np.linalg.svd((q - mq).T @ (p - mp))
    D = np.diag([1.0, 1.0, np.sign(np.linalg.det(U @ Vt))])
    R = U @ D @ Vt
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, mq - R @ mp
    aligned = p @ R.T + T[:3, 3]
    return np.sqrt(np.mean(np.sum((aligned - q) ** 2, axis=1))), T


def test_ate_matches_numpy_on_a_random_trajectory():
    rng = np.random.default_rng(7)
    truth = np.stack([pose(*rng.uniform(-20, 20, 2), rng.uniform(0, 360), rng.uniform(-1, 1))
                      for _ in range(25)])
    # The estimate: the truth in another world frame, plus noise.
    T_other_world = np.eye(4)
    T_other_world[:3, :3] = random_rotation(rng)
    T_other_world[:3, 3] = rng.normal(size=3) * 10
    estimate = np.einsum("ij,njk->nik", T_other_world, truth)
    estimate[:, :3, 3] += rng.normal(scale=0.3, size=(25, 3))
    ate, T_truth_estimate = numpy_ate(estimate, truth)
    assert lidarloop.absolute_trajectory_rmse(estimate, truth) == pytest.approx(ate, rel=1e-9)
    aligned = lidarloop.align_rigid(estimate[:, :3, 3], truth[:, :3, 3])
    np.testing.assert_allclose(aligned, T_truth_estimate, atol=1e-9)
    np.testing.assert_allclose(aligned[:3, :3], np.linalg.inv(T_other_world)[:3, :3], atol=0.02)


def test_align_rigid_refuses_positions_that_are_not_finite():
    good = np.zeros((3, 3))
    for bad in (np.full((3, 3), np.nan), np.array([[0, 0, 0], [1, np.inf, 0], [0, 1, 0]])):
        with pytest.raises(lidarloop.NonFiniteError, match="row"):
            lidarloop.align_rigid(bad, good)
        with pytest.raises(lidarloop.NonFiniteError, match="truth row"):
            lidarloop.align_rigid(good, bad)


def rotation_angle(R):
    return np.arccos(np.clip((np.trace(R) - 1) / 2, -1, 1))


def numpy_rpe(estimate, truth, lengths, step):
    path = np.concatenate([[0], np.cumsum(np.linalg.norm(np.diff(truth[:, :3, 3], axis=0),
                                                          axis=1))])
    t_errors, r_errors = [], []
    for i in range(0, len(truth), step):
        for length in lengths:
            later = np.nonzero(path >= path[i] + length)[0]
            if len(later) == 0:
                continue
            j = later[0]
            E = np.linalg.inv(np.linalg.inv(truth[i]) @ truth[j]) @ (
                np.linalg.inv(estimate[i]) @ estimate[j])
            t_errors.append(np.linalg.norm(E[:3, 3]) / length)
            r_errors.append(rotation_angle(E[:3, :3]) / length)
    return 100 * np.mean(t_errors), 100 * np.degrees(np.mean(r_errors)), len(t_errors)


def test_rpe_matches_numpy_on_a_drifting_square():
    truth, odometry = drifting_square(np.random.default_rng(5))
    rpe = lidarloop.trajectory_rpe(odometry, truth, lengths_m=[10, 25, 40], step=3)
    translation, rotation, segments = numpy_rpe(odometry, truth, [10, 25, 40], 3)
    assert rpe.segments == segments > 0
    assert rpe.translation_percent == pytest.approx(translation, rel=1e-9)
    assert rpe.rotation_deg_per_100m == pytest.approx(rotation, rel=1e-9)
    assert lidarloop.trajectory_rpe(truth, truth, lengths_m=[10]).translation_percent == \
        pytest.approx(0, abs=1e-9)
