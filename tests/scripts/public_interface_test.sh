#!/usr/bin/env bash
# What a library user is told matches what is installed. Usage: public_interface_test.sh SOURCE_DIR
# - cpp/lidarloop/lidarloop.hpp includes every installed header (every .hpp of a target's folder
#   outside detail/: cmake/LidarloopTargetDefaults.cmake) and nothing else;
# - docs/library.md's table of layers names every installed target (lidarloop_add_library);
# - the README's C++ snippet names the header and the target that examples/online_detection links.
set -euo pipefail
source_dir="$(cd "$1" && pwd)"
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

cd "$source_dir/cpp"
umbrella=lidarloop/lidarloop.hpp
installed="$(find lidarloop -mindepth 2 -name '*.hpp' -not -path '*/detail/*' | sort)"
included="$(sed -n 's/^#include "\(lidarloop\/.*\.hpp\)"$/\1/p' "$umbrella" | sort)"
if [ "$installed" != "$included" ]; then
    fail "$umbrella and the installed headers differ (< installed only, > included only):"
    diff <(echo "$installed") <(echo "$included") | grep '^[<>]' || true
else
    echo "ok: $umbrella includes all $(echo "$installed" | wc -l) installed headers"
fi

cd "$source_dir"
targets="$(sed -n 's/^lidarloop_add_library(\([a-z_0-9]*\).*/\1/p' cpp/lidarloop/*/CMakeLists.txt | sort)"
for target in $targets; do
    grep -q "^| \`lidarloop::$target\` |" docs/library.md ||
        fail "docs/library.md's table of layers has no row for lidarloop::$target"
done
echo "ok: docs/library.md checked for $(echo "$targets" | wc -w) targets"

# The README's sentence before its C++ block: "... headers `X`, link `lidarloop::Y`".
linked="$(sed -n 's/.*target_link_libraries(example_\${example} PRIVATE \(lidarloop::[a-z_]*\)).*/\1/p' \
    examples/CMakeLists.txt)"
grep -q "link \`$linked\`" README.md || fail "README.md does not say the example links $linked"
grep -q '#include "lidarloop/lidarloop.hpp"' examples/online_detection.cpp ||
    fail "examples/online_detection.cpp does not include lidarloop/lidarloop.hpp"
grep -q 'header `lidarloop/lidarloop.hpp`' README.md ||
    fail "README.md does not name the header lidarloop/lidarloop.hpp"
grep -q '#include "lidarloop/lidarloop.hpp"' tests/consumer/main.cpp ||
    fail "tests/consumer/main.cpp does not include lidarloop/lidarloop.hpp"

if [ "$failures" -ne 0 ]; then echo "$failures failure(s)"; exit 1; fi
echo "public interface: all checks passed"
