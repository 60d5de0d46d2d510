#!/usr/bin/env bash
# The main job on the example product: installs what is missing, builds the cell, shows the
# Cranfield benchmark's finished geometry, then runs the whole cell on it (cellctl run:
# cell-sim, station and arm, mobile robot, buffers, and the order's twin as processes on
# DDS): planning, virtual assembly in cell-sim, physical assembly. Writes
#   out/cranfield-product.json   the finished geometry
#   out/cranfield/plan.json      the plan and the findings (schema agile-cell/plan)
#   out/cranfield/report.html    the designer's report: 3D view, findings, margins, Gantt chart
#   out/cranfield/animation.gltf the virtual assembly as a glTF 2.0 animation
#   out/cranfield-events.jsonl   every command event and delivery, in sim time
set -euo pipefail
cd "$(dirname "$0")/.."
bash deploy/install-deps.sh
cmake -S . -B build/release -G Ninja -DCMAKE_BUILD_TYPE=Release -DCELL_BUILD_TESTS=OFF >/dev/null
cmake --build build/release -j "$(nproc)" --target cellctl
mkdir -p out
build/release/bin/cellctl describe deploy/products/cranfield/cranfield.aml
build/release/bin/cellctl describe --json deploy/products/cranfield/cranfield.aml > out/cranfield-product.json
echo
fastdds shm clean >/dev/null 2>&1 || true
build/release/bin/cellctl run deploy/products/cranfield/cranfield.aml --order cranfield --out out/cranfield \
  --events out/cranfield-events.jsonl
