#!/usr/bin/env bash
# Checks README.md against what runs. Usage: readme_test.sh SOURCE_DIR LIDARLOOP DATASET
# - its C++ block must appear verbatim between the `// [readme-snippet]` lines of
#   examples/online_detection.cpp (built and run by examples.online_detection);
# - every shell block but the first (scripts/setup and scripts/test, which CI itself runs) is run
#   line by line, with ./build/cli/lidarloop, path/to/scans and poses.txt standing for this build's
#   tool and a simulated dataset, in a fresh folder; `lidarloop demo`, which cli.demo runs and
#   checks, is skipped (minutes of verification twice would buy nothing), and simulated
#   sequences are shortened to 120 scans (the commands are checked, not their figures).
set -euo pipefail
source_dir="$1"
cli="$2"
dataset="$3"
readme="$source_dir/README.md"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

# block LANG: prints every block of LANG, blocks separated by a line "@@".
block() {
    awk -v lang="$1" '
        $0 == "```" lang { inside = 1; next }
        inside && $0 == "```" { inside = 0; print "@@"; next }
        inside { print }' "$readme"
}

snippet="$(block cpp | sed '/^@@$/d')"
if [ -z "$snippet" ]; then echo "FAIL: README.md has no cpp block"; exit 1; fi
example="$(sed -n '/\/\/ \[readme-snippet\]/,/\/\/ \[readme-snippet\]/p' \
    "$source_dir/examples/online_detection.cpp" | sed '1d;$d' | sed 's/^        //')"
if [ "$snippet" != "$example" ]; then
    echo "FAIL: the README's C++ block differs from examples/online_detection.cpp:"
    diff <(echo "$snippet") <(echo "$example") || true
    exit 1
fi

commands="$(block sh | awk 'BEGIN { n = 0 } /^@@$/ { n++; next } n > 0 { print }')"
if [ -z "$commands" ]; then echo "FAIL: README.md has no shell commands to run"; exit 1; fi
cd "$work"
ran=0
while IFS= read -r line; do
    [ -z "$line" ] && continue
    case "$line" in ./build/cli/lidarloop\ demo*) continue ;; esac
    # The README's own paths first, so that paths of this build (which may lie under /tmp) stay.
    line="${line//\/tmp\//$work/}"
    line="${line//poses.txt/$dataset/poses.txt}"
    line="${line//path\/to\/new_scans/$dataset}"
    line="${line//path\/to\/scans/$dataset}"
    line="${line//.\/build\/cli\/lidarloop/$cli}"
    line="${line//--scans 300/--scans 120}"
    echo "+ $line"
    if ! bash -c "$line" >"$work/out.txt" 2>&1; then
        echo "FAIL: README command failed: $line"
        cat "$work/out.txt"
        exit 1
    fi
    ran=$((ran + 1))
done <<<"$commands"
echo "README: C++ snippet matches the example; $ran shell commands ran"
