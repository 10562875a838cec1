#!/usr/bin/env bash
# Verified loop closures on simulated sequences: every scene with a dense and a sparse sensor on
# the grid route (revisits in the same lane, a lane to the side, in the opposite direction, and
# crossings). Simulates each sequence once into WORK, evaluates it with `lidarloop evaluate`
# (descriptor alone and verified, top-k candidates), and prints one table row per sequence and
# method from metrics.json. Usage:
#   [SEQUENCES=dense|sparse] bench/verification_sweep.sh WORK [SEED] [TOP_K] [-- evaluate flags]
# e.g. bench/verification_sweep.sh /tmp/sweep 1 10
# SEQUENCES=sparse: issue 24's sparse and narrow sensors and a front end's thinning, 300 scans of
# the urban grid route, with hdl64 and vlp16 on the same route for reference.
set -euo pipefail
work="${1:?usage: verification_sweep.sh WORK [SEED] [TOP_K] [-- evaluate flags]}"
seed="${2:-1}"
top_k="${3:-10}"
shift $(($# < 3 ? $# : 3))
[ "${1:-}" = "--" ] && shift
lidarloop="${LIDARLOOP:-$(dirname "$0")/../build/cli/lidarloop}"
mkdir -p "$work"

# scene sensor scans spacing_min spacing_max [simulate flags]
dense=(
    "urban hdl64 420 2 3"
    "urban vlp16 420 2 3"
    "rural hdl64 420 4 6"
    "rural vlp16 420 4 6"
    "mine hdl64 300 0.5 1"
    "mine vlp16 300 0.5 1"
    "indoor hdl64 300 0.4 0.8"
    "indoor vlp16 300 0.4 0.8"
)
sparse=(
    "urban hdl64 300 2 3"
    "urban vlp16 300 2 3"
    "urban hdl32 300 2 3"
    "urban ouster64-wide 300 2 3"
    "urban livox-avia 300 2 3"
    "urban hdl32 300 2 3 --keep-every 10"
    "urban vlp16 300 2 3 --keep-every 4"
    "urban livox-avia 300 2 3 --keep-every 5"
)
case "${SEQUENCES:-dense}" in
    dense) sequences=("${dense[@]}") ;;
    sparse) sequences=("${sparse[@]}") ;;
    *) echo "SEQUENCES must be dense or sparse, got '${SEQUENCES}'" >&2; exit 2 ;;
esac
printf "| sequence | method | revisiting | recall@1 | recall@%s (ceiling) | descriptor true/false | verified true/false/wrong pose | verified recall | verified recall@100%%P | pose error m med/max | yaw deg med/max | ms/pair med |\n" "$top_k"
printf "|---|---|---|---|---|---|---|---|---|---|---|---|\n"
for row in "${sequences[@]}"; do
    read -r scene sensor scans smin smax extra <<<"$row"
    read -ra simulate_flags <<<"${extra:-}"
    suffix="$(tr -d ' -' <<<"${extra:-}")"  # "--keep-every 10" -> "keepevery10"
    name="${scene}_${sensor}${suffix:+_$suffix}_s${seed}"
    data="$work/$name"
    # A sequence made before is reused only when it has the row's number of scans.
    if [ ! -f "$data/poses.txt" ] || ! grep -qx "scans: $scans" "$data/simulation.yaml"; then
        "$lidarloop" simulate --scene "$scene" --sensor "$sensor" --route grid --scans "$scans" \
            --spacing-min-m "$smin" --spacing-max-m "$smax" --seed "$seed" --out "$data" \
            "${simulate_flags[@]}" --overwrite --quiet >/dev/null
    fi
    out="$work/eval_${name}_k${top_k}"
    rm -rf "$out"
    "$lidarloop" evaluate "$data" --top-k "$top_k" --out "$out" --quiet "$@" >/dev/null
    "${PYTHON:-python3}" - "$out/metrics.json" "$name" <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
def pct(x): return "–" if x is None else f"{100 * x:.1f} %"
def mm(d, k):
    s = d["pose_error"][k]
    return "–" if s is None else f"{s['median']:.3f} / {s['max']:.3f}"
for method, e in m["methods"].items():
    r = e.get("retrieval")
    if not r: continue
    d, v = r["descriptor"], r.get("verified") or {}
    ms = r.get("verify_ms_per_pair", {}).get("median")
    print(f"| {sys.argv[2]} | {method} | {d['revisiting_scans']} | {pct(d['recall_at_1'])} | "
          f"{pct(d['recall_at_k'])} | {d['true_loops']}/{d['false_loops']} | "
          f"{v.get('true_loops', '–')}/{v.get('false_loops', '–')}/"
          f"{v.get('wrong_pose_loops', '–')} | {pct(v.get('recall'))} | "
          f"{pct(v.get('recall_at_full_precision'))} | {mm(v, 'translation_m') if v else '–'} | "
          f"{mm(v, 'yaw_deg') if v else '–'} | {'–' if ms is None else f'{ms:.2f}'} |")
PY
done
