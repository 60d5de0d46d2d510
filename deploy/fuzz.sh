#!/usr/bin/env bash
# Runs each libFuzzer target for a bounded time on its corpus in tests/fuzz/corpus (seeded
# with the example products), printing libFuzzer's totals. A crash, a leak or a time-out
# fails the script; the input that did it is kept in build/fuzz/artifacts.
#   bash deploy/fuzz.sh [SECONDS_PER_TARGET [BUILD_DIR]]     (default 60, build/fuzz)
# Without BUILD_DIR it builds the targets in build/fuzz (clang, optimised, ASan + UBSan). CI
# gives its clang sanitizer tree, which built them beside the tests (deploy/test.sh): one
# build less, at fewer executions per second.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
build=${2:-}
if [ -z "$build" ]; then
  bash deploy/install-deps.sh
  build=build/fuzz
  cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
    -DCELL_FUZZ=ON -DCELL_BUILD_TESTS=OFF -DCELL_BUILD_BENCHMARKS=OFF
  cmake --build "$build" -j "$(nproc)" --target fuzz_automationml fuzz_mesh fuzz_samples fuzz_dashboard_requests
fi
out=build/fuzz
mkdir -p "$out/artifacts"
run() {  # target, then seed folders (read only; new inputs go to a scratch copy of the corpus)
  local target=$1
  shift
  local work="$out/corpus/$target"
  mkdir -p "$work"
  cp -n tests/fuzz/corpus/"$target"/* "$work"/ 2>/dev/null || true
  echo "== $target, $seconds s"
  set +e
  ASAN_OPTIONS=detect_leaks=${LEAKS:-1} "$build/bin/$target" "$work" "$@" -max_total_time="$seconds" -timeout=10 \
    -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$out/artifacts/$target-" \
    >"$out/$target.log" 2>&1
  local code=$?
  set -e
  grep -E "^(stat::|#[0-9]+ *DONE|==[0-9]+==ERROR|SUMMARY)" "$out/$target.log"
  [ "$code" -eq 0 ] || tail -40 "$out/$target.log"
  return "$code"
}
run fuzz_automationml deploy/products/lego-tower deploy/products/cranfield
# Assimp 5.2.5 (Debian's) leaks in its OBJ importer on some malformed files (found here; not
# ours to fix, docs/hostile-input.md): leaks are not checked for this target, crashes are.
LEAKS=0 run fuzz_mesh deploy/products/lego-tower/meshes deploy/products/cranfield/meshes -detect_leaks=0
run fuzz_samples
run fuzz_dashboard_requests
