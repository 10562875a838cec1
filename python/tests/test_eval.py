"""Ground truth and the evaluation metrics against NumPy brute force on small random inputs."""

import types

import numpy as np
import pytest

import lidarloop

N = 40


def random_sequence(seed, n=N):
    """Poses on a random walk that comes back near itself, random headings, 1 s apart."""
    rng = np.random.default_rng(seed)
    xy = np.cumsum(rng.normal(scale=3.0, size=(n, 2)), axis=0) % 25.0
    yaw = rng.uniform(0, 2 * np.pi, n)
    T = np.tile(np.eye(4), (n, 1, 1))
    T[:, 0, 0], T[:, 0, 1], T[:, 1, 0], T[:, 1, 1] = np.cos(yaw), -np.sin(yaw), np.sin(yaw), \
        np.cos(yaw)
    T[:, :2, 3] = xy
    T[:, 2, 3] = rng.uniform(-0.5, 0.5, n)
    return np.arange(n, dtype=float), T, rng


def heading_deg(T):
    return np.degrees(np.arctan2(T[:, 1, 0], T[:, 0, 0]))


def brute_truth(T, distance_m, max_heading_deg, min_gap):
    """positive[i, j]: the rule, by definition, for every pair."""
    positions = T[:, :3, 3]
    d = np.linalg.norm(positions[:, None] - positions[None], axis=2)
    h = heading_deg(T)
    dh = np.abs((h[:, None] - h[None] + 180) % 360 - 180)
    idx = np.arange(len(T))
    comparable = np.abs(idx[:, None] - idx[None]) > min_gap
    positive = comparable & (d < distance_m)
    if max_heading_deg > 0:
        positive &= dh < max_heading_deg
    return positive, comparable, d


@pytest.mark.parametrize("max_heading_deg", [0.0, 60.0])
def test_ground_truth_matches_brute_force(max_heading_deg):
    times, T, _ = random_sequence(1)
    truth = lidarloop.build_ground_truth(times, T, distance_m=6.0, max_heading_deg=max_heading_deg,
                                         min_gap=3)
    positive, comparable, d = brute_truth(T, 6.0, max_heading_deg, 3)
    expected = np.argwhere(np.triu(positive, 1))
    np.testing.assert_array_equal(truth.loops, expected)
    np.testing.assert_allclose(truth.loop_distances_m, d[positive & np.triu(positive, 1)],
                               rtol=1e-12)
    assert len(truth) == N and truth.comparable_pair_count == np.triu(comparable, 1).sum()
    assert truth.overlapping_count == positive.any(axis=1).sum()
    # The nearest scan outside the gap that passes the heading rule.
    for i in range(N):
        allowed = comparable[i].copy()
        if max_heading_deg > 0:
            h = heading_deg(T)
            allowed &= np.abs((h[i] - h + 180) % 360 - 180) < max_heading_deg
        if allowed.any():
            assert truth.nearest[i] == np.flatnonzero(allowed)[np.argmin(d[i, allowed])]
        else:
            assert truth.nearest[i] == -1
    assert truth.is_loop(*expected[0]) and truth.is_loop(expected[0][1], expected[0][0])
    for call in (lambda: truth.is_loop(0, N), lambda: truth.comparable(N, 0),
                 lambda: truth.overlapping(10**9)):
        with pytest.raises(IndexError, match=f"out of range for {N} scans"):
            call()
    config = lidarloop.GroundTruthConfig(distance_m=6.0, min_gap=3)
    assert lidarloop.build_ground_truth(times, T, config).loops.shape == \
        lidarloop.build_ground_truth(times, T, distance_m=6.0, min_gap=3).loops.shape


def random_distances(rng, positive):
    """Distances that tend to be small for positives, with ties (rounded)."""
    n = len(positive)
    D = np.round(rng.uniform(0.2, 1.0, (n, n)) - 0.3 * positive, 2).astype(np.float32)
    D = np.triu(D, 1)
    return D + D.T


def condensed(D):
    return D[np.triu_indices(len(D), 1)]


def brute_confusion(distance, loop, tau):
    detected = distance <= tau
    return (int(np.sum(detected & loop)), int(np.sum(detected & ~loop)),
            int(np.sum(~detected & ~loop)), int(np.sum(~detected & loop)))


def mcc(tp, fp, tn, fn):
    den = np.sqrt(float((tp + fp) * (tp + fn) * (tn + fp) * (tn + fn)))
    return 0.0 if den == 0 else (tp * tn - fp * fn) / den


def f1(tp, fp, tn, fn):
    return 0.0 if tp + fp + fn == 0 else 2 * tp / (2 * tp + fp + fn)


def test_pairwise_evaluation_matches_brute_force():
    times, T, rng = random_sequence(2)
    truth = lidarloop.build_ground_truth(times, T, distance_m=6.0, min_gap=2)
    positive, comparable, _ = brute_truth(T, 6.0, 0.0, 2)
    D = random_distances(rng, positive)
    pairs = lidarloop.collect_pairs(D, truth)
    iu = np.triu_indices(N, 1)
    keep = comparable[iu]
    np.testing.assert_array_equal(pairs.i, iu[0][keep])
    np.testing.assert_array_equal(pairs.loop, positive[iu][keep])
    # The condensed form gives the same pairs.
    np.testing.assert_array_equal(lidarloop.collect_pairs(condensed(D), truth).distance,
                                  pairs.distance)
    distance, loop = pairs.distance.astype(np.float64), pairs.loop
    result = lidarloop.evaluate_pairs(pairs, max_curve_points=0)
    thresholds = np.unique(distance)
    confusions = [brute_confusion(distance, loop, t) for t in thresholds]
    curve = result.curve
    np.testing.assert_array_equal(curve["threshold"][1:], thresholds)
    assert curve["threshold"][0] == -np.inf
    np.testing.assert_array_equal(np.stack([curve[k][1:] for k in ("tp", "fp", "tn", "fn")], 1),
                                  confusions)
    tpr = np.array([0] + [c[0] / loop.sum() for c in confusions])
    fpr = np.array([0] + [c[1] / (~loop).sum() for c in confusions])
    np.testing.assert_allclose(curve["tpr"], tpr)
    np.testing.assert_allclose(curve["fpr"], fpr)
    assert result.roc_auc == pytest.approx(np.sum(np.diff(fpr) * (tpr[1:] + tpr[:-1]) / 2))
    mccs = [mcc(*c) for c in confusions]
    f1s = [f1(*c) for c in confusions]
    assert result.best_mcc.score == pytest.approx(max(mccs))
    assert result.best_mcc.threshold == pytest.approx(thresholds[int(np.argmax(mccs))])
    assert result.best_f1.score == pytest.approx(max(f1s))
    c = result.best_f1.confusion
    assert (c.tp, c.fp, c.tn, c.fn) == confusions[int(np.argmax(f1s))]
    assert c.f1 == pytest.approx(max(f1s)) and c.mcc == pytest.approx(mccs[int(np.argmax(f1s))])
    for tau, c in zip([0.3, 0.5], lidarloop.confusions_at(pairs, [0.3, 0.5])):
        assert (c.tp, c.fp, c.tn, c.fn) == brute_confusion(distance, loop, tau)
        assert c == lidarloop.confusion_at(pairs, tau)
    learnt = lidarloop.learn_on_first_part(pairs, N, train_fraction=0.5, criterion="f1")
    train = pairs.j < round(0.5 * N)
    train_f1 = [f1(*brute_confusion(distance[train], loop[train], t))
                for t in np.unique(distance[train])]
    assert learnt.train_score == pytest.approx(max(train_f1))
    assert learnt.threshold == pytest.approx(np.unique(distance[train])[int(np.argmax(train_f1))])


def brute_best_matches(D, comparable):
    best, best_d, second = [], [], []
    for i in range(len(D)):
        candidates = np.flatnonzero(comparable[i])
        order = candidates[np.lexsort((candidates, D[i, candidates]))]
        best.append(order[0] if len(order) else -1)
        best_d.append(D[i, order[0]] if len(order) else np.inf)
        second.append(D[i, order[1]] if len(order) > 1 else np.inf)
    return np.array(best), np.array(best_d), np.array(second)


def brute_labels(best, best_d, positive, t_d):
    labels = []
    for i, (m, d) in enumerate(zip(best, best_d)):
        overlapping = positive[i].any()
        if m >= 0 and d < t_d:
            labels.append("false_positive" if not overlapping else
                          "true_positive" if positive[i, m] else "mismatch")
        else:
            labels.append("false_negative" if overlapping else "true_negative")
    return labels


def test_per_scan_evaluation_matches_brute_force():
    times, T, rng = random_sequence(3)
    truth = lidarloop.build_ground_truth(times, T, distance_m=5.0, min_gap=4)
    positive, comparable, _ = brute_truth(T, 5.0, 0.0, 4)
    D = random_distances(rng, positive)
    matches = lidarloop.best_matches(D, truth)
    best, best_d, second = brute_best_matches(D.astype(np.float64), comparable)
    np.testing.assert_array_equal(matches.match, best)
    np.testing.assert_allclose(matches.distance, best_d)
    np.testing.assert_allclose(matches.second_distance, second)
    for t_d in (0.3, 0.55, np.inf):
        assert lidarloop.label_scans(matches, truth, t_d) == brute_labels(best, best_d, positive,
                                                                          t_d)
    result = lidarloop.evaluate_per_scan(matches, truth)
    # Zero errors: the largest t_d below which no false positive or mismatch is similar.
    errors = [d for i, (m, d) in enumerate(zip(best, best_d))
              if m >= 0 and (not positive[i].any() or not positive[i, m])]
    t_d = min(errors) if errors else np.inf
    labels = brute_labels(best, best_d, positive, t_d)
    assert result.zero_error.t_d == pytest.approx(t_d)
    assert result.zero_error.counts.true_positive == labels.count("true_positive")
    assert result.zero_error.recall == pytest.approx(labels.count("true_positive")
                                                     / positive.any(axis=1).sum())
    assert result.overlapping == positive.any(axis=1).sum()
    curve = result.curve
    for k in range(len(curve["t_d"])):
        labels = brute_labels(best, best_d, positive, curve["t_d"][k])
        assert curve["mismatch"][k] == labels.count("mismatch")
        assert curve["false_negative"][k] == labels.count("false_negative")


def test_loop_retrieval_recall_matches_brute_force():
    times, T, rng = random_sequence(4)
    truth = lidarloop.build_ground_truth(times, T, distance_m=6.0, min_gap=3)
    positive, comparable, _ = brute_truth(T, 6.0, 0.0, 3)
    D = random_distances(rng, positive)
    k, tau = 3, 0.45
    ranked, hits1, hitsk, revisiting, true_loops, false_loops = [], 0, 0, 0, 0, 0
    for q in range(N):
        earlier = np.flatnonzero(comparable[q, :q])
        order = earlier[np.lexsort((earlier, D[q, earlier]))][:k]
        ranked.append((q, [dict(match=int(j), distance=float(D[q, j]),
                                accepted=bool(D[q, j] <= tau)) for j in order]))
        is_revisiting = positive[q, :q].any()
        revisiting += is_revisiting
        hits1 += is_revisiting and len(order) > 0 and positive[q, order[0]]
        hitsk += is_revisiting and positive[q, order].any()
        accepted = [j for j in order if D[q, j] <= tau]
        if accepted:
            true_loops += positive[q, accepted[0]]
            false_loops += not positive[q, accepted[0]]
    result = lidarloop.evaluate_loop_retrieval(ranked, truth, times, T)
    assert result.k == k and result.revisiting == revisiting > 0
    assert (result.hits_at_1, result.hits_at_k) == (hits1, hitsk)
    assert result.recall_at_1 == pytest.approx(hits1 / revisiting)
    assert (result.true_loops, result.false_loops) == (true_loops, false_loops)
    assert result.precision == pytest.approx(true_loops / (true_loops + false_loops))
    # Any mapping and any sequence of candidates; a bad field is a TypeError that names it.
    proxies = [(q, tuple(types.MappingProxyType(c) for c in cs)) for q, cs in ranked]
    assert lidarloop.evaluate_loop_retrieval(proxies, truth, times, T).hits_at_k == hitsk
    q, candidates = next((q, cs) for q, cs in ranked if cs)
    for key, bad in (("match", -1), ("match", 1.5), ("distance", "x"), ("accepted", "no")):
        with pytest.raises(TypeError, match=f"'{key}' of a candidate of query {q} must be"):
            lidarloop.evaluate_loop_retrieval([(q, [dict(candidates[0], **{key: bad})])],
                                              truth, times, T)


def test_loop_retrieval_checks_a_gap_in_metres_on_the_detectors_path():
    """The detector measured its 20 m gap on an odometry twice as long as the true path."""
    times, T, _ = random_sequence(4)
    truth = lidarloop.build_ground_truth(times, T, distance_m=6.0, min_gap=20.0,
                                         min_gap_unit="metres")
    steps = np.linalg.norm(np.diff(T[:, :3, 3], axis=0), axis=1)
    true_path = np.concatenate([[0.0], np.cumsum(steps)])
    odometry_path = 2.0 * true_path
    positive = (np.linalg.norm(T[:, None, :3, 3] - T[None, :, :3, 3], axis=2) < 6.0) & \
        (np.abs(true_path[:, None] - true_path[None]) > 20.0)
    ranked, hits, inside_true_gap = [], 0, 0
    for q in range(N):
        earlier = [j for j in range(q) if odometry_path[q] - odometry_path[j] > 20.0]
        ranked.append((q, [dict(match=j, distance=float(q - j), accepted=False) for j in earlier]))
        hits += positive[q, :q].any() and positive[q, earlier].any()
        inside_true_gap += sum(true_path[q] - true_path[j] <= 20.0 for j in earlier)
    assert inside_true_gap > 0
    with pytest.raises(lidarloop.ConfigError, match="outside the minimum gap"):
        lidarloop.evaluate_loop_retrieval(ranked, truth, times, T)
    result = lidarloop.evaluate_loop_retrieval(ranked, truth, times, T,
                                               detector_path_m=odometry_path)
    assert result.hits_at_k == hits > 0
    with pytest.raises(lidarloop.Error, match="detector's path"):
        lidarloop.evaluate_loop_retrieval(ranked, truth, times, T,
                                          detector_path_m=odometry_path[:-1])
    shrinking = odometry_path.copy()
    shrinking[5] = -1.0
    with pytest.raises(lidarloop.Error, match="detector's path: scan 5's path"):
        lidarloop.evaluate_loop_retrieval(ranked, truth, times, T, detector_path_m=shrinking)


def test_em_threshold_lies_between_two_clusters():
    rng = np.random.default_rng(5)
    sample = np.concatenate([rng.normal(0.1, 0.01, 200), rng.normal(0.5, 0.05, 300),
                             rng.normal(0.8, 0.05, 100), [np.inf]])
    result = lidarloop.estimate_difference_threshold(sample)
    assert result.fitted and result.values_used == 600 and result.values_skipped == 1
    np.testing.assert_allclose(result.means, [0.1, 0.5, 0.8], atol=0.02)
    assert 0.13 < result.t_d < 0.4
    assert lidarloop.estimate_difference_threshold(sample[:2]).t_d is None


def test_bad_input_raises_typed_errors():
    times, T, _ = random_sequence(6, n=5)
    truth = lidarloop.build_ground_truth(times, T)
    with pytest.raises(lidarloop.ConfigError):  # a ValueError, as the docs' table says
        lidarloop.collect_pairs(np.zeros(3, np.float32), truth)  # 5 scans have 10 pairs
    with pytest.raises(lidarloop.ShapeError):
        lidarloop.collect_pairs(np.zeros((5, 4), np.float32), truth)
    with pytest.raises(lidarloop.ConfigError):
        lidarloop.build_ground_truth(times, T, distance_m=-1.0)
    with pytest.raises(TypeError):
        lidarloop.build_ground_truth(times, T, no_such_rule=1.0)
    bad = T.copy()
    bad[2, 0, 3] = np.nan
    with pytest.raises(lidarloop.NonFiniteError):
        lidarloop.build_ground_truth(times, bad)
    with pytest.raises(lidarloop.EmptyInputError):
        lidarloop.evaluate_pairs(lidarloop.ScoredPairs([], [], [], []))
    for i in (-1, 2**40):  # not wrapped into a 32-bit scan index
        with pytest.raises(lidarloop.ShapeError, match="scan indices must be in"):
            lidarloop.ScoredPairs([i], [1], [0.5], [True])
