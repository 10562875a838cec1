#!/usr/bin/env bash
# Bag and folder give the same loops on real scans (issue 28): each KITTI-layout sequence given
# (by default the HKU Livox Avia runs in ../shared/data/hku-avia-loops/, absent in CI) is written
# to a ROS 1 bag with its odometry (tests/tools/write_bag.py, Debian's python3-rosbag), read back
# by `detect` and `optimise --odometry-topic`, and compared with the folder: loops.csv must be
# byte-identical. Prints one Markdown row per sequence.
# Usage: bench/bag_parity.sh LIDARLOOP WORK_DIR [SEQUENCE_FOLDER ...]
set -euo pipefail
cli="$1"
work="$2"
shift 2
here="$(cd "$(dirname "$0")/.." && pwd)"
sequences=("$@")
if [ "${#sequences[@]}" -eq 0 ]; then
    sequences=("$here/../shared/data/hku-avia-loops/HKU_1_bag" "$here/../shared/data/hku-avia-loops/HKU_2_bag")
fi
mkdir -p "$work"
echo "| sequence | scans | bag MB | write bag (s) | accepted loops folder / bag | loops.csv | candidates.csv | optimise --odometry-topic |"
echo "|---|---|---|---|---|---|---|---|"
for seq in "${sequences[@]}"; do
    name="$(basename "$seq")"
    bag="$work/$name.bag"
    start=$(date +%s.%N)
    /usr/bin/python3 "$here/tests/tools/write_bag.py" from-kitti "$seq" "$bag" --odometry-topic /odom
    written=$(echo "$(date +%s.%N) - $start" | bc)
    "$cli" detect "$seq" --quiet --overwrite --out "$work/${name}_folder" >/dev/null
    "$cli" detect "$bag" --poses "$seq/poses.txt" --quiet --overwrite --out "$work/${name}_bag" \
        >/dev/null
    accepted() { awk -F, 'NR > 1 && $5 == 1' "$1" | wc -l; }
    same() { if cmp -s "$1" "$2"; then echo identical; else echo DIFFERENT; fi; }
    "$cli" optimise "$bag" --odometry-topic /odom --loops "$work/${name}_bag/loops.csv" \
        --quiet --overwrite --out "$work/${name}_optimised" >/dev/null
    scans=$(find "$seq/velodyne" -name "*.bin" | wc -l)
    printf '| %s | %d | %.1f | %.1f | %d / %d | %s | %s | %s |\n' "$name" "$scans" \
        "$(echo "$(stat -c %s "$bag") / 1048576" | bc -l)" "$written" \
        "$(accepted "$work/${name}_folder/loops.csv")" "$(accepted "$work/${name}_bag/loops.csv")" \
        "$(same "$work/${name}_folder/loops.csv" "$work/${name}_bag/loops.csv")" \
        "$(same "$work/${name}_folder/candidates.csv" "$work/${name}_bag/candidates.csv")" \
        "$(grep -c '' "$work/${name}_optimised/poses_optimised.txt") poses"
done
