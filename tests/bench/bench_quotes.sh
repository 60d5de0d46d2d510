#!/usr/bin/env bash
# Quotes against what the cell then does, on PAIRS pairs of cells generated at random (the
# process test "quotes come true", tests/cell/test_quote_accuracy.cpp, run for more pairs,
# at 8 times real time):
# prints each cell's quoted makespan over its executed physical span, how many lie within
# 10 %, and how often the best by time and by cost were marked right.
#   tests/bench/bench_quotes.sh [PAIRS=10]
set -euo pipefail
pairs=${1:-10}
root=$(cd "$(dirname "$0")/../.." && pwd)
log=$(mktemp /tmp/bench-quotes-XXXXXX.log)
AGILE_CELL_QUOTE_PAIRS=$pairs AGILE_CELL_QUOTE_FACTOR=8 "$root/build/release/bin/process_tests" "quotes come true*" > "$log" 2>&1 || true
grep "quote accuracy:" "$log"
grep "ratio" "$log" | awk '{r = $NF; n++; if (r < lo || n == 1) lo = r; if (r > hi || n == 1) hi = r;
  if (r >= 0.9 && r <= 1.1) ok++; s += r}
  END {printf "cells %d, within 10 %%: %d, ratio min %.3f mean %.3f max %.3f\n", n, ok, lo, s / n, hi}'
echo "best marked right: $(grep -c " right" "$log" || true) of $(grep -c "best by" "$log" || true) (pairs whose cells differ by more than 10 %)"
tail -3 "$log"
