#!/usr/bin/env bash
# The main job on the example product: installs what is missing, builds cellctl and shows
# the Cranfield benchmark's finished geometry (parts, links, final positions).
set -euo pipefail
cd "$(dirname "$0")/.."
bash deploy/install-deps.sh
cmake -S . -B build/release -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build/release -j "$(nproc)" --target cellctl
mkdir -p out
build/release/deploy/cellctl/cellctl describe deploy/products/cranfield/cranfield.aml
build/release/deploy/cellctl/cellctl describe --json deploy/products/cranfield/cranfield.aml > out/cranfield.json
echo "wrote out/cranfield.json"
