#!/usr/bin/env bash
# A day's orders through the cell's queue: `cellctl up` on a deployment file with max_twins
# set, N Lego towers handed over at once with `cellctl submit --detach`, `cellctl up` killed
# hard once when a third of them have ended and started again on the same state, and the
# time until every order has ended. Prints the orders done and failed, the wall time, the
# orders a minute, the most twins seen at once, the peak of the cell's summed RSS, and the
# wall time against the arms' lower bound: one tower's arm work (measured first, by a
# `cellctl run --events` of one tower on the same cell) times N, shared by the cell's arms
# (equal arms, as in four-stations.yaml), at the real-time factor. At a high factor the
# machine's cores, not the arms, bound the throughput: measure the bound at a low one.
#   tests/bench/bench_queue.sh [ORDERS=200] [MAX_TWINS=20] [CELL=deploy/cells/four-stations.yaml] [DOMAIN=60] [FACTOR=20]
set -euo pipefail
orders=${1:-200} max_twins=${2:-20} cell_file=${3:-deploy/cells/four-stations.yaml} domain=${4:-60} factor=${5:-20}
root=$(cd "$(dirname "$0")/../.." && pwd)
bin=$root/build/release/bin
work=$(mktemp -d /tmp/bench-queue-XXXXXX)
# The racks hold bricks for 240 towers (the file's for 60).
sed -e "s/^max_twins:.*//" -e "s/Brick2x4: 180, Brick2x2: 150/Brick2x4: 720, Brick2x2: 600/" "$cell_file" > "$work/cell.yaml"
echo "max_twins: $max_twins" >> "$work/cell.yaml"
product=$root/deploy/products/lego-tower/lego-tower.aml

# One tower's arm work in sim s: each arm command from its first event to its last.
"$bin/cellctl" run --cell "$work/cell.yaml" --domain "$domain" --real-time-factor "$factor" \
  --events "$work/one.jsonl" --out "$work/one" "$product" > "$work/one.log" 2>&1
arm_work=$(awk '/"resource":"arm-/ {
    match($0, /"command":"[^"]*"/); c = substr($0, RSTART, RLENGTH)
    match($0, /"t":[0-9.]+/); t = substr($0, RSTART + 4, RLENGTH - 4) + 0
    if (!(c in lo) || t < lo[c]) lo[c] = t
    if (!(c in hi) || t > hi[c]) hi[c] = t
  } END { for (c in lo) s += hi[c] - lo[c]; printf "%.2f", s }' "$work/one.jsonl")
arms=$(grep -c "arm_speed" "$work/cell.yaml")
bound=$(echo "scale=1; $orders * $arm_work / $arms / $factor" | bc)
echo "one tower: $arm_work sim s of arm work; $orders on $arms arms at factor $factor: at least $bound s wall"
up_pid=
start_up() {
  "$bin/cellctl" up --cell "$work/cell.yaml" --domain "$domain" --real-time-factor "$factor" --state-dir "$work/state" \
    >> "$work/up.log" 2>&1 &
  up_pid=$!
  until grep -q "cell up on domain" "$work/up.log" 2>/dev/null; do sleep 0.2; done
}
finish() { [ -n "$up_pid" ] && kill "$up_pid" 2>/dev/null && wait "$up_pid" 2>/dev/null; true; }
trap finish EXIT
ended() { sqlite3 -cmd ".timeout 10000" "$work/state/cell.db" "SELECT count(*) FROM orders WHERE state IN ('DONE', 'FAILED')"; }

start_up
t0=$(date +%s.%N)
for i in $(seq "$orders"); do
  "$bin/cellctl" submit --detach "$product" --domain "$domain" --order "o$i" --out "$work/out/o$i" > /dev/null
done
echo "handed over $orders orders in $(echo "$(date +%s.%N) - $t0" | bc) s"
killed=0 most=0 peak_kb=0
while [ "$(ended)" -lt "$orders" ]; do
  twins=$(pgrep -c -x twin || true)
  [ "$twins" -gt "$most" ] && most=$twins
  # A process may end between pgrep and awk: that is no error (set -e, pipefail).
  kb=$(for p in $(pgrep -f "domain $domain" || true); do awk '/VmRSS/{print $2}' "/proc/$p/status" 2>/dev/null || true; done |
       awk '{s+=$1} END {print s+0}')
  [ "$kb" -gt "$peak_kb" ] && peak_kb=$kb
  if [ "$killed" = 0 ] && [ "$(ended)" -ge $((orders / 3)) ]; then
    kill -9 "$up_pid"; wait "$up_pid" 2>/dev/null || true
    while pgrep -f "domain $domain" > /dev/null; do sleep 0.2; done
    echo "cellctl up killed with $(ended) orders ended; starting it again"
    killed=1
    start_up
  fi
  sleep 1
done
t1=$(date +%s.%N)
wall=$(echo "$t1 - $t0" | bc)
done_count=$(sqlite3 -cmd ".timeout 10000" "$work/state/cell.db" "SELECT count(*) FROM orders WHERE state = 'DONE'")
echo "orders: $orders, done $done_count, failed $((orders - done_count)); wall ${wall} s;" \
     "$(echo "scale=1; $orders * 60 / $wall" | bc) orders a minute; at most $most twins at once;" \
     "peak summed RSS $((peak_kb / 1024)) MB; max_twins $max_twins, factor $factor;" \
     "wall / the arms' bound $(echo "scale=2; $wall / $bound" | bc)"
sqlite3 -cmd ".timeout 10000" "$work/state/cell.db" "SELECT order_id, reason FROM orders WHERE state = 'FAILED' LIMIT 5"
echo "logs: $work"
