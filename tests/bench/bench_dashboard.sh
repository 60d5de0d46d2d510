#!/usr/bin/env bash
# What the dashboard costs cellctl up: ORDERS orders (Lego towers and Cranfield in turn) on the
# two-station cell, once with no dashboard and once with one that a page follows (curl on its
# event stream); prints cellctl up's CPU seconds (its own threads: observer, desks, supervisor,
# and the dashboard's feed and server) and its peak resident memory, each run.
#   tests/bench/bench_dashboard.sh [ORDERS=20] [DOMAIN=176]
set -euo pipefail
orders=${1:-20}
domain=${2:-176}
root=$(cd "$(dirname "$0")/../.." && pwd)
cellctl="$root/build/release/bin/cellctl"
cell="$root/deploy/cells/two-stations.yaml"
hz=$(getconf CLK_TCK)

run() {  # $1: "with" or "without"
  local dir
  dir=$(mktemp -d /tmp/bench-dashboard-XXXXXX)
  local args=(up "$cell" --domain "$domain" --state-dir "$dir/state")
  [ "$1" = with ] && args+=(--dashboard 127.0.0.1:0)
  "$cellctl" "${args[@]}" > "$dir/up.log" 2>&1 &
  local up=$!
  until grep -q "cell up on domain" "$dir/up.log"; do sleep 0.2; done
  local follower=""
  if [ "$1" = with ]; then
    local url port token
    url=$(grep -o "http://127.0.0.1:[0-9]*/" "$dir/up.log")
    token=$(cat "$dir/state/dashboard.token")
    curl -sN -H "Authorization: Bearer $token" "${url}events" > "$dir/events.txt" &
    follower=$!
  fi
  local start
  start=$(date +%s.%N)
  for i in $(seq 1 "$orders"); do
    local product=lego-tower/lego-tower.aml
    [ $((i % 2)) -eq 0 ] && product=cranfield/cranfield.aml
    "$cellctl" submit "$root/deploy/products/$product" --domain "$domain" --order "order-$i" --out "$dir/order-$i" --detach > /dev/null
  done
  until "$cellctl" status --cell "$cell" --domain "$domain" --json 2> /dev/null |
        python3 -c "import json,sys; s=json.load(sys.stdin); o=[x for x in s['orders'] if not x['quote']]; sys.exit(0 if len(o) >= $orders and all(x['state'] in ('DONE','FAILED') for x in o) else 1)"; do
    sleep 1
  done
  local wall cpu rss done_count
  wall=$(echo "$(date +%s.%N) - $start" | bc)
  read -r utime stime < <(awk '{print $14, $15}' "/proc/$up/stat")
  cpu=$(echo "scale=2; ($utime + $stime) / $hz" | bc)
  rss=$(awk '/VmHWM/ {print $2}' "/proc/$up/status")
  done_count=$("$cellctl" status --cell "$cell" --domain "$domain" --json | python3 -c "import json,sys; print(sum(o['state']=='DONE' for o in json.load(sys.stdin)['orders']))")
  [ -n "$follower" ] && kill "$follower" 2> /dev/null || true
  local events=0
  [ -f "$dir/events.txt" ] && events=$(grep -c "^event: state" "$dir/events.txt" || true)
  "$cellctl" down --domain "$domain" > /dev/null
  wait "$up" || true
  printf "%-8s dashboard: %d orders (%d done) in %.0f s wall; cellctl up: %.2f CPU s (%.2f %% of a core), peak RSS %d MB; states pushed %d\n" \
    "$1" "$orders" "$done_count" "$wall" "$cpu" "$(echo "scale=4; 100 * $cpu / $wall" | bc)" $((rss / 1024)) "$events"
  rm -rf "$dir"
}

run without
run with
