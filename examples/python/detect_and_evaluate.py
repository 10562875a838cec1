#!/usr/bin/env python3
"""Detect and evaluate the loop closures of a folder of scans with poses, and plot them.

    python3 examples/python/detect_and_evaluate.py DATASET --out OUT [--method range]

DATASET is any folder lidarloop reads (KITTI layout, a folder of scan files, Osnabrueck) with
ground-truth poses. Writes into OUT:
  detection/       `lidarloop detect`'s results folder (loops.csv, ...)
  evaluation/      `lidarloop evaluate`'s results folder (metrics.json, report.md, ...)
  similarity.png   the descriptor distance matrix, the accepted loops marked
  trajectory.png   the ground-truth trajectory (top view), accepted loops drawn as lines
and prints the main figures. Everything is computed by the C++ library; this script only
chooses what to run and draws.
"""

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only, no display
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import lidarloop  # noqa: E402


def parse_arguments():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("dataset", type=Path, help="folder of scans with poses")
    parser.add_argument("--out", type=Path, required=True, help="folder for results and plots")
    parser.add_argument("--method", default="range", help=" | ".join(lidarloop.method_names()))
    parser.add_argument("--top-k", type=int, default=None,
                        help="candidates verified per scan (default: the config's)")
    parser.add_argument("--no-verify", action="store_true", help="descriptor threshold only")
    return parser.parse_args()


def plot_similarity(evaluation, loops, png):
    """The distance matrix (darker: more similar) with the accepted loops as red dots."""
    figure, axes = plt.subplots(figsize=(6, 5))
    image = axes.imshow(evaluation.similarity, cmap="viridis_r", interpolation="nearest")
    accepted = loops["accepted"]
    axes.scatter(loops["match"][accepted], loops["query"][accepted], s=8, c="red",
                 label="accepted loop")
    axes.set_xlabel("match scan")
    axes.set_ylabel("query scan")
    axes.set_title(f"{evaluation.name}: descriptor distance")
    figure.colorbar(image, ax=axes, label="distance")
    axes.legend(loc="lower left")
    figure.tight_layout()
    figure.savefig(png, dpi=100)
    plt.close(figure)


def plot_trajectory(T_world_sensor, loops, png):
    """Top view of the ground truth (the two axes of largest spread, metres) and the loops."""
    positions = T_world_sensor[:, :3, 3]
    x_axis, y_axis = np.argsort(positions.std(axis=0))[::-1][:2]
    xy = positions[:, [x_axis, y_axis]]
    figure, axes = plt.subplots(figsize=(6, 6))
    axes.plot(xy[:, 0], xy[:, 1], "-", color="0.4", lw=1, label="ground truth")
    axes.plot(*xy[0], "go", label="start")
    for query, match in zip(loops["query"][loops["accepted"]], loops["match"][loops["accepted"]]):
        axes.plot(*xy[[match, query]].T, "r-", lw=0.8)
    axes.plot([], [], "r-", label="accepted loop")
    axes.set_aspect("equal", adjustable="datalim")  # true shape, filling the figure
    axes.set_xlabel("metres")
    axes.set_ylabel("metres")
    axes.legend()
    figure.tight_layout()
    figure.savefig(png, dpi=100)
    plt.close(figure)


def main():
    args = parse_arguments()
    args.out.mkdir(parents=True, exist_ok=True)
    verify = False if args.no_verify else None
    detection = lidarloop.detect(args.dataset, out=args.out / "detection", method=args.method,
                                 verify=verify, top_k=args.top_k)
    evaluation = lidarloop.evaluate(args.dataset, out=args.out / "evaluation",
                                    methods=[args.method], verify=False)
    method = evaluation.methods[args.method]
    _, T_world_sensor = lidarloop.open_dataset(args.dataset).poses
    if method.similarity is not None:  # None past output.similarity_matrix_mib
        plot_similarity(method, detection.loops, args.out / "similarity.png")
    plot_trajectory(T_world_sensor, detection.loops, args.out / "trajectory.png")
    print(f"{len(T_world_sensor)} scans, {evaluation.truth.describe()}")
    scans = "scan" if detection.accepted == 1 else "scans"
    print(f"detect ({args.method}): {detection.accepted} {scans} with an accepted loop")
    print(f"evaluate: best MCC {method.pairwise.best_mcc.score:.3f} "
          f"(tau {method.pairwise.best_mcc.threshold:.4g}), ROC AUC "
          f"{method.pairwise.roc_auc:.3f}, recall@1 {method.retrieval.recall_at_1:.3f}")
    print(f"plots: {args.out / 'similarity.png'}, {args.out / 'trajectory.png'}")


if __name__ == "__main__":
    main()
