#!/usr/bin/env python3
"""The online detector with and without the odometry (docs/BENCHMARK.md, "The online detector
takes the odometry"): every scan of SEQUENCE through lidarloop.LoopDetector (range, verifying),
once alone and once with each scan's pose from SEQUENCE/poses_odometry.txt, which applies the pose
graph's odometry gate and, with --min-gap-metres, counts the gap in metres of path. Writes each
run's loops as OUT.alone.csv and OUT.odometry.csv (query, match, accepted) for
../shared/tools/verified_recall.py, and prints one line per run. --all-candidates turns off
detection.stop_at_first_loop (docs/verification.md, "Stopping at the first loop").

    PYTHONPATH=build/python /usr/bin/python3 bench/online_odometry.py SEQUENCE OUT [--min-gap-metres M]
        [--all-candidates]
"""

import argparse
import csv
import time

import lidarloop


def run(dataset, times, odometry, min_gap_metres, stop_at_first_loop):
    config = {"detection": {"stop_at_first_loop": stop_at_first_loop}}
    if odometry is not None and min_gap_metres is not None:
        detector = lidarloop.LoopDetector(method="range", min_gap=min_gap_metres,
                                          min_gap_unit="metres", config=config)
    else:
        detector = lidarloop.LoopDetector(method="range", config=config)
    loops, mismatches = [], 0
    start = time.process_time()
    for i in range(len(dataset)):
        pose = None if odometry is None else odometry[i]
        query = detector.process(dataset[i], times[i], odometry=pose)
        mismatches += sum(v.reason == "odometry_mismatch" for v in query.verifications)
        if query.loop is not None:
            loops.append((i, query.match, 1))
    return loops, mismatches, (time.process_time() - start) / len(dataset)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("sequence")
    parser.add_argument("out")
    parser.add_argument("--min-gap-metres", type=float, default=None)
    parser.add_argument("--all-candidates", action="store_true")
    args = parser.parse_args()
    dataset = lidarloop.open_dataset(args.sequence)
    times, odometry = lidarloop.read_poses(f"{args.sequence}/poses_odometry.txt")
    for name, poses in (("alone", None), ("odometry", odometry)):
        loops, mismatches, cpu_s = run(dataset, times, poses, args.min_gap_metres,
                                         not args.all_candidates)
        with open(f"{args.out}.{name}.csv", "w", newline="") as file:
            writer = csv.writer(file)
            writer.writerow(["query", "match", "accepted"])
            writer.writerows(loops)
        print(f"{name}: {len(loops)} loops, {mismatches} candidates rejected as odometry_mismatch, "
              f"{cpu_s * 1e3:.1f} ms of CPU per scan")


if __name__ == "__main__":
    main()
