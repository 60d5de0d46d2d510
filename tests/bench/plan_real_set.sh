#!/bin/sh
# The real test set (tests/data/real, unpacked by the build into BUILD/tests/real) through
# `cellctl plan`, one product after another: per product its wall time, the plan's first line
# and its orientation finding. The figures of docs/performance.md, "Real assemblies".
#   tests/bench/plan_real_set.sh [BUILD]      (default build/release)
set -eu
build=${1:-build/release}
for aml in "$build"/tests/real/*/*.aml; do
  product=$(basename "$(dirname "$aml")")
  start=$(date +%s.%N)
  out=$("$build/bin/cellctl" plan "$aml" --quiet 2>&1 || true)
  end=$(date +%s.%N)
  printf '%s\t%s s\t%s\t%s\n' "$product" "$(awk "BEGIN { printf \"%.1f\", $end - $start }")" \
    "$(echo "$out" | grep '^Plan for' | sed 's/.*): //')" \
    "$(echo "$out" | grep '\[orientation\]' | sed 's/.*\[orientation\] //')"
done
