#!/usr/bin/env bash
# Peak resident memory and wall time of `lidarloop detect` and `lidarloop evaluate` against the
# number of scans, on synthetic ~280-point scans (simulate: VLP-16 with 20 azimuth steps, urban,
# uturn). Both run with --no-verify (descriptors only: the cost that grows with the pairs).
# evaluate's ns/pair is its wall time over the n(n-1)/2 pairs (each distance is computed twice,
# once per pass, when the matrix does not fit output.similarity_matrix_mib). Prints one Markdown
# table row per scan count, with evaluate's positive pairs (same place closer than --distance,
# default 10 m): they grow as n^2 here, the same town driven again and again, and evaluate keeps
# them. docs/BENCHMARK.md has the figures.
#
# usage: bench/scale.sh [--method M] [--distance D] [--no-detect] [--no-evaluate] [--work DIR] N ...
#   e.g. bench/scale.sh 1000 10000 100000
# Needs ./build/cli/lidarloop (cmake --preset release) and GNU time (/usr/bin/time). The
# sequences are kept in DIR (default /tmp/lidarloop_scale: 5 MB per 1000 scans) for later runs.
set -euo pipefail
cd "$(dirname "$0")/.."
cli="$PWD/build/cli/lidarloop"
method=range
evaluate=1
detect=1
distance=10
work=/tmp/lidarloop_scale
counts=()
while [ "$#" -gt 0 ]; do
    case "$1" in
        --method) method="$2"; shift 2 ;;
        --no-evaluate) evaluate=0; shift ;;
        --no-detect) detect=0; shift ;;
        --distance) distance="$2"; shift 2 ;;
        --work) work="$2"; shift 2 ;;
        *) counts+=("$1"); shift ;;
    esac
done
[ "${#counts[@]}" -gt 0 ] || counts=(1000 3000 10000 30000 100000)
mkdir -p "$work"

# Runs a command under GNU time; prints "<peak RSS MiB> <wall s>" or "failed <exit code>".
measure() {
    local log="$1"
    shift
    local status=0
    /usr/bin/time -f "%M %e" -o "$log.time" "$@" >"$log" 2>&1 || status=$?
    if [ "$status" -ne 0 ]; then
        echo "failed $status"
        return
    fi
    awk '{ printf "%.0f %s\n", $1 / 1024, $2 }' "$log.time"
}

echo "| scans | detect peak RSS MiB | detect wall s | positives | evaluate peak RSS MiB | evaluate wall s | evaluate ns/pair |"
echo "|---|---|---|---|---|---|---|"
for n in "${counts[@]}"; do
    sequence="$work/sequence_$n"
    if [ ! -f "$sequence/poses.txt" ]; then
        "$cli" simulate --out "$sequence" --scans "$n" --sensor vlp16 --horizontal-steps 20 \
            --overwrite --quiet >/dev/null
    fi
    rm -rf "$work/detect_$n" "$work/evaluate_$n"
    detect_mib="-"
    detect_s="-"
    if [ "$detect" -eq 1 ]; then
        read -r detect_mib detect_s < <(measure "$work/detect_$n.log" "$cli" detect "$sequence" \
            --method "$method" --no-verify --quiet --out "$work/detect_$n")
    fi
    evaluate_mib="-"
    evaluate_s="-"
    evaluate_ns="-"
    if [ "$evaluate" -eq 1 ]; then
        read -r evaluate_mib evaluate_s < <(measure "$work/evaluate_$n.log" "$cli" evaluate \
            "$sequence" --method "$method" --distance "$distance" --no-verify --quiet \
            --out "$work/evaluate_$n")
        if [ "$evaluate_mib" != failed ]; then
            evaluate_ns=$(awk -v s="$evaluate_s" -v n="$n" 'BEGIN { printf "%.0f", s * 1e9 / (n * (n - 1) / 2) }')
        fi
    fi
    positives=$(grep -o '[0-9]* positive pairs' "$work/evaluate_$n.log" 2>/dev/null | cut -d' ' -f1)
    echo "| $n | $detect_mib | $detect_s | ${positives:--} | $evaluate_mib | $evaluate_s | $evaluate_ns |"
done
