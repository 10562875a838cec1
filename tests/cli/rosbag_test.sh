#!/usr/bin/env bash
# ROS 1 bags in (issue 28): a bag written from a simulated sequence gives byte-identical results to
# the folder, in every cloud layout; bag-info, scan references, odometry from the bag; and every
# kind of bad bag is a one-line error naming the file and the topic.
# Usage: rosbag_test.sh LIDARLOOP WRITE_BAG_PY   (WRITE_BAG_PY runs with /usr/bin/python3)
set -u
if [ "$#" -ne 2 ]; then
    echo "usage: $0 LIDARLOOP WRITE_BAG_PY" >&2
    exit 2
fi
cli="$1"
write_bag=(/usr/bin/python3 "$2")
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
passed=0
failed=0
pass() { passed=$((passed + 1)); }
fail() { failed=$((failed + 1)); echo "FAIL: $*"; }

# expect_ok NAME PHRASE CMD...: exit 0 and stdout contains PHRASE.
expect_ok() {
    local name="$1" phrase="$2" out
    shift 2
    if out="$("$@" 2>"$work/stderr")" && grep -qF -- "$phrase" <<<"$out"; then pass; else
        fail "$name: expected success with '$phrase'; got: $out $(cat "$work/stderr")"
    fi
}

# expect_error NAME CMD...: exit code 1 and one stderr line holding every phrase of PHRASES
# (a |-separated list, set before the call).
expect_error() {
    local name="$1" phrase
    shift
    "$@" >"$work/stdout" 2>"$work/stderr"
    local code=$?
    if [ "$code" -ne 1 ] || [ "$(wc -l <"$work/stderr")" -ne 1 ]; then
        fail "$name: expected one error line and exit code 1, got $code: $(head -c 400 "$work/stderr")"
        return
    fi
    IFS='|' read -ra wanted <<<"$PHRASES"
    for phrase in "${wanted[@]}"; do
        if ! grep -qF -- "$phrase" "$work/stderr"; then
            fail "$name: error message lacks '$phrase': $(cat "$work/stderr")"
            return
        fi
    done
    pass
}

# expect_same NAME A B: the two files are byte-identical.
expect_same() {
    if cmp -s "$2" "$3"; then pass; else fail "$1: $2 and $3 differ"; fi
}

# --- the same scans from a folder and from bags give byte-identical results -------------------
seq="$work/seq"
"$cli" simulate --scene urban --route uturn --sensor vlp16 --scans 60 --horizontal-steps 360 \
    --quiet --out "$seq" >/dev/null
"${write_bag[@]}" from-kitti "$seq" "$work/run.bag" --odometry-topic /odom
"${write_bag[@]}" from-kitti "$seq" "$work/run64.bag" --float64 --organised --compression bz2 \
    --topic /velodyne_points
"${write_bag[@]}" from-kitti "$seq" "$work/runlz4.bag" --compression lz4
expect_ok "detect folder" "60 scans (kitti)" "$cli" detect "$seq" --quiet --out "$work/folder"
if [ "$(awk -F, 'NR > 1 && $5 == 1' "$work/folder/loops.csv" | wc -l)" -ge 1 ]; then pass; else
    fail "the simulated sequence has no accepted loop: the comparison would prove little"
fi
expect_ok "detect bag" "60 scans (rosbag)" "$cli" detect "$work/run.bag" --poses "$seq/poses.txt" \
    --quiet --out "$work/bag"
expect_same "loops.csv of folder and bag" "$work/folder/loops.csv" "$work/bag/loops.csv"
expect_same "candidates.csv of folder and bag" "$work/folder/candidates.csv" \
    "$work/bag/candidates.csv"
# The other encodings without verification: equal descriptors already mean equal points.
expect_ok "detect folder without verification" "60 scans" "$cli" detect "$seq" --no-verify \
    --quiet --out "$work/folder_nv"
expect_ok "detect float64 organised bz2 bag" "60 scans (rosbag)" "$cli" detect "$work/run64.bag" \
    --poses "$seq/poses.txt" --quiet --no-verify --out "$work/bag64"
expect_same "loops.csv of folder and float64 bag" "$work/folder_nv/loops.csv" \
    "$work/bag64/loops.csv"
expect_ok "detect lz4 bag" "60 scans (rosbag)" "$cli" detect "$work/runlz4.bag" --topic /points \
    --poses "$seq/poses.txt" --quiet --no-verify --out "$work/baglz4"
expect_same "loops.csv of folder and lz4 bag" "$work/folder_nv/loops.csv" "$work/baglz4/loops.csv"

# --- bag-info, scan references, odometry from the bag ------------------------------------------
expect_ok "bag-info" "/odom    nav_msgs/Odometry        60" "$cli" bag-info "$work/run.bag"
expect_ok "bag-info clouds" "/points  sensor_msgs/PointCloud2  60" "$cli" bag-info "$work/run.bag"
"$cli" describe "$seq/velodyne/000007.bin" >"$work/describe_file.json"
"$cli" describe "$work/run64.bag:/velodyne_points:7" >"$work/describe_bag.json"
expect_same "describe a scan of a bag" "$work/describe_file.json" "$work/describe_bag.json"
expect_ok "verify scans of a bag" '"accepted"' "$cli" verify "$work/run.bag::55" "$work/run.bag::5"
# A gap in metres of the path on the bag's odometry, as on the folder's odometry file.
expect_ok "detect, gap on the bag's odometry" "60 scans (rosbag)" "$cli" detect "$work/run.bag" \
    --odometry-topic /odom --min-gap 20 --min-gap-unit metres --no-verify --quiet --out "$work/gap_bag"
"$cli" detect "$seq" --odometry "$seq/poses_odometry.txt" --min-gap 20 --min-gap-unit metres \
    --no-verify --quiet --out "$work/gap_folder" >/dev/null
# path_m went through quaternions only in rotation: the same loops; path_m to rounding.
if [ "$(cut -d, -f1-5 "$work/gap_bag/loops.csv")" = "$(cut -d, -f1-5 "$work/gap_folder/loops.csv")" ]
then pass; else fail "detect with a gap in metres: the bag's odometry gives other loops"; fi
expect_ok "optimise with the bag's odometry" "ATE RMSE: odometry" "$cli" optimise "$work/run.bag" \
    --poses "$seq/poses.txt" --odometry-topic /odom --loops "$work/bag/loops.csv" --out "$work/opt"
if grep -qF "topic '/odom'" "$work/opt/report.md"; then pass; else
    fail "optimise's report.md does not name the odometry topic"
fi
"$cli" optimise "$seq" --odometry "$seq/poses_odometry.txt" --loops "$work/bag/loops.csv" \
    --out "$work/opt_folder" >/dev/null
# The bag's odometry went through quaternions: the same poses to rounding.
if paste -d' ' "$work/opt/poses_optimised.txt" "$work/opt_folder/poses_optimised.txt" |
    awk '{ for (k = 1; k <= 12; ++k) { d = $k - $(k + 12); if (d > 1e-6 || d < -1e-6) bad = 1 } }
         END { exit bad }'; then pass; else
    fail "optimise from the bag's odometry differs from the folder's by more than 1e-6"
fi

# --- bad input: one line naming the file and the topic -----------------------------------------
for name in wrong-type no-xyz no-clouds two-clouds short-odometry big-endian; do
    "${write_bag[@]}" case "$name" "$work/$name.bag"
done
PHRASES="wrong-type.bag: topic '/points' holds 'nav_msgs/Odometry', not sensor_msgs/PointCloud2"
expect_error "topic of the wrong type" "$cli" detect "$work/wrong-type.bag" --topic /points \
    --out "$work/x"
PHRASES="no-xyz.bag: topic '/points' message |: the cloud has no field z (fields: 'x y intensity_2 intensity')"
expect_error "cloud without z" "$cli" detect "$work/no-xyz.bag" --quiet --out "$work/x"
PHRASES="no-clouds.bag: has 0 sensor_msgs/PointCloud2 topics (none)"
expect_error "bag without clouds" "$cli" detect "$work/no-clouds.bag" --out "$work/x"
PHRASES="no-clouds.bag: has no topic '/points'"
expect_error "absent topic" "$cli" detect "$work/no-clouds.bag" --topic /points --out "$work/x"
PHRASES="two-clouds.bag: has 2 sensor_msgs/PointCloud2 topics ('/front', '/rear'); name one with --topic"
expect_error "two cloud topics" "$cli" detect "$work/two-clouds.bag" --out "$work/x"
expect_ok "two cloud topics, one named" "5 scans (rosbag)" "$cli" detect "$work/two-clouds.bag" \
    --topic /rear --min-gap 1 --quiet --out "$work/rear"
PHRASES="short-odometry.bag: odometry topic '/odom': the odometry covers 101.000000 s to 104.000000 s, but scan 0 is at 100.000000 s"
expect_error "odometry not covering the scans" "$cli" optimise "$work/short-odometry.bag" \
    --odometry-topic /odom --min-gap 1 --out "$work/x"
PHRASES="big-endian.bag: topic '/points' message 0: the cloud is big-endian"
expect_error "big-endian cloud" "$cli" describe "$work/big-endian.bag:/points:0"
head -c 3000 "$work/run.bag" >"$work/truncated.bag"
PHRASES="truncated.bag: "
expect_error "truncated bag" "$cli" detect "$work/truncated.bag" --out "$work/x"
expect_error "truncated bag, bag-info" "$cli" bag-info "$work/truncated.bag"
# Damage to the record structure (the bag header, a chunk's header and its compression field),
# which lidarloop checks before rosbag_storage trusts it, and to compressed data, which
# rosbag_storage's decompression notices.
for offset in 20 4121 4133; do
    cp "$work/run.bag" "$work/corrupt.bag"
    printf '\377\377\377\377\377\377\377\377' |
        dd of="$work/corrupt.bag" bs=1 seek="$offset" conv=notrunc status=none
    PHRASES="corrupt.bag: damaged bag at byte"
    expect_error "bag damaged at byte $offset" "$cli" detect "$work/corrupt.bag" --quiet \
        --out "$work/x"
done
cp "$work/runlz4.bag" "$work/corrupt.bag"
printf '\377\377\377\377\377\377\377\377' |
    dd of="$work/corrupt.bag" bs=1 seek=5133 conv=notrunc status=none
PHRASES="corrupt.bag: topic '/points': not a readable ROS 1 bag (ROSLZ4_"
expect_error "lz4 data damaged" "$cli" detect "$work/corrupt.bag" --quiet --out "$work/x"
echo "not a bag" >"$work/text.bag"
PHRASES="text.bag: not a ROS 1 bag of format 2.0 (it does not start with '#ROSBAG V2.0')"
expect_error "text file named .bag" "$cli" bag-info "$work/text.bag"
PHRASES="missing.bag: no such bag"
expect_error "missing bag" "$cli" detect "$work/missing.bag" --out "$work/x"
PHRASES="run.bag: topic '/points' has 60 messages, no 60"
expect_error "scan index past the topic" "$cli" describe "$work/run.bag:/points:60"
PHRASES="INDEX 'seven' is no message number"
expect_error "scan index not a number" "$cli" describe "$work/run.bag:/points:seven"
PHRASES="is a folder; a topic ('/points') names the scans of a ROS bag"
expect_error "topic for a folder" "$cli" detect "$seq" --topic /points --out "$work/x"
PHRASES="needs a bag"
expect_error "odometry topic for a folder" "$cli" optimise "$seq" --odometry-topic /odom \
    --loops "$work/bag/loops.csv" --out "$work/x"
PHRASES="give --odometry FILE, or --odometry-topic TOPIC"
expect_error "optimise without odometry" "$cli" optimise "$work/run.bag" \
    --loops "$work/bag/loops.csv" --out "$work/x"

echo "cli rosbag: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
