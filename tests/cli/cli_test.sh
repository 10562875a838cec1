#!/usr/bin/env bash
# CLI smoke and bad-input tests in named sections, one CTest case each (cli.<section>).
# Usage: cli_test.sh LIDARLOOP SAMPLES_DIR COMMITTED_SAMPLES_DIR SECTION...
#        cli_test.sh --list   prints the section names, one a line (tests/cli/CMakeLists.txt
#                             registers one test per name)
# SECTION is one of the names --list prints, or "all". Each section makes the files it needs in a
# folder of its own, so any one runs alone. Every case checks the exit code and a phrase of the
# output; the last line is "cli <sections>: N passed, N failed".
set -u
sections=(describe distance ndt scancontext verify detect bench demo evaluate dump-config bad-input simulate
    optimise map results-folders errors loops path-gap)
if [ "${1-}" = "--list" ]; then
    printf '%s\n' "${sections[@]}"
    exit 0
fi
if [ "$#" -lt 4 ]; then
    echo "usage: $0 LIDARLOOP SAMPLES_DIR COMMITTED_SAMPLES_DIR SECTION... (or --list)" >&2
    exit 2
fi
cli="$1"
samples="$2"
committed="$3"
shift 3
root="$(mktemp -d)"
trap 'rm -rf "$root"' EXIT
work="$root"  # the running section's own folder, set by run_section
passed=0
failed=0

pass() { passed=$((passed + 1)); }
fail() { failed=$((failed + 1)); echo "FAIL: $*"; }

# expect_ok NAME PHRASE CMD...: exit 0 and stdout contains PHRASE.
expect_ok() {
    local name="$1" phrase="$2"
    shift 2
    local out
    if out="$("$@" 2>"$work/stderr")" && grep -qF -- "$phrase" <<<"$out"; then
        pass
    else
        fail "$name: expected success with '$phrase'; got: $out $(cat "$work/stderr")"
    fi
}

# expect_error NAME PHRASE CMD...: non-zero exit (not a crash), one stderr line containing PHRASE.
expect_error() {
    local name="$1" phrase="$2"
    shift 2
    "$@" >"$work/stdout" 2>"$work/stderr"
    local code=$?
    if [ "$code" -eq 0 ] || [ "$code" -ge 128 ]; then
        fail "$name: expected a clean error exit, got code $code: $(cat "$work/stderr")"
    elif ! grep -qF -- "$phrase" "$work/stderr"; then
        fail "$name: error message lacks '$phrase': $(cat "$work/stderr")"
    else
        pass
    fi
}

# expect_exit_1 NAME PHRASE CMD...: exit code exactly 1 (docs/cli.md) and one stderr line
# containing PHRASE.
expect_exit_1() {
    local name="$1" phrase="$2"
    shift 2
    "$@" >"$work/stdout" 2>"$work/stderr"
    local code=$?
    if [ "$code" -ne 1 ]; then
        fail "$name: expected exit code 1, got $code: $(head -c 300 "$work/stderr")"
    elif [ "$(wc -l <"$work/stderr")" -ne 1 ] || ! grep -qF -- "$phrase" "$work/stderr"; then
        fail "$name: expected one stderr line with '$phrase': $(head -c 300 "$work/stderr")"
    else
        pass
    fi
}

# make_sequence DIR: a folder dataset of 8 scans without poses: scans 0-5 are copies of one scan,
# 6 is the same place seen from elsewhere, 7 another place.
make_sequence() {
    mkdir -p "$1"
    for i in 0 1 2 3 4 5; do cp "$samples/corner_a.bin" "$1/scan$i.bin"; done
    cp "$samples/corner_b.ply" "$1/scan6.ply"
    cp "$samples/courtyard.bin" "$1/scan7.bin"
}

# alone_yaml FILE: a detect configuration verifying each scan alone, without submaps.
alone_yaml() {
    printf 'verification:\n  reduction:\n    submap_path_m: 0\n' >"$1"
}

# --- describe: every format gives the same histogram for the same scan -----------------------
section_describe() {
    reference="$("$cli" describe "$samples/corner_a.bin")"
    for scan in corner_a.pcd corner_a_ascii.pcd corner_a_binary.pcd corner_a_ascii.ply \
        corner_a_le64.ply corner_a_be.ply corner_a.xyz; do
        if [ "$("$cli" describe "$samples/$scan")" = "$reference" ]; then pass; else
            fail "describe $scan differs from the .bin of the same scan"
        fi
    done
    expect_ok "describe osnabrueck" '"method":"range"' "$cli" describe "$samples/scan000.3d"
    expect_ok "describe json keys" '"points_used":6000' "$cli" describe "$samples/corner_a.bin"
    expect_ok "describe skipped" '"points_skipped":0' "$cli" describe "$samples/corner_a.bin"
    expect_ok "describe range" '"method":"range"' "$cli" describe --method range --bins 10 \
        --min 0 --max 50 "$samples/corner_a.bin"
    expect_ok "describe pca" '"up":[' "$cli" describe --method height --up pca "$samples/corner_b.ply"
    expect_error "up with range" "applies to the height method only" "$cli" describe --up pca \
        "$samples/corner_b.ply"
    bins="$("$cli" describe --bins 7 "$samples/corner_a.bin" | grep -o '"bins":\[[^]]*\]' |
        tr -cd , | wc -c)"
    if [ "$bins" -eq 6 ]; then pass; else fail "--bins 7 gave $((bins + 1)) buckets"; fi
}

# --- distance --------------------------------------------------------------------------------
section_distance() {
    same="$("$cli" distance "$samples/corner_a.pcd" "$samples/corner_a.bin")"
    if [ "$same" = "0" ]; then pass; else fail "distance of a scan to itself is $same, not 0"; fi
    near="$("$cli" distance "$samples/corner_a.pcd" "$samples/corner_b.ply")"
    far="$("$cli" distance "$samples/corner_a.pcd" "$samples/courtyard.bin")"
    if awk -v n="$near" -v f="$far" 'BEGIN { exit !(n > 0 && n < f && f <= 1) }'; then pass; else
        fail "expected 0 < W(same place)=$near < W(other place)=$far <= 1"
    fi
    for method in height range; do
        expect_ok "distance $method" "." "$cli" distance --method "$method" \
            "$committed/corner_a.pcd" "$committed/courtyard.bin"
    done
}

# --- verify: one pair, registered without a prior, as JSON --------------------------------------
section_verify() {
    expect_ok "verify same place" '"accepted": true' "$cli" verify "$samples/corner_b.ply" \
        "$samples/corner_a.bin"
    # T_match_query is 4x4 nested row-major lists with a last row 0 0 0 1, and the reason is none.
    if "$cli" verify "$samples/corner_b.ply" "$samples/corner_a.bin" | python3 -c '
import json, sys
v = json.load(sys.stdin)
T = v["T_match_query"]
assert len(T) == 4 and all(len(row) == 4 for row in T), T
assert T[3] == [0, 0, 0, 1], T[3]
assert v["reason"] == "none" and 0 < v["overlap"] <= 1 and v["rmse_m"] >= 0, v
'; then pass; else fail "verify JSON of a true pair is malformed"; fi
    expect_ok "verify other place" '"accepted": false' "$cli" verify "$samples/courtyard.bin" \
        "$samples/corner_a.bin"
    printf '1 2 3\n1 2 3\n' >"$work/two.xyz"
    expect_ok "verify too few points" '"reason": "too_few_points"' "$cli" verify "$work/two.xyz" \
        "$samples/corner_a.bin"
    expect_error "verify missing file" "nothing.bin" "$cli" verify "$work/nothing.bin" \
        "$samples/corner_a.bin"
    printf 'verification:\n  acceptance:\n    min_overlap: 2\n' >"$work/bad.yaml"
    expect_error "verify bad config" "min_overlap" "$cli" verify --config "$work/bad.yaml" \
        "$samples/corner_b.ply" "$samples/corner_a.bin"
}

# --- NDT (Magnusson 2009): describe and distance ---------------------------------------------
section_ndt() {
    expect_ok "describe ndt" '"method":"ndt"' "$cli" describe --method ndt "$samples/corner_a.bin"
    expect_ok "describe ndt matrix" '"F":[[' "$cli" describe --method ndt "$samples/corner_a.bin"
    ndt_same="$("$cli" distance --method ndt "$samples/corner_a.pcd" "$samples/corner_a.bin")"
    if [ "$ndt_same" = "0" ]; then pass; else fail "ndt sigma' of a scan to itself is $ndt_same"; fi
    ndt_near="$("$cli" distance --method ndt "$samples/corner_a.pcd" "$samples/corner_b.ply")"
    ndt_far="$("$cli" distance --method ndt "$samples/corner_a.pcd" "$samples/courtyard.bin")"
    if awk -v n="$ndt_near" -v f="$ndt_far" 'BEGIN { exit !(n > 0 && n < f) }'; then pass; else
        fail "expected 0 < sigma'(same place)=$ndt_near < sigma'(other place)=$ndt_far"
    fi
    printf 'method: ndt\nndt:\n  cell_size_m: 1.0\n  planar_classes: 4\n' >"$work/ndt.yaml"
    expect_ok "ndt from config" '"method":"ndt"' "$cli" describe --config "$work/ndt.yaml" \
        "$samples/corner_a.bin"
    printf 'ndt:\n  cell_size_m: 0\n' >"$work/ndt_bad.yaml"
    expect_error "ndt absurd cell size" "ndt.cell_size_m must be in" "$cli" describe --method ndt \
        --config "$work/ndt_bad.yaml" "$samples/corner_a.bin"
    expect_error "histogram flag with ndt" \
        "--bins applies to the height and range methods, not ndt: its parameters have flags --ndt-" \
        "$cli" describe --method ndt --bins 10 "$samples/corner_a.bin"
    # The flags of the ndt section, derived from its declaration like --scancontext-*.
    ndt_config="$("$cli" describe --config "$work/ndt.yaml" "$samples/corner_a.bin")"
    ndt_flags="$("$cli" describe --method ndt --ndt-cell-size-m 1.0 --ndt-planar-classes 4 \
        "$samples/corner_a.bin")"
    if [ -n "$ndt_flags" ] && [ "$ndt_flags" = "$ndt_config" ]; then pass; else
        fail "--ndt-cell-size-m 1.0 --ndt-planar-classes 4 differ from the same keys in --config"
    fi
    expect_error "ndt flag out of range" \
        "--ndt-cell-size-m: ndt.cell_size_m must be in [0.01, 100], got 0" "$cli" describe \
        --method ndt --ndt-cell-size-m 0 "$samples/corner_a.bin"
    expect_error "ndt open range" "ndt.eigen_ratio_threshold must be in (0, 1), got 1" "$cli" \
        describe --method ndt --ndt-eigen-ratio-threshold 1 "$samples/corner_a.bin"
    expect_error "ndt flag with another method" "--ndt-cell-size-m applies to the ndt method" \
        "$cli" describe --method range --ndt-cell-size-m 1 "$samples/corner_a.bin"
    expect_ok "ndt flags in help" "--ndt-range-limits-m [FLOAT,...]" "$cli" describe --help
    expect_ok "ndt in dump-config --markdown" '| `ndt.cell_size_m` | 0.5 |' "$cli" dump-config \
        --markdown
    printf '1 2 3\n1 2 3\n' >"$work/two.xyz"
    expect_error "ndt too few points" "two.xyz: no NDT cell could be classified" "$cli" describe \
        --method ndt "$work/two.xyz"
}

# --- scancontext: describe, distance, config section, detect -----------------------------------
section_scancontext() {
    expect_ok "describe scancontext" '"ring_key":[' "$cli" describe --method scancontext \
        "$samples/corner_a.bin"
    sc_same="$("$cli" distance --method scancontext "$samples/corner_a.pcd" "$samples/corner_a.bin")"
    if [ "$sc_same" = "0" ]; then pass; else fail "scancontext distance to itself is $sc_same"; fi
    sc_near="$("$cli" distance --method scancontext "$samples/corner_a.pcd" "$samples/corner_b.ply")"
    sc_far="$("$cli" distance --method scancontext "$samples/corner_a.pcd" "$samples/courtyard.bin")"
    if awk -v n="$sc_near" -v f="$sc_far" 'BEGIN { exit !(n > 0 && n < f && f <= 1) }'; then pass
    else fail "expected 0 < d(same place)=$sc_near < d(other place)=$sc_far <= 1"; fi
    printf 'method: scancontext\nscancontext:\n  rings: 10\n  sectors: 30\n' >"$work/sc.yaml"
    expect_ok "scancontext from config" '"sectors":30' "$cli" describe --config "$work/sc.yaml" \
        "$samples/corner_a.bin"
    printf 'scancontext:\n  rings: 0\n' >"$work/sc_bad.yaml"
    expect_error "scancontext absurd rings" "scancontext.rings must be in [1, 200], got 0" "$cli" \
        describe --method scancontext --config "$work/sc_bad.yaml" "$samples/corner_a.bin"
    printf 'scancontext:\n  ringz: 3\n' >"$work/sc_unknown.yaml"
    expect_error "scancontext unknown key" "scancontext.ringz" "$cli" describe \
        --config "$work/sc_unknown.yaml" "$samples/corner_a.bin"
    expect_error "histogram flag with scancontext" "--bins applies to the height and range" \
        "$cli" describe --method scancontext --bins 10 "$samples/corner_a.bin"
    expect_ok "dump-config scancontext" "ring_key_candidates: 0" "$cli" dump-config
    # A flag per declared parameter (docs/options.md), read and checked as its key in --config.
    expect_ok "scancontext flags" '"sectors":30' "$cli" describe --method scancontext \
        --scancontext-rings 10 --scancontext-sectors 30 "$samples/corner_a.bin"
    expect_error "scancontext flag out of range" \
        "--scancontext-rings: scancontext.rings must be in [1, 200], got 0" "$cli" describe \
        --method scancontext --scancontext-rings 0 "$samples/corner_a.bin"
    expect_error "scancontext flag not a number" "key 'scancontext.rings': expected an integer" \
        "$cli" describe --method scancontext --scancontext-rings ten "$samples/corner_a.bin"
    expect_error "scancontext flag with another method" \
        "--scancontext-rings applies to the scancontext method" "$cli" describe --method range \
        --scancontext-rings 10 "$samples/corner_a.bin"
    expect_ok "scancontext flags in help" "--scancontext-ring-key-candidates" "$cli" detect --help
    expect_ok "dump-config --markdown" '| `scancontext.rings` | 20 |' "$cli" dump-config --markdown
    seq="$work/seq"
    make_sequence "$seq"
    alone_yaml "$work/alone.yaml"
    expect_ok "detect scancontext" "method scancontext" "$cli" detect "$seq" --method scancontext \
        --min-gap 2 --config "$work/alone.yaml" --quiet --out "$work/det_sc"
    # Scan 3 is a copy of scan 0: at distance 0, verified at the identity pose.
    if grep -q "^3,0,0,,1,1,0,0,0,0,0,0,1," "$work/det_sc/loops.csv"; then pass; else
        fail "scancontext: scan 3 (a copy of scan 0) is not a verified loop: $(cat "$work/det_sc/loops.csv")"
    fi
}

# --- detect over a small sequence ------------------------------------------------------------
section_detect() {
    seq="$work/seq"
    make_sequence "$seq"
    # Scans 0-5, copies of one scan, are one piece of the chain of each scan registered to the
    # one before (no odometry): 0 m of path apart, the recent past, so no candidates of each
    # other. The checks of a verified identity loop below verify each scan alone.
    expect_ok "detect, submaps from the neighbours" "8 scans (folder)" "$cli" detect "$seq" \
        --min-gap 2 --out "$work/det_chain"
    if grep -qF "placed by each scan's registration to the one before" "$work/stderr"; then
        pass
    else fail "detect without odometry does not say that the neighbours place submaps"; fi
    if grep -q "^3,[0-9]*,[0-2]," "$work/det_chain/candidates.csv"; then
        fail "scan 3 has a copy of its recent past as a candidate: $(cat "$work/det_chain/candidates.csv")"
    else pass; fi
    if grep -q "submap_path_m: 10" "$work/det_chain/config.yaml"; then pass; else
        fail "config.yaml does not record the submaps"
    fi
    alone_yaml "$work/alone.yaml"
    expect_ok "detect" "8 scans (folder)" "$cli" detect "$seq" --min-gap 2 \
        --config "$work/alone.yaml" --quiet --out "$work/det"
    for file in loops.csv candidates.csv similarity.png similarity_distance.png similarity.bin \
        database.lldb database.scans config.yaml timings.json; do
        if [ -s "$work/det/$file" ]; then pass; else fail "detect did not write $file"; fi
    done
    verified_header="query,match,distance,second_ratio,accepted,rank,tx,ty,tz,qx,qy,qz,qw"
    verified_header+=",overlap_query,overlap_match,distinctive_query,distinctive_match,rmse_m"
    verified_header+=",shifted_overlap,reason,path_m"  # path_m empty: the folder has no poses
    if head -1 "$work/det/loops.csv" | grep -qx "$verified_header"; then
        pass
    else fail "loops.csv header: $(head -1 "$work/det/loops.csv")"; fi
    # Scan 3 is a copy of scan 0: verified at the identity pose.
    if grep -q "^3,0,0,,1,1,0,0,0,0,0,0,1,1,1,[^,]*,[^,]*,0,[^,]*,none,$" "$work/det/loops.csv"; then
        pass
    else
        fail "scan 3 (a copy of scan 0) is not a verified loop: $(cat "$work/det/loops.csv")"
    fi
    if head -1 "$work/det/candidates.csv" |
        grep -qx "query,rank,match,distance,accepted,${verified_header#*rank,}"; then
        pass
    else fail "candidates.csv header: $(head -1 "$work/det/candidates.csv")"; fi
    expect_ok "detect --no-verify" "8 scans (folder)" "$cli" detect "$seq" --min-gap 2 --quiet \
        --no-verify --out "$work/det_descriptor"
    if head -1 "$work/det_descriptor/loops.csv" |
        grep -qx "query,match,distance,second_ratio,accepted,path_m"; then
        pass
    else fail "--no-verify loops.csv header: $(head -1 "$work/det_descriptor/loops.csv")"; fi
    if grep -q "^3,0,0,.*,1,$" "$work/det_descriptor/loops.csv"; then pass; else
        fail "--no-verify: scan 3 is not an accepted loop: $(cat "$work/det_descriptor/loops.csv")"
    fi
    if grep -q "min_gap: 2" "$work/det/config.yaml"; then pass; else
        fail "config.yaml lacks the gap"
    fi
    expect_ok "detect ndt" "method ndt" "$cli" detect "$seq" --method ndt --min-gap 2 --quiet \
        --out "$work/det_ndt"
    # The effective config leaves the threshold to the method unless one is given, so that it
    # can be reused with another method.
    if grep -q "^  threshold: default" "$work/det_ndt/config.yaml"; then pass; else
        fail "detect --method ndt: config.yaml does not leave the threshold default"
    fi
    expect_ok "detect ndt --threshold" "threshold 0.02," "$cli" detect "$seq" --method ndt \
        --min-gap 2 --threshold 0.02 --quiet --out "$work/det_ndt_t"
    # Localisation against the saved map: every scan finds itself (or an identical copy) at
    # distance 0.
    expect_ok "detect --map" "localised against the map" "$cli" detect "$seq" \
        --map "$work/det/database.lldb" --threshold 0.001 --quiet --out "$work/loc"
    if [ "$(grep -c '^[0-9]*,[0-9]*,0,[^,]*,1,.*,none,$' "$work/loc/loops.csv")" -eq 8 ]; then pass; else
        fail "localisation did not match every scan at distance 0: $(cat "$work/loc/loops.csv")"
    fi
    if grep -q "^6,6,0," "$work/loc/loops.csv" && grep -q "^7,7,0," "$work/loc/loops.csv"; then
        pass
    else
        fail "the unique scans 6 and 7 did not find themselves: $(cat "$work/loc/loops.csv")"
    fi
    if grep -q "threshold: 0.001" "$work/loc/config.yaml"; then pass; else
        fail "the localisation config lacks the --threshold"
    fi
    expect_ok "detect --map ndt" "method ndt" "$cli" detect "$seq" \
        --map "$work/det_ndt/database.lldb" --quiet --out "$work/loc_ndt"
    # A map keeps the threshold of the detection that made it, as the default for localising.
    expect_ok "detect --map keeps its threshold" "threshold 0.02," "$cli" detect "$seq" \
        --map "$work/det_ndt_t/database.lldb" --quiet --out "$work/loc_ndt_t"
    expect_ok "detect --map of 0.1" "threshold 0.004," "$cli" detect "$seq" --no-verify \
        --map "$(dirname "$committed")/legacy/database_v0.1.lldb" --quiet --out "$work/loc_v01"
    # A map without prepared scans cannot verify: a clear error, not descriptor-only loops.
    expect_error "detect --map without scans" "has no prepared scans" "$cli" detect "$seq" \
        --map "$(dirname "$committed")/legacy/database_v0.1.lldb" --quiet --out "$work/loc_v01b"
    expect_error "detect --map with --bins" "--bins changes how scans are described" "$cli" detect \
        "$seq" --map "$work/det/database.lldb" --bins 10 --quiet --out "$work/loc2"
    head -c 100 "$work/det/database.lldb" >"$work/truncated.lldb"
    expect_error "detect --map truncated" "truncated.lldb" "$cli" detect "$seq" \
        --map "$work/truncated.lldb" --quiet --out "$work/loc3"
    printf 'garbage' >"$seq/scan3.bin"
    expect_error "detect bad scan" "scan 3: $seq/scan3.bin" "$cli" detect "$seq" --quiet \
        --out "$work/det2"
    expect_ok "detect --skip-bad" "1 skipped" "$cli" detect "$seq" --skip-bad --quiet --min-gap 2 \
        --out "$work/det3"
    # The results line names what the run wrote, as run.json lists it.
    expect_ok "detect names its files" "database.scans, loops.csv, similarity.bin" "$cli" detect \
        "$seq" --skip-bad --quiet --min-gap 2 --out "$work/det3" --overwrite
    if grep -q "skipped.txt, timings.json)" <<<"$("$cli" detect "$seq" --skip-bad --quiet \
        --min-gap 2 --out "$work/det3" --overwrite)"; then pass; else
        fail "detect's results line omits skipped.txt"
    fi
    if grep -q "scan3.bin" "$work/det3/skipped.txt"; then pass; else
        fail "skipped.txt lacks scan3"
    fi
    if grep -q "^3," "$work/det3/loops.csv"; then fail "a skipped scan got a match"; else pass; fi
    rm "$seq/scan3.bin"
    # Results folders never lie: a clean run into det3 leaves no stale skipped.txt, a failed run
    # no results, and run.json says how each ended.
    expect_ok "detect into the same folder" "7 scans" "$cli" detect "$seq" --min-gap 2 --quiet \
        --no-verify --out "$work/det3"
    if [ -e "$work/det3/skipped.txt" ]; then fail "a stale skipped.txt survived"; else pass; fi
    if grep -q '"status": "complete"' "$work/det3/run.json"; then pass; else
        fail "run.json does not say complete"
    fi
    expect_error "detect failing into a results folder" "detection.top_k" "$cli" detect "$seq" \
        --top-k 0 --quiet --out "$work/det3"
    if [ -s "$work/det3/loops.csv" ]; then pass; else fail "a failed rerun removed loops.csv"; fi
    mkdir -p "$work/foreign" && touch "$work/foreign/thesis.tex"
    expect_error "detect into a folder of other files" "holds no lidarloop run.json" "$cli" \
        detect "$seq" --quiet --out "$work/foreign"
    expect_error "detect into the dataset" "lies inside the input" "$cli" detect "$seq" \
        --quiet --out "$seq/results"
    if [ -e "$seq/results" ]; then fail "a results folder was made inside the dataset"; else pass; fi
    expect_error "detect seconds without times" "has no poses and no times.txt" "$cli" detect \
        "$seq" --min-gap 1 --min-gap-unit seconds --quiet --out "$work/det4"
    # A times.txt alone gives the scans' times (KITTI's sequences without poses).
    seq_times="$work/seq_times"
    cp -r "$seq" "$seq_times"
    find "$seq_times" -name 'scan*' | awk '{ print 0.1 * (NR - 1) }' >"$seq_times/times.txt"
    expect_ok "detect seconds with times.txt" "scans (folder)" "$cli" detect "$seq_times" \
        --min-gap 0.15 --min-gap-unit seconds --quiet --out "$work/det4"
    expect_error "detect bad top-k" "--top-k: detection.top_k must be in" "$cli" detect "$seq" \
        --top-k 0 --quiet --out "$work/det5"
    expect_error "evaluate bad distance" "--distance: ground_truth.distance_m must be" "$cli" \
        evaluate "$seq" --distance -3 --quiet --out "$work/eval_bad_distance"
    expect_error "evaluate bad train fraction" "--train-fraction: threshold_learning.train_fraction" \
        "$cli" evaluate "$seq" --train-fraction 1.5 --quiet --out "$work/eval_bad_fraction"
    expect_error "detect missing dataset" "no such dataset folder" "$cli" detect "$work/none" \
        --quiet --out "$work/det6"
}

# --- bench over a small sequence -------------------------------------------------------------
section_bench() {
    seq="$work/seq"
    make_sequence "$seq"
    expect_ok "bench" '"ns_per_comparison_one_core"' "$cli" bench "$seq" --queries 3 --quiet \
        --json -
    expect_ok "bench scaled" '"scaled_queries"' "$cli" bench "$seq" --queries 3 --scale-to 500 \
        --quiet --json -
    # The table: the online step's stages and its rate, with the figures of the JSON.
    expect_ok "bench table" "per scan on one core =" "$cli" bench "$seq" \
        --queries 3 --verify-queries 2 --min-gap 2 --quiet
    expect_ok "bench table without verification" "online step without verification" "$cli" \
        bench "$seq" --queries 3 --verify-queries 0 --quiet
    expect_ok "bench online step in the JSON" '"online_rate_hz": ' "$cli" bench "$seq" --queries 3 \
        --verify-queries 2 --min-gap 2 --quiet --json -
    if grep -q '"online_rate_hz": null' <<<"$("$cli" bench "$seq" --queries 3 --verify-queries 2 \
        --min-gap 2 --quiet --json -)"; then fail "bench measured no online step"; else pass; fi
    # No timed scan (a gap longer than the sequence): no rate that reads as measured.
    expect_ok "bench without candidates" "online step: not measured" "$cli" bench "$seq" \
        --queries 3 --verify-queries 2 --min-gap 1000 --quiet
    # No query timed: the retrieval row and the JSON say so, no "0.00 us" that reads as measured.
    expect_ok "bench without queries" "| retrieval (index)                            | query          |          - |          - |" \
        "$cli" bench "$seq" --queries 0 --verify-queries 0 --quiet
    expect_ok "bench without queries, the rate" "online step without verification: not measured" \
        "$cli" bench "$seq" --queries 0 --verify-queries 0 --quiet
    expect_ok "bench without queries in the JSON" '"count": 0,' "$cli" bench "$seq" --queries 0 \
        --verify-queries 0 --quiet --json -
    # A negative count must not wrap to 2^64 - 1 (a bench that never ends), nor a huge one run
    # out of memory.
    expect_error "bench negative queries" "--queries: must not be negative, got -1" "$cli" \
        bench "$seq" --queries -1 --quiet
    expect_error "bench negative scale" "--scale-to: must not be negative" "$cli" bench "$seq" \
        --scale-to -5 --quiet
    expect_error "bench huge scale" "scale_to must be at most 2000000" "$cli" bench "$seq" \
        --scale-to 100000000000 --quiet
    expect_error "simulate negative seed" "--seed: must not be negative" "$cli" simulate \
        --seed -1 --scans 2 --out "$work/negative_seed"
    # bench --method ndt reports the rotation candidates of each scan: copies of one scan have as
    # many as describe prints descriptors for it.
    ndt_seq="$work/ndt_seq"
    mkdir -p "$ndt_seq"
    for i in 0 1 2; do cp "$samples/corner_a.bin" "$ndt_seq/scan$i.bin"; done
    described="$("$cli" describe --method ndt "$samples/corner_a.bin" |
        grep -o '"R_aligned_sensor"' | wc -l)"
    benched="$("$cli" bench "$ndt_seq" --method ndt --queries 3 --quiet --json - | tr -d ' \n' |
        grep -o '"rotation_candidates_per_scan":{"max":[0-9.]*,"median":[0-9.]*' |
        grep -o '"median":[0-9]*' | cut -d: -f2)"
    if [ "$described" -ge 1 ] && [ "$benched" = "$described" ]; then pass; else
        fail "bench ndt: median rotation candidates '$benched'," \
            "describe printed $described descriptors"
    fi
}

# --- demo ------------------------------------------------------------------------------------
section_demo() {
    # A results folder the demo may not write is refused before the sequence is simulated.
    mkdir -p "$work/demo_refused/evaluation" && echo mine >"$work/demo_refused/evaluation/mine.txt"
    expect_exit_1 "demo into a folder of the user's" "evaluation: is not empty" "$cli" demo \
        --out "$work/demo_refused" --quiet
    if [ ! -e "$work/demo_refused/sequence" ]; then pass; else
        fail "demo simulated its sequence before refusing its evaluation folder"
    fi
    expect_ok "demo" "(optimised); top view:" "$cli" demo --out "$work/demo" --quiet
    for file in metrics.json roc.csv pr.csv report.md ground_truth.png similarity_height.png \
        similarity_ndt.png config.yaml; do
        if [ -s "$work/demo/evaluation/$file" ]; then pass; else fail "demo did not write $file"; fi
    done
    for file in map.png map_odometry.ply map_optimised.ply; do
        if [ -s "$work/demo/optimised/$file" ]; then pass; else fail "demo did not write $file"; fi
    done
    for stage in evaluation optimised; do
        if grep -q '"status": "complete"' "$work/demo/$stage/run.json"; then pass; else
            fail "demo's $stage/run.json does not say complete"
        fi
    done
    for key in best_mcc tau_best_mcc best_f1 tau_best_f1 roc_auc recall_at_zero_fp tau_zero_fp \
        em_threshold; do
        if grep -q "\"$key\"" "$work/demo/evaluation/metrics.json"; then pass; else
            fail "metrics.json lacks $key"
        fi
    done
}

# --- evaluate on a sequence like the demo's and a sequence without poses -----------------------
section_evaluate() {
    seq="$work/seq"
    make_sequence "$seq"
    # The demo's sequence (sim::DemoConfig) from simulate: the whole demo would also detect,
    # evaluate and optimise every method, two CPU minutes that section_demo spends already.
    demo_seq="$work/demo_sequence"
    if ! "$cli" simulate --scene urban --route grid --sensor vlp16 --horizontal-steps 1024 \
        --scans 320 --spacing-min-m 2.5 --spacing-max-m 3.5 --seed 1 --quiet \
        --out "$demo_seq" >"$work/simulate.log" 2>&1; then
        fail "setup: lidarloop simulate failed: $(tail -5 "$work/simulate.log")"
        return
    fi
    expect_ok "detect on demo" "320 scans (kitti)" "$cli" detect "$demo_seq" --top-k 2 --quiet \
        --out "$work/demo_det"
    expect_ok "evaluate results csv" "results:loops" "$cli" evaluate "$demo_seq" --no-verify --method height \
        --results "$work/demo_det/loops.csv" --distance 5 --quiet --out "$work/demo_eval"
    # loops.csv lists one candidate per scan; the pairs it omits are never detected, so no
    # threshold is +inf (null in metrics.json) and no curve reaches +inf.
    if ! grep -qE '"(tau|tau_best_mcc|tau_best_f1)": null' "$work/demo_eval/metrics.json" &&
        ! grep -q '^results:loops,inf,' "$work/demo_eval/roc.csv"; then pass; else
        fail "evaluate results csv: a threshold is +inf, omitted pairs counted as detected"
    fi
    # Two pairs at one distance: too few for the EM fit, which is left out, not an error.
    printf 'query,match,distance\n100,10,0\n200,20,0\n' >"$work/sparse.csv"
    expect_ok "evaluate sparse results" "results:sparse" "$cli" evaluate "$demo_seq" --no-verify \
        --method height --results "$work/sparse.csv" --quiet --out "$work/demo_sparse"
    if grep -q '"em": null' "$work/demo_sparse/metrics.json"; then pass; else
        fail "evaluate sparse results: metrics.json lacks \"em\": null"
    fi
    # Trained on the test sequence itself, the learnt tau is exactly the best-MCC tau.
    expect_ok "evaluate --train-on" "report:" "$cli" evaluate "$demo_seq" --no-verify --method height \
        --train-on "$demo_seq" --quiet --out "$work/demo_train"
    json_number() {
        grep -o "\"$1\": [-0-9.e]*" "$work/demo_train/metrics.json" | head -1 | cut -d' ' -f2
    }
    if [ -n "$(json_number tau)" ] && [ "$(json_number tau)" = "$(json_number tau_best_mcc)" ] &&
        [ "$(json_number test_mcc)" = "$(json_number best_mcc)" ]; then pass; else
        fail "threshold learnt on the same sequence:" \
            "tau $(json_number tau) vs $(json_number tau_best_mcc)"
    fi
    if grep -q "\"trained_on\": \"all pairs of $demo_seq\"" "$work/demo_train/metrics.json"; then
        pass
    else
        fail "metrics.json does not say where the threshold was learnt"
    fi
    expect_error "evaluate --train-on without poses" "has no poses; threshold learning needs" \
        "$cli" evaluate "$demo_seq" --no-verify --method height --train-on "$seq" --quiet \
        --out "$work/demo_train2"
    expect_exit_1 "evaluate a method twice" "method range is asked for twice" "$cli" evaluate \
        "$demo_seq" --no-verify --method range --method range --quiet --out "$work/demo_twice"
    expect_error "evaluate --train-poses alone" "--train-poses needs --train-on" "$cli" evaluate \
        "$demo_seq" --method height --train-poses "$demo_seq/poses.txt" --quiet \
        --out "$work/demo_train3"
    expect_ok "evaluate fixed thresholds" "report:" "$cli" evaluate "$demo_seq" --no-verify --method range \
        --fixed-thresholds 0.003,0.005,0.007 --quiet --out "$work/demo_fixed"
    if grep -q "every compared pair" "$work/stderr" "$work/demo_fixed/report.md"; then
        fail "a one-class note on a sequence of both classes"
    else
        pass
    fi
    # Every pair the same place: the pair protocol's figures mean nothing, and a note says so.
    expect_ok "evaluate one class" "every compared pair is the same place" "$cli" evaluate \
        "$demo_seq" --no-verify --method range --distance 100000 --quiet --out "$work/demo_one"
    # No revisit at all: recall is undefined ("–"), not 0 % or "nan %".
    no_revisit="$("$cli" evaluate "$demo_seq" --no-verify --method range --distance 0.01 --quiet \
        --out "$work/demo_none" 2>&1)"
    if grep -qF "revisiting scans: recall@1 –, recall@10 –" <<<"$no_revisit" &&
        grep -qF "recall at 100 % precision –" <<<"$no_revisit" && ! grep -qi "nan" <<<"$no_revisit"
    then pass; else fail "evaluate without a revisit: $no_revisit"; fi
    if grep -q "L_0.003 | L_0.005 | L_0.007" "$work/demo_fixed/report.md"; then pass; else
        fail "report.md lacks the fixed-threshold table"
    fi
    if grep -q "less than 5 m apart" "$work/demo_eval/report.md"; then pass; else
        fail "report.md lacks the ground-truth rule"
    fi
    expect_error "evaluate without poses" "has no poses" "$cli" evaluate "$seq" --quiet \
        --out "$work/e1"
    expect_error "evaluate bad method" "--method" "$cli" evaluate "$demo_seq" --no-verify --method sift \
        --out "$work/e2"
    expect_error "evaluate bad distance" "ground_truth.distance_m" "$cli" evaluate "$demo_seq" --no-verify \
        --distance 0 --quiet --out "$work/e3"
    # --min/--max belong to the one histogram method evaluated.
    expect_ok "evaluate range --max" "report:" "$cli" evaluate "$demo_seq" --no-verify --method range \
        --max 50 --quiet --out "$work/demo_max"
    if grep -q "range_max_m: 50" "$work/demo_max/config.yaml" &&
        grep -q "height_max_m: 7" "$work/demo_max/config.yaml"; then pass; else
        fail "evaluate --method range --max 50 did not set range_max_m only"
    fi
    expect_error "evaluate ambiguous --max" "--min and --max set the value range of one" \
        "$cli" evaluate "$demo_seq" --no-verify --max 50 --quiet --out "$work/e5"
    printf 'query,match,distance\n1,999,0.1\n' >"$work/far.csv"
    expect_error "evaluate results beyond" "names a scan beyond the 320" "$cli" evaluate \
        "$demo_seq" --no-verify --method height --results "$work/far.csv" --quiet --out "$work/e4"
    # A scan evaluate cannot read is reported, as detect reports it: never a silent gap.
    local small="$work/small"
    "$cli" simulate --scans 40 --sensor vlp16 --horizontal-steps 200 --quiet --out "$small" \
        >/dev/null
    head -c 1000 "$small/velodyne/000005.bin" >"$work/short.bin"
    mv "$work/short.bin" "$small/velodyne/000005.bin"
    expect_ok "evaluate --skip-bad" "1 scan could not be read (skipped.txt)" "$cli" evaluate \
        "$small" --skip-bad --no-verify --method height --quiet --out "$work/e_skip"
    if grep -q "000005.bin" "$work/e_skip/skipped.txt" &&
        grep -q '"skipped_scans": 1' "$work/e_skip/metrics.json"; then pass; else
        fail "evaluate --skip-bad wrote no skipped.txt or skipped_scans"
    fi
}

# --- dump-config and --config ----------------------------------------------------------------
section_dump_config() {
    expect_ok "dump-config" "bins: 100" "$cli" dump-config
    expect_ok "dump-config threshold" "threshold: default" "$cli" dump-config
    # lidarloop 0.1 kept tau under histogram: its default loads, another value says where it went.
    legacy="$(dirname "$committed")/legacy"
    expect_ok "0.1 config loads" "bins: 100" "$cli" dump-config --config "$legacy/config_v0.1.yaml"
    expect_error "0.1 threshold moved" "moved to 'detection.threshold'" "$cli" dump-config \
        --config "$legacy/config_v0.1_threshold.yaml"
    printf 'histogram:\n  bins: 12\n' >"$work/twelve.yaml"
    expect_ok "dump-config --config" "bins: 12" "$cli" dump-config --config "$work/twelve.yaml"
    expect_ok "dump-config keeps others" "range_max_m: 80" "$cli" dump-config \
        --config "$work/twelve.yaml"
    twelve="$("$cli" describe --config "$work/twelve.yaml" "$samples/corner_a.bin" |
        grep -o '"bins":\[[^]]*\]' | tr -cd , | wc -c)"
    if [ "$twelve" -eq 11 ]; then pass; else
        fail "--config bins: 12 gave $((twelve + 1)) buckets"
    fi
    flag_wins="$("$cli" describe --config "$work/twelve.yaml" --bins 5 "$samples/corner_a.bin" |
        grep -o '"bins":\[[^]]*\]' | tr -cd , | wc -c)"
    if [ "$flag_wins" -eq 4 ]; then pass; else fail "--bins did not override --config"; fi
    printf 'histogram:\n  binz: 12\n' >"$work/typo.yaml"
    expect_error "unknown key" "key 'histogram.binz': unknown key" "$cli" dump-config \
        --config "$work/typo.yaml"
    expect_error "unknown key in describe" "typo.yaml" "$cli" describe --config "$work/typo.yaml" \
        "$samples/corner_a.bin"
    printf 'histogram: [1\n' >"$work/broken.yaml"
    expect_error "broken yaml" "broken.yaml" "$cli" dump-config --config "$work/broken.yaml"
}

# --- bad input: each a clean error naming the problem ----------------------------------------
section_bad_input() {
    expect_error "missing file" "missing.pcd: no such file" "$cli" describe "$work/missing.pcd"
    printf 'hello' >"$work/odd.bin"
    expect_error "truncated bin" "odd.bin" "$cli" describe "$work/odd.bin"
    : >"$work/empty.bin"
    expect_error "empty scan" "empty.bin: the scan has no points" "$cli" describe "$work/empty.bin"
    printf 'nan nan nan\n1 inf 2\n' >"$work/nan.xyz"
    expect_error "all non-finite" "nan.xyz: no point of the scan is usable (2 non-finite" \
        "$cli" describe "$work/nan.xyz"
    printf '1 2 3\nnan 0 0\n' >"$work/some_nan.xyz"
    expect_ok "some non-finite" '"points_skipped":1' "$cli" describe "$work/some_nan.xyz"
    printf 'ply\nformat ascii 1.0\n' >"$work/cut.ply"
    expect_error "truncated ply" "cut.ply" "$cli" describe "$work/cut.ply"
    printf 'not a pcd\n' >"$work/wrong.pcd"
    expect_error "wrong magic pcd" "wrong.pcd" "$cli" describe "$work/wrong.pcd"
    head -c 300 "$samples/corner_a_binary.pcd" >"$work/cut.pcd"
    expect_error "truncated pcd" "cut.pcd" "$cli" describe "$work/cut.pcd"
    printf 'x' >"$work/scan.las"
    expect_error "unknown format" "unknown scan format '.las'" "$cli" describe "$work/scan.las"
    expect_error "unknown method" "unknown method 'sift'" "$cli" describe --method sift \
        "$samples/corner_a.bin"
    expect_error "a switch given a value" "all-candidates" "$cli" detect "$samples" \
        --all-candidates=false --out "$work/switch_value"
    expect_error "zero bins" "--bins: histogram.bins must be in [1, 1000000], got 0" "$cli" \
        describe --bins 0 "$samples/corner_a.bin"
    expect_error "huge bins" "histogram.bins must be in [1, 1000000]" "$cli" describe \
        --bins 999999999 "$samples/corner_a.bin"
    expect_error "min above max" "must be smaller than" "$cli" describe --min 5 --max 1 \
        "$samples/corner_a.bin"
    # Checked as a pair: --min 8 alone would be above the default height_max_m 7.
    expect_ok "min and max above the defaults" '"min":8' "$cli" describe --method height \
        --min 8 --max 10 "$samples/corner_a.bin"
    expect_error "negative range" "range_min_m must be >= 0" "$cli" describe --method range \
        --min -1 "$samples/corner_a.bin"
    expect_error "bad up" "unknown up vector mode" "$cli" describe --method height --up sideways \
        "$samples/corner_a.bin"
    expect_error "non-number flag" "--bins" "$cli" describe --bins many "$samples/corner_a.bin"
    expect_error "distance needs two" "SCAN_A SCAN_B" "$cli" distance "$samples/corner_a.bin"
    expect_error "no subcommand" "subcommand" "$cli"
}

# --- simulate: a tiny synthetic sequence in the KITTI layout ---------------------------------
section_simulate() {
    expect_ok "simulate" "simulated 5 scans (urban, uturn, vlp16, seed 2)" "$cli" simulate \
        --scene urban --route uturn --sensor vlp16 --scans 5 --seed 2 --horizontal-steps 360 \
        --quiet --out "$work/sim"
    expect_ok "describe a simulated scan" '"points_skipped":0' "$cli" describe \
        "$work/sim/velodyne/000004.bin"
    if [ "$(wc -l <"$work/sim/poses.txt")" -eq 5 ] && [ "$(wc -l <"$work/sim/times.txt")" -eq 5 ] &&
        grep -q "model: vlp16" "$work/sim/simulation.yaml"; then pass; else
        fail "simulate wrote no 5 poses, 5 times and simulation.yaml"
    fi
    "$cli" simulate --sensor vlp16 --scans 5 --seed 2 --horizontal-steps 360 --quiet \
        --out "$work/sim2" >/dev/null 2>&1
    if cmp -s "$work/sim/velodyne/000003.bin" "$work/sim2/velodyne/000003.bin"; then pass; else
        fail "simulate with the same seed wrote different scans"
    fi
    expect_error "simulate bad scene" "unknown scene 'moon' (valid: urban, rural, mine, indoor)" \
        "$cli" simulate --scene moon --out "$work/sim_bad"
    expect_error "simulate zero scans" "--scans must be in [1, 1000000]" "$cli" simulate --scans 0 \
        --out "$work/sim_bad"
    : >"$work/no_poses.txt"
    expect_error "simulate an empty trajectory" "$work/no_poses.txt: holds no poses" "$cli" simulate \
        --trajectory "$work/no_poses.txt" --out "$work/sim_bad"
    expect_exit_1 "simulate negative threads" "threads must be 0 (all cores) or more, got -1" \
        "$cli" simulate --scans 2 --threads -1 --out "$work/sim_bad"
    expect_error "simulate bad dropout" "sensor.dropout must be in [0, 1)" "$cli" simulate \
        --dropout 1.5 --out "$work/sim_bad"
    expect_error "simulate bad sensor" \
        "unknown sensor 'hdl33' (valid: hdl64, vlp16, tilt180, hdl32, ouster64-wide, livox-avia)" \
        "$cli" simulate --sensor hdl33 --out "$work/sim_bad"
    expect_error "simulate keep every 0" "front_end.keep_every must be in [1, 1000], got 0" \
        "$cli" simulate --keep-every 0 --out "$work/sim_bad"
    expect_error "simulate keep every huge" "front_end.keep_every must be in [1, 1000], got 5000" \
        "$cli" simulate --keep-every 5000 --out "$work/sim_bad"
    expect_ok "simulate livox-avia thinned" "simulated 3 scans (urban, uturn, livox-avia, seed 2)" \
        "$cli" simulate --sensor livox-avia --scans 3 --seed 2 --horizontal-steps 400 \
        --keep-every 4 --quiet --out "$work/sim_livox"
    if grep -q "model: livox-avia" "$work/sim_livox/simulation.yaml" &&
        grep -q "keep_every: 4" "$work/sim_livox/simulation.yaml"; then pass; else
        fail "simulate did not record the livox-avia sensor and keep_every 4 in simulation.yaml"
    fi
    expect_error "simulate into old scans" "holds a lidarloop dataset" "$cli" simulate \
        --sensor vlp16 --scans 2 --out "$work/sim"
    expect_ok "simulate --overwrite" "simulated 2 scans" "$cli" simulate --sensor vlp16 --scans 2 \
        --horizontal-steps 360 --quiet --overwrite --out "$work/sim"
    if [ "$(find "$work/sim/velodyne" -name '*.bin' | wc -l)" -eq 2 ]; then pass; else
        fail "simulate --overwrite left scans of the longer sequence before"
    fi
}

# --- optimise: a pose graph of a tiny simulated sequence, and its bad input -----------------------
section_optimise() {
    "$cli" simulate --sensor vlp16 --route grid --scans 40 --horizontal-steps 90 --quiet \
        --out "$work/seq" >/dev/null 2>&1
    local header="query,match,distance,second_ratio,accepted,rank,tx,ty,tz,qx,qy,qz,qw"
    printf '%s\n%s\n' "$header" "35,2,0.001,,1,1,0,0,0,0,0,0,1" >"$work/loops.csv"
    expect_ok "optimise" "ATE RMSE: odometry" "$cli" optimise "$work/seq" --odometry \
        "$work/seq/poses_odometry.txt" --loops "$work/loops.csv" --format tum --out "$work/opt"
    if [ -s "$work/opt/graph.g2o" ] && grep -q "ate_rmse_m_optimised" "$work/opt/metrics.json" &&
        [ "$(awk 'NR == 1 { print NF }' "$work/opt/poses_optimised.txt")" -eq 8 ]; then pass; else
        fail "optimise wrote no graph.g2o, metrics.json or TUM poses_optimised.txt"
    fi
    if grep -q '"status": "complete"' "$work/opt/run.json"; then pass; else
        fail "optimise's run.json does not say complete"
    fi
    # KITTI's RPE needs 100 m segments; this path is about 60 m long.
    expect_ok "optimise short path RPE" "RPE n/a (path shorter than 100 m)" "$cli" optimise \
        "$work/seq" --odometry "$work/seq/poses_odometry.txt" --loops "$work/loops.csv" \
        --out "$work/opt"
    expect_error "optimise into the dataset" "lies inside the input" "$cli" optimise "$work/seq" \
        --odometry "$work/seq/poses_odometry.txt" --loops "$work/loops.csv" --out "$work/seq/opt"
    printf '%s\n%s\n' "$header" "35,2,0.001,,0,1,0,0,0,0,0,0,1" >"$work/none.csv"
    expect_ok "optimise without loops" "no loop: the odometry is returned unchanged" "$cli" \
        optimise "$work/seq" --odometry "$work/seq/poses_odometry.txt" --loops "$work/none.csv" \
        --out "$work/opt_none"
    head -n 39 "$work/seq/poses_odometry.txt" >"$work/short.txt"
    expect_error "optimise short odometry" "short.txt: holds 39 poses but" "$cli" optimise \
        "$work/seq" --odometry "$work/short.txt" --loops "$work/loops.csv" --out "$work/opt_bad"
    printf '%s\n%s\n' "$header" "99,2,0.001,,1,1,0,0,0,0,0,0,1" >"$work/far.csv"
    expect_error "optimise missing scan" "line 2: query scan 99 does not exist" "$cli" optimise \
        "$work/seq" --odometry "$work/seq/poses_odometry.txt" --loops "$work/far.csv" \
        --out "$work/opt_bad"
    sed '3s/^[^ ]*/nan/' "$work/seq/poses_odometry.txt" >"$work/inf.txt"
    expect_error "optimise non-finite odometry" "line 3: 'nan' is not a finite number" "$cli" \
        optimise "$work/seq" --odometry "$work/inf.txt" --loops "$work/loops.csv" \
        --out "$work/opt_bad"
}

# --- map: the scans placed with a trajectory, and optimise's maps ------------------------------
section_map() {
    "$cli" simulate --sensor vlp16 --route grid --scans 40 --horizontal-steps 90 --quiet \
        --out "$work/seq" >/dev/null 2>&1
    local odometry="$work/seq/poses_odometry.txt"
    expect_ok "map" "40 scans" "$cli" map "$work/seq" --poses "$odometry" --out "$work/m/map.ply"
    if head -c 200 "$work/m/map.ply" | grep -q "comment written by lidarloop" &&
        head -c 400 "$work/m/map.ply" | grep -q "property uchar red"; then pass; else
        fail "map wrote no coloured lidarloop PLY"
    fi
    expect_ok "map again over its own file" "voxels of 0.5 m" "$cli" map "$work/seq" --poses \
        "$odometry" --voxel 0.5 --out "$work/m/map.ply"
    expect_ok "map of the dataset's poses, capped" "map.max_points = 1000" "$cli" map \
        "$work/seq" --max-points 1000 --out "$work/m/truth.ply"
    echo "my map" >"$work/mine.ply"
    expect_exit_1 "map onto a foreign file" "give --overwrite" "$cli" map "$work/seq" --out \
        "$work/mine.ply"
    if grep -q "my map" "$work/mine.ply"; then pass; else fail "map replaced mine.ply"; fi
    expect_ok "map --overwrite" "40 scans" "$cli" map "$work/seq" --out "$work/mine.ply" \
        --overwrite
    expect_exit_1 "map into the dataset" "lies inside the input" "$cli" map "$work/seq" \
        --out "$work/seq/map.ply"
    expect_exit_1 "map zero voxel" "map.voxel_m must be in [0.01, 100] m, got 0" "$cli" map \
        "$work/seq" --voxel 0 --out "$work/bad.ply"
    head -n 39 "$odometry" >"$work/short.txt"
    expect_exit_1 "map short poses" "short.txt: holds 39 poses but" "$cli" map "$work/seq" \
        --poses "$work/short.txt" --out "$work/bad.ply"
    sed '3s/^[^ ]*/nan/' "$odometry" >"$work/nan.txt"
    expect_exit_1 "map non-finite pose" "line 3: 'nan' is not a finite number" "$cli" map \
        "$work/seq" --poses "$work/nan.txt" --out "$work/bad.ply"
    expect_exit_1 "map voxel 0" "voxel" "$cli" map "$work/seq" --voxel 0 --out "$work/bad.ply"
    expect_exit_1 "map voxel nan" "map.voxel_m must be in" "$cli" map "$work/seq" --voxel nan \
        --out "$work/bad.ply"
    printf 'map:\n  voxel_m: -1\n' >"$work/bad.yaml"
    expect_exit_1 "map negative voxel in a config" "map.voxel_m" "$cli" map "$work/seq" \
        --config "$work/bad.yaml" --out "$work/bad.ply"
    expect_exit_1 "map missing poses" "missing.txt" "$cli" map "$work/seq" --poses \
        "$work/missing.txt" --out "$work/bad.ply"
    if [ ! -e "$work/bad.ply" ]; then pass; else fail "a failed map left bad.ply"; fi
    # optimise writes both maps and their top view, linked from its report.
    local header="query,match,distance,second_ratio,accepted,rank,tx,ty,tz,qx,qy,qz,qw"
    printf '%s\n%s\n' "$header" "35,2,0.001,,1,1,0,0,0,0,0,0,1" >"$work/loops.csv"
    expect_ok "optimise with maps" "map.png" "$cli" optimise "$work/seq" --odometry "$odometry" \
        --loops "$work/loops.csv" --out "$work/opt"
    if [ -s "$work/opt/map_odometry.ply" ] && [ -s "$work/opt/map_optimised.ply" ] &&
        [ "$(head -c 4 "$work/opt/map.png" | tail -c 3)" = "PNG" ] &&
        grep -q "(map.png)" "$work/opt/report.md"; then pass; else
        fail "optimise wrote no maps or map.png, or report.md does not link it"
    fi
}

# expect_intact NAME FILE...: each file still exists and is not empty.
expect_intact() {
    local name="$1" file
    shift
    for file in "$@"; do
        if [ -s "$file" ]; then pass; else fail "$name: $file was removed or emptied"; fi
    done
}

# --- results folders: no command removes or replaces what it did not write (issue 25) --------
section_results_folders() {
    local seq="$work/seq" res="$work/res"
    make_sequence "$seq"
    expect_ok "detect" "8 scans" "$cli" detect "$seq" --min-gap 2 --quiet --out "$res"
    local detected=("$res/loops.csv" "$res/database.lldb" "$res/database.scans" "$res/run.json")
    printf '%s\n' 0 0 0 0 0 0 0 0 | awk '{ print "1 0 0 " NR " 0 1 0 0 0 0 1 0" }' \
        >"$work/odometry.txt"
    expect_error "optimise into its loops' folder" "holds the input $res/loops.csv" "$cli" \
        optimise "$seq" --odometry "$work/odometry.txt" --loops "$res/loops.csv" --out "$res"
    expect_error "evaluate into its results' folder" "holds the input" "$cli" evaluate "$seq" \
        --poses "$work/odometry.txt" --results "$res/loops.csv" --method range --quiet \
        --out "$res"
    expect_error "detect into its map's folder" "holds the input $res/database.lldb" "$cli" \
        detect "$seq" --map "$res/database.lldb" --quiet --out "$res"
    # The config a run wrote, edited and given back, is an input: never replaced by the rerun.
    echo "# my edits" >>"$res/config.yaml"
    expect_error "detect with its --config inside --out" "holds the input $res/config.yaml" \
        "$cli" detect "$seq" --config "$res/config.yaml" --quiet --out "$res"
    expect_error "bench --json onto its --config" "is an input of this run" "$cli" bench "$seq" \
        --config "$res/config.yaml" --queries 2 --verify-queries 0 --quiet \
        --json "$res/config.yaml"
    if grep -q "# my edits" "$res/config.yaml"; then pass; else fail "detect replaced --config"; fi
    expect_intact "inputs inside --out" "${detected[@]}"
    # A rerun that fails on a truncated scan leaves the earlier results.
    head -c 100 "$samples/corner_a.bin" >"$seq/scan3.bin"
    expect_error "detect rerun on a truncated scan" "scan3.bin" "$cli" detect "$seq" --quiet \
        --out "$res"
    expect_intact "failed rerun" "${detected[@]}"
    if grep -q '"status": "complete"' "$res/run.json"; then pass; else
        fail "a failed rerun changed the earlier run.json"
    fi
    cp "$samples/corner_a.bin" "$seq/scan3.bin"
    # Another command into detect's folder would remove the map: refused without --overwrite.
    expect_error "evaluate into detect's results" "holds the results of \`lidarloop detect\`" \
        "$cli" evaluate "$seq" --poses "$work/odometry.txt" --method range --quiet --out "$res"
    expect_intact "another command's run" "${detected[@]}"
    # --overwrite replaces files of the same names, never a folder of the user's as a whole.
    mkdir -p "$work/mine/velodyne"
    echo "my notes" >"$work/mine/velodyne/notes.txt"
    expect_error "simulate over a folder of mine" "would be replaced as a whole" "$cli" simulate \
        --scans 2 --overwrite --out "$work/mine"
    if grep -q "my notes" "$work/mine/velodyne/notes.txt"; then pass; else
        fail "simulate --overwrite removed a folder of the user's"
    fi
    # bench --json: never into the dataset, never over a file that lidarloop did not write.
    cp "$seq/scan0.bin" "$work/scan0.copy"
    expect_error "bench --json onto a scan" "lies inside the input" "$cli" bench "$seq" \
        --queries 2 --verify-queries 0 --quiet --json "$seq/scan0.bin"
    if cmp -s "$seq/scan0.bin" "$work/scan0.copy"; then pass; else fail "bench replaced a scan"; fi
    echo "my figures" >"$work/mine.json"
    expect_error "bench --json onto a foreign file" "give --overwrite" "$cli" bench "$seq" \
        --queries 2 --verify-queries 0 --quiet --json "$work/mine.json"
    if grep -q "my figures" "$work/mine.json"; then pass; else fail "bench replaced mine.json"; fi
    cp "$res/run.json" "$work/run.json.copy"
    expect_error "bench --json onto a run's record" "belongs to the results of \`lidarloop detect\`" \
        "$cli" bench "$seq" --queries 2 --verify-queries 0 --quiet --json "$res/run.json"
    if cmp -s "$res/run.json" "$work/run.json.copy"; then pass; else fail "bench replaced run.json"; fi
    expect_error "bench --json ''" "empty file name" "$cli" bench "$seq" --queries 2 \
        --verify-queries 0 --quiet --json ""
    expect_ok "bench --json" "online step" "$cli" bench "$seq" --queries 2 \
        --verify-queries 0 --quiet --json "$work/bench.json"
    if grep -q '"ns_per_comparison_one_core"' "$work/bench.json"; then pass; else
        fail "bench --json wrote no figures"
    fi
    expect_ok "bench --json again" "online step" "$cli" bench "$seq" --queries 2 \
        --verify-queries 0 --quiet --json "$work/bench.json"
    expect_ok "bench --json --overwrite" "online step" "$cli" bench "$seq" --queries 2 \
        --verify-queries 0 --quiet --json "$work/mine.json" --overwrite
    # simulate into a foreign sequence folder, and a Ctrl-C halfway.
    mkdir -p "$work/foreign" && echo "my poses" >"$work/foreign/poses.txt"
    expect_error "simulate into a foreign folder" "holds no lidarloop run.json" "$cli" simulate \
        --sensor vlp16 --scans 3 --horizontal-steps 90 --quiet --out "$work/foreign"
    if grep -q "my poses" "$work/foreign/poses.txt"; then pass; else
        fail "simulate replaced a foreign poses.txt"
    fi
    "$cli" simulate --sensor vlp16 --scans 100000 --horizontal-steps 90 --threads 1 --quiet \
        --out "$work/cut" >/dev/null 2>"$work/cut.err" &
    local pid=$! waited=0
    until compgen -G "$work/cut/.lidarloop-staging-*/velodyne/000002.bin" >/dev/null ||
        [ "$waited" -ge 600 ]; do
        sleep 0.1
        waited=$((waited + 1))
    done
    kill -INT "$pid"
    wait "$pid"
    local code=$?
    if [ "$code" -eq 130 ] && [ ! -e "$work/cut/velodyne" ] &&
        grep -q '"status": "interrupted"' "$work/cut/run.json"; then pass; else
        fail "interrupted simulate: exit $code, $(ls -A "$work/cut"), $(cat "$work/cut.err")"
    fi
    expect_error "detect on an interrupted sequence" "not finished" "$cli" detect "$work/cut" \
        --quiet --out "$work/cut_res"
    # demo never replaces a foreign report (a small sequence stands in for the demo's).
    "$cli" simulate --sensor vlp16 --scans 40 --horizontal-steps 90 --quiet \
        --out "$work/demo/sequence" >/dev/null
    mkdir -p "$work/demo/evaluation" && echo "my report" >"$work/demo/evaluation/report.md"
    expect_error "demo into a foreign evaluation folder" "holds no lidarloop run.json" "$cli" demo \
        --quiet --out "$work/demo"
    if grep -q "my report" "$work/demo/evaluation/report.md"; then pass; else
        fail "demo replaced a foreign report.md"
    fi
}

# --- errors: every input error exits 1 with one short line naming the problem ---------------
section_errors() {
    expect_exit_1 "missing --config" "missing.yaml" "$cli" dump-config --config "$work/missing.yaml"
    expect_exit_1 "folder as --config" "$work" "$cli" dump-config --config "$work"
    expect_exit_1 "missing verify scan" "missing.bin" "$cli" verify "$work/missing.bin" \
        "$samples/corner_a.bin"
    expect_exit_1 "folder as verify scan" "$work" "$cli" verify "$samples/corner_a.bin" "$work"
    expect_exit_1 "missing describe scan" "missing.pcd: no such file" "$cli" describe \
        "$work/missing.pcd"
    expect_exit_1 "folder as describe scan" "is a folder, not a file" "$cli" describe "$work"
    expect_exit_1 "value not in the list" "--format" "$cli" detect "$work" --format bogus \
        --out "$work/out"
    printf 'histogram:\n  bins: 12\n  range_max_m: 50\n  bins: 40\n' >"$work/twice.yaml"
    expect_exit_1 "repeated yaml key" "line 4: key 'histogram.bins' appears twice" "$cli" \
        dump-config --config "$work/twice.yaml"
    { printf '1 2 '; head -c 1000000 /dev/zero | tr '\0' 7; printf '\n'; } >"$work/long.xyz"
    expect_exit_1 "long token cut" "(1000000 characters) is not a number" "$cli" describe \
        "$work/long.xyz"
    if [ "$(wc -c <"$work/stderr")" -lt 300 ]; then pass; else
        fail "long token: the message has $(wc -c <"$work/stderr") bytes"
    fi
    "$cli" describe --no-such-flag "$samples/corner_a.bin" >/dev/null 2>&1
    local code=$?
    if [ "$code" -eq 1 ]; then pass; else fail "unknown flag: exit code $code, expected 1"; fi
}

# --- loops: each loop enters the pose graph once; implausible loops and odometry are errors -----
section_loops() {
    "$cli" simulate --sensor vlp16 --route grid --scans 40 --horizontal-steps 90 --quiet \
        --out "$work/seq" >/dev/null 2>&1
    local odometry="$work/seq/poses_odometry.txt"
    local header="query,match,distance,second_ratio,accepted,rank,tx,ty,tz,qx,qy,qz,qw"
    header+=",overlap_query,overlap_match,distinctive_query,distinctive_match,rmse_m,reason"
    local loop="35,2,0.001,,1,1,0,0,0,0,0,0,1,0.6,0.5,0.4,0.3,0.1,none"
    printf '%s\n' "$header" "$loop" "$loop" "2,35,0.001,,1,1,0,0,0,0,0,0,1,0.6,0.5,0.4,0.3,0.1,none" \
        "$loop" >"$work/loops.csv"
    expect_ok "duplicate loops merged" "3 duplicate rows of loops.csv merged" "$cli" optimise \
        "$work/seq" --odometry "$odometry" --loops "$work/loops.csv" --format tum --out "$work/opt"
    if [ "$(grep -c '^[0-9]' "$work/opt/loop_verdicts.csv")" -eq 1 ]; then pass; else
        fail "duplicate loops: loop_verdicts.csv does not hold the loop once"
    fi
    printf '%s\n' "$header" "35,2,0.001,,1,1,0,0,0,0,0,0,1,-5,0.5,0.4,0.3,0.1,none" >"$work/neg.csv"
    expect_exit_1 "overlap -5" "neg.csv: line 2: overlap_query '-5' is outside [0, 1]" "$cli" \
        optimise "$work/seq" --odometry "$odometry" --loops "$work/neg.csv" --out "$work/bad"
    awk 'NR == 5 { $4 = "1e30" } { print }' "$odometry" >"$work/far.txt"
    expect_exit_1 "odometry at 1e30" "far.txt: line 5: the position is 1e+30 m from the origin" \
        "$cli" optimise "$work/seq" --odometry "$work/far.txt" --loops "$work/loops.csv" \
        --out "$work/bad"
    awk 'NR >= 20 { $4 += 500 } { print }' "$odometry" >"$work/jump.txt"
    expect_exit_1 "odometry jump" "jump.txt: line 20: the pose is " \
        "$cli" optimise "$work/seq" --odometry "$work/jump.txt" --loops "$work/loops.csv" \
        --out "$work/bad"
    # The bound is a config key (posegraph.max_odometry_step_m) that the flag overrides.
    printf 'posegraph:\n  max_odometry_step_m: 1000\n' >"$work/far_steps.yaml"
    expect_ok "odometry jump within the configured bound" "ATE RMSE" "$cli" optimise "$work/seq" \
        --odometry "$work/jump.txt" --loops "$work/loops.csv" --config "$work/far_steps.yaml" \
        --out "$work/far_ok"
    expect_exit_1 "the flag overrides the config" "jump.txt: line 20: the pose is " "$cli" \
        optimise "$work/seq" --odometry "$work/jump.txt" --loops "$work/loops.csv" \
        --config "$work/far_steps.yaml" --max-odometry-step 100 --out "$work/bad"
    printf 'posegraph:\n  max_odometry_step_m: 0\n' >"$work/zero_steps.yaml"
    expect_exit_1 "a zero step bound" "posegraph.max_odometry_step_m must be in (0, 1e+08]" \
        "$cli" optimise "$work/seq" --odometry "$odometry" --loops "$work/loops.csv" \
        --config "$work/zero_steps.yaml" --out "$work/bad"
    # Line 3's time before line 2's (the scans' own times, whatever their spacing).
    awk 'NR == 2 { before = $1 } NR == 3 { $1 = before - 1 } { print }' \
        "$work/opt/poses_optimised.txt" >"$work/back.tum"
    expect_exit_1 "TUM time going back" "back.tum: line 3: time " "$cli" optimise \
        "$work/seq" --odometry "$work/back.tum" --loops "$work/loops.csv" --out "$work/bad"
    # Odometry that freezes from scan 10 on: the loops disagree with it, and a summary says so.
    awk 'NR == 11 { frozen = $0 } NR > 11 { $0 = frozen } { print }' "$odometry" >"$work/frozen.txt"
    printf '%s\n' "$header" "$loop" "36,3${loop#35,2}" "37,4${loop#35,2}" "38,5${loop#35,2}" \
        >"$work/four.csv"
    expect_ok "odometry that freezes" "longest standstill: scans 10 to 39" "$cli" optimise \
        "$work/seq" --odometry "$work/frozen.txt" --loops "$work/four.csv" --out "$work/frozen"
}

# --- a gap in metres of path, path_m, evaluate --min-path -------------------------------------
section_path_gap() {
    "$cli" simulate --sensor vlp16 --route grid --scans 40 --horizontal-steps 90 --quiet \
        --out "$work/seq" >/dev/null 2>&1
    local odometry="$work/seq/poses_odometry.txt"
    expect_ok "detect gap in metres" "40 scans" "$cli" detect "$work/seq" --min-gap 20 \
        --min-gap-unit metres --odometry "$odometry" --no-verify --top-k 3 --quiet --out "$work/det"
    if grep -q "no path rule" "$work/stderr"; then fail "a path rule note with odometry"; else pass; fi
    # Without poses or odometry the 50 m path rule cannot hold: a note says so.
    mkdir -p "$work/no_poses"
    cp "$work/seq/velodyne/"*.bin "$work/no_poses/"
    expect_ok "detect without a path" "40 scans" "$cli" detect "$work/no_poses" --no-verify \
        --quiet --out "$work/det_no_path"
    if grep -q "no path rule (detection.min_path_m)" "$work/stderr"; then pass; else
        fail "detect without poses gave no note on the path rule: $(cat "$work/stderr")"
    fi
    # Every candidate lies more than 20 m of path back, and path_m is the path walked anew.
    local wrong
    wrong="$(awk -F, 'NR == FNR { x[FNR - 1] = $4; y[FNR - 1] = $8; z[FNR - 1] = $12; next }
        FNR == 1 { if ($NF != "path_m") print "no path_m column"; next }
        { q = $1; m = $3; p = 0
          for (k = m; k < q; ++k) p += sqrt((x[k+1]-x[k])^2 + (y[k+1]-y[k])^2 + (z[k+1]-z[k])^2)
          if ($NF <= 20 || (p - $NF)^2 > 1e-8) print "row " FNR ": path_m " $NF ", walked " p }' \
        FS=' ' "$odometry" FS=, "$work/det/candidates.csv")"
    if [ -z "$wrong" ] && [ "$(wc -l <"$work/det/candidates.csv")" -gt 5 ]; then pass; else
        fail "candidates.csv path_m: ${wrong:-too few rows}"
    fi
    seq="$work/bare"
    make_sequence "$seq"
    expect_error "detect metres without poses" "needs the path travelled" "$cli" detect "$seq" \
        --min-gap 5 --min-gap-unit metres --quiet --out "$work/det_bare"
    head -n 39 "$odometry" >"$work/short.txt"
    expect_error "detect short odometry" "short.txt: holds 39 poses" "$cli" detect "$work/seq" \
        --min-gap-unit metres --odometry "$work/short.txt" --quiet --out "$work/det_short"
    printf 'detection:\n  min_gap: 50\n  min_gap_unit: metres\n' >"$work/metres.yaml"
    expect_ok "dump-config metres" "min_gap_unit: metres" "$cli" dump-config \
        --config "$work/metres.yaml"
    expect_ok "evaluate --min-path" "report:" "$cli" evaluate "$work/seq" --method range \
        --no-verify --min-gap 5 --min-path 30 --quiet --out "$work/eval"
    if grep -q '"min_path_m": 30' "$work/eval/metrics.json"; then pass; else
        fail "evaluate --min-path: metrics.json lacks min_path_m"
    fi
    # optimise --loops reads a loops.csv with path_m last.
    printf '%s\n%s\n' "query,match,distance,second_ratio,accepted,rank,tx,ty,tz,qx,qy,qz,qw,path_m" \
        "35,2,0.001,,1,1,0,0,0,0,0,0,1,42.5" >"$work/loops.csv"
    expect_ok "optimise loops with path_m" "ATE RMSE: odometry" "$cli" optimise "$work/seq" \
        --odometry "$odometry" --loops "$work/loops.csv" --out "$work/opt"
}

# --- run the sections named on the command line -------------------------------------------------
run_section() {
    local function_name="section_${1//-/_}"
    if ! declare -F "$function_name" >/dev/null; then
        echo "cli_test.sh: unknown section '$1' (valid: ${sections[*]}, all)" >&2
        exit 2
    fi
    work="$root/$1"
    mkdir -p "$work"
    "$function_name"
}
for section in "$@"; do
    if [ "$section" = all ]; then
        for each in "${sections[@]}"; do run_section "$each"; done
    else
        run_section "$section"
    fi
done
echo "cli $*: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
