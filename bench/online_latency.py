#!/usr/bin/env python3
"""The online detector's latency: every scan of SEQUENCE through lidarloop.LoopDetector (range,
verifying, the default top 10), timing each process() call in wall and process CPU time, once
per mode: the default (up to the first loop, as many candidates at once as TBB has threads) and
--all-candidates (every candidate, in parallel). Reading the scans is excluded. Prints, per mode,
the median and 95th percentile of the wall time over the scans that had candidates, the mean CPU
time per scan and the scans with a loop. Run it under `taskset -c 0` for one thread.

    PYTHONPATH=build/python /usr/bin/python3 bench/online_latency.py SEQUENCE [--all-candidates]
"""

import argparse
import time

import numpy as np

import lidarloop


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("sequence")
    parser.add_argument("--all-candidates", action="store_true")
    args = parser.parse_args()
    dataset = lidarloop.open_dataset(args.sequence)
    scans = [dataset[i] for i in range(len(dataset))]
    detector = lidarloop.LoopDetector(method="range",
                                      stop_at_first_loop=not args.all_candidates)
    wall_ms, loops = [], 0
    cpu_start = time.process_time()
    for points in scans:
        start = time.perf_counter()
        query = detector.process(points)
        elapsed_ms = (time.perf_counter() - start) * 1e3
        if query.candidates:
            wall_ms.append(elapsed_ms)
        loops += query.loop is not None
    cpu_ms = (time.process_time() - cpu_start) * 1e3 / len(scans)
    mode = "every candidate" if args.all_candidates else "up to the first loop"
    print(f"{mode}: wall median {np.median(wall_ms):.1f} ms, p95 "
          f"{np.percentile(wall_ms, 95):.1f} ms over {len(wall_ms)} scans with candidates; "
          f"CPU {cpu_ms:.1f} ms a scan; {loops} scans with a loop")


if __name__ == "__main__":
    main()
