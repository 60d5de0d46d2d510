#!/usr/bin/env python3
"""Schedules on a heterogeneous cell (issue #34's goals): N mixed orders (Cranfield and the
Lego tower in turn) handed to `cellctl run` at once on a two-station cell whose arms differ,
and on the same cell with its faster station only. From the events file it prints the
makespan, each arm's orders and motion time, the arms' idle time at each change of order,
and the arms' lower bound:

  the fluid bound: every order's arm work in metres (its motion time on the arm it ran on
  times that arm's speed; turns scale alike at the cells' equal angular speeds), shared by
  both arms at once, so work / (v1 + v2); and never less than the longest order on the
  faster arm. Messages and fetches are left out, so the bound is below any real schedule.

  tests/bench/bench_schedule.py [ORDERS=10] [CELL=deploy/cells/mixed-stations.yaml]
"""
import json
import os
import re
import subprocess
import sys
import tempfile

import yaml  # python3-yaml

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CELLCTL = os.path.join(ROOT, "build", "release", "bin", "cellctl")
PRODUCTS = [os.path.join(ROOT, "deploy", "products", p) for p in ("cranfield/cranfield.aml", "lego-tower/lego-tower.aml")]


def run(cell_file, orders, work):
    events = os.path.join(work, os.path.basename(cell_file) + ".jsonl")
    products = [PRODUCTS[i % 2] for i in range(orders)]
    out = subprocess.run([CELLCTL, "run", "--cell", cell_file, *products, "--events", events,
                          "--out", os.path.join(work, "out-" + os.path.basename(cell_file)),
                          "--state-dir", os.path.join(work, "state-" + os.path.basename(cell_file))],
                         capture_output=True, text=True, timeout=1800)
    if out.returncode != 0:
        sys.exit("cellctl run failed:\n" + out.stdout[-3000:] + out.stderr[-3000:])
    makespan = float(re.search(r"makespan ([0-9.]+) sim s", out.stdout).group(1))
    physical = [json.loads(line) for line in open(events)]
    physical = [e for e in physical if "/virtual/" not in e.get("part", "")]
    return makespan, physical


def arms(cell):
    return {s["arm"]: s["arm_speed"] for s in cell.get("stations", [cell.get("station")]) if s}


def analyse(name, makespan, physical, speeds):
    moving = {}
    orders_of = {}
    for e in physical:
        if e["resource"] not in speeds:
            continue
        runs = orders_of.setdefault(e["resource"], [])
        if not runs or runs[-1][0] != e["order"]:
            runs.append([e["order"], e["t"], e["t"]])
        runs[-1][2] = max(runs[-1][2], e["t"])
        if e["event"] == "succeeded" and "duration" in e:
            moving[(e["resource"], e["order"])] = moving.get((e["resource"], e["order"]), 0) + e["duration"]
    work = {order: busy * speeds[arm] for (arm, order), busy in moving.items()}
    bound = max(sum(work.values()) / sum(speeds.values()), max(work.values()) / max(speeds.values()))
    idle = [b[1] - a[2] for runs in orders_of.values() for a, b in zip(runs, runs[1:])]
    print(f"{name}: makespan {makespan:.1f} s, arms' lower bound {bound:.1f} s ({makespan / bound:.2f}x)")
    for arm, runs in sorted(orders_of.items()):
        busy = sum(t for (a, _), t in moving.items() if a == arm)
        print(f"  {arm} ({speeds[arm]} m/s): {len(runs)} orders, moving {busy:.1f} s")
    if idle:
        print(f"  idle at a change of order: mean {sum(idle) / len(idle):.1f} s, max {max(idle):.1f} s ({len(idle)} changes)")
    return makespan


def main():
    orders = int(sys.argv[1]) if len(sys.argv) > 1 else 10
    cell_file = sys.argv[2] if len(sys.argv) > 2 else os.path.join(ROOT, "deploy", "cells", "mixed-stations.yaml")
    cell = yaml.safe_load(open(cell_file))
    with tempfile.TemporaryDirectory(prefix="bench-schedule-") as work:
        # The same cell with its faster station only.
        fastest = max(cell["stations"], key=lambda s: s["arm_speed"])
        one = dict(cell, stations=[fastest])
        one_file = os.path.join(work, "one-station.yaml")
        with open(one_file, "w") as f:
            yaml.safe_dump(one, f)
        two = analyse(f"{len(cell['stations'])} stations, {orders} orders", *run(cell_file, orders, work), arms(cell))
        single = analyse(f"1 station ({fastest['arm']}), {orders} orders", *run(one_file, orders, work), arms(one))
        print(f"two stations / one: {two / single:.2f}")


if __name__ == "__main__":
    main()
