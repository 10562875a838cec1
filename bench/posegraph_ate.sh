#!/usr/bin/env bash
# ATE of the simulated odometry and of the optimised trajectory on simulated sequences with loops
# (docs/BENCHMARK.md#pose-graph-optimisation): each sequence is simulated, its loops detected and
# verified (height), and the pose graph optimised. Optionally one along KITTI 00's ground truth.
# Usage: bench/posegraph_ate.sh LIDARLOOP WORK_DIR [KITTI_POSES_00]
set -euo pipefail
cli="$1"
work="$2"
kitti="${3-}"
mkdir -p "$work"
run() {  # NAME SIMULATE_FLAGS... ; prints one Markdown table row
    local name="$1"
    shift
    "$cli" simulate "$@" --sensor vlp16 --horizontal-steps 1024 --overwrite --quiet \
        --out "$work/$name" >/dev/null
    "$cli" optimise "$work/$name" --odometry "$work/$name/poses_odometry.txt" --min-gap 50 \
        --quiet --out "$work/${name}_optimised" >/dev/null
    python3 - "$name" "$work/${name}_optimised/metrics.json" <<'PY'
import json, sys
m = json.load(open(sys.argv[2]))
l = m["loops"]
a, b = m["ate_rmse_m_odometry"], m["ate_rmse_m_optimised"]
print(f"| {sys.argv[1]} | {m['scans']} | {l['accepted']} ({l['false']} false) | {l['used']} "
      f"({l['false_used']} false) | {a:.2f} | {b:.3f} | {a / b:.1f}x | "
      f"{m['rpe_odometry']['rpe_translation_percent']:.2f} -> "
      f"{m['rpe_optimised']['rpe_translation_percent']:.2f} | {m['solver']['seconds']:.2f} |")
PY
}
echo "| sequence | scans | accepted loops | used | ATE odometry (m) | ATE optimised (m) | ratio | RPE % | solve (s) |"
echo "|---|---|---|---|---|---|---|---|---|"
run urban_uturn --scene urban --route uturn --scans 600 --seed 2
run urban_grid --scene urban --route grid --scans 600 --seed 3 --spacing-min-m 2.5 --spacing-max-m 3.5
run rural_figure8 --scene rural --route figure8 --scans 600 --seed 4 --spacing-min-m 2 --spacing-max-m 3
run mine_grid --scene mine --route grid --scans 600 --seed 5
if [ -n "$kitti" ]; then run kitti00 --scene urban --trajectory "$kitti" --seed 1; fi
