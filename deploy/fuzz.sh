#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (ASan + UBSan) and runs each for a bounded time on
# its corpus in tests/fuzz/corpus (seeded with the example products), printing libFuzzer's
# totals. A crash, a leak or a time-out fails the script; the input that did it is kept in
# build/fuzz/artifacts.
#   bash deploy/fuzz.sh [SECONDS_PER_TARGET]     (default 60)
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
bash deploy/install-deps.sh
missing=()
for p in clang libclang-rt-14-dev; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq
  $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

cmake -S . -B build/fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
  -DCELL_FUZZ=ON -DCELL_BUILD_TESTS=OFF -DCELL_BUILD_BENCHMARKS=OFF
cmake --build build/fuzz -j "$(nproc)" --target fuzz_automationml fuzz_mesh fuzz_samples

mkdir -p build/fuzz/artifacts
run() {  # target, then seed folders (read only; new inputs go to a scratch copy of the corpus)
  local target=$1
  shift
  local work="build/fuzz/corpus/$target"
  mkdir -p "$work"
  cp -n tests/fuzz/corpus/"$target"/* "$work"/ 2>/dev/null || true
  echo "== $target, $seconds s"
  set +e
  ASAN_OPTIONS=detect_leaks=${LEAKS:-1} build/fuzz/bin/"$target" "$work" "$@" -max_total_time="$seconds" -timeout=10 \
    -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix=build/fuzz/artifacts/"$target"- \
    >"build/fuzz/$target.log" 2>&1
  local code=$?
  set -e
  grep -E "^(stat::|#[0-9]+ *DONE|==[0-9]+==ERROR|SUMMARY)" "build/fuzz/$target.log"
  [ "$code" -eq 0 ] || tail -40 "build/fuzz/$target.log"
  return "$code"
}
run fuzz_automationml deploy/products/lego-tower deploy/products/cranfield
# Assimp 5.2.5 (Debian's) leaks in its OBJ importer on some malformed files (found here; not
# ours to fix, docs/hostile-input.md): leaks are not checked for this target, crashes are.
LEAKS=0 run fuzz_mesh deploy/products/lego-tower/meshes deploy/products/cranfield/meshes -detect_leaks=0
run fuzz_samples
