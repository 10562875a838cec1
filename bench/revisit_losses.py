#!/usr/bin/env python3
"""Where a detect run's revisits are won and lost, from its candidates.csv and the true poses.

Usage: revisit_losses.py POSES CANDIDATES_CSV [--distance M] [--min-path M] [--min-gap N]

A revisiting scan has an earlier scan more than N scans back, within M metres and more than
--min-path metres of path back (the definitions of ../shared/tools/verified_recall.py); a true
candidate is one of those. Prints:
- the shortlist's ceiling: revisiting scans with a true candidate among the first k ranks, for
  the k the file holds (run `detect --no-verify --top-k 50` for the descriptor alone);
- the revisiting scans closed (a true candidate accepted), those without a true candidate, and
  for the rest the reason their first true candidate was rejected.
Needs NumPy.
"""

import argparse
import collections
import csv

import numpy as np


def positions(poses_file):
    try:
        poses = np.loadtxt(poses_file, ndmin=2)
    except (OSError, ValueError) as error:
        raise SystemExit(f"{poses_file}: cannot read KITTI poses ({error})") from None
    if poses.shape[1] != 12:
        raise SystemExit(f"{poses_file}: expected KITTI poses, 12 values a line")
    return poses.reshape(-1, 3, 4)[:, :, 3]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("poses")
    parser.add_argument("candidates")
    parser.add_argument("--distance", type=float, default=10.0)
    parser.add_argument("--min-path", type=float, default=50.0)
    parser.add_argument("--min-gap", type=int, default=30)
    args = parser.parse_args()

    xyz = positions(args.poses)
    path = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(xyz, axis=0), axis=1))])

    def true_matches(query, matches):
        """Which of `matches` (scan indices) are true matches of `query`: one rule for both uses."""
        matches = np.asarray(matches, dtype=int)
        return ((np.linalg.norm(xyz[matches] - xyz[query], axis=1) < args.distance) &
                (path[query] - path[matches] > args.min_path) & (matches < query - args.min_gap))

    revisiting = [q for q in range(len(xyz)) if true_matches(q, range(q)).any()]
    rows = collections.defaultdict(list)
    try:
        candidates = open(args.candidates, newline="")
    except OSError as error:
        raise SystemExit(f"{args.candidates}: cannot open ({error.strerror})") from None
    with candidates as f:
        reader = csv.DictReader(f)
        if not {"query", "rank", "match"} <= set(reader.fieldnames or []):
            raise SystemExit(f"{args.candidates}: not a candidates.csv (needs query, rank, match)")
        for row in reader:
            rows[int(row["query"])].append(row)

    best_rank, closed, without, first_reason = {}, 0, 0, collections.Counter()
    for query in revisiting:
        listed = rows[query]
        hits = true_matches(query, [int(r["match"]) for r in listed])
        true = sorted((r for r, hit in zip(listed, hits) if hit), key=lambda r: int(r["rank"]))
        if true:
            best_rank[query] = int(true[0]["rank"])
        if any(r.get("accepted") == "1" for r in true):
            closed += 1
        elif not true:
            without += 1
        else:
            first_reason[true[0].get("reason") or "not verified"] += 1

    n = len(revisiting)
    deepest = max((int(r["rank"]) for rs in rows.values() for r in rs), default=0)
    ceiling = [f"k={k}: {sum(1 for r in best_rank.values() if r <= k)}"
               for k in (1, 5, 10, 20, 30, 50) if k <= deepest]
    print(f"revisiting scans: {n}")
    print("true candidate within the first k: " + ", ".join(ceiling))
    print(f"closed {closed}, no true candidate {without}, rejected {n - closed - without}: " +
          ", ".join(f"{reason} {count}" for reason, count in first_reason.most_common()))


if __name__ == "__main__":
    main()
