#!/usr/bin/env bash
# The main job on the example product: installs what is missing, builds cellctl, shows the
# Cranfield benchmark's finished geometry and plans its assembly by virtual assembly.
set -euo pipefail
cd "$(dirname "$0")/.."
bash deploy/install-deps.sh
cmake -S . -B build/release -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build/release -j "$(nproc)" --target cellctl
mkdir -p out
build/release/deploy/cellctl/cellctl describe deploy/products/cranfield/cranfield.aml
build/release/deploy/cellctl/cellctl describe --json deploy/products/cranfield/cranfield.aml > out/cranfield-product.json
echo
build/release/deploy/cellctl/cellctl plan deploy/products/cranfield/cranfield.aml --json out/cranfield-plan.json --gltf out/cranfield.gltf
