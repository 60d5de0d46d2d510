#!/usr/bin/env bash
# Installs every Debian package the project needs to build, test and run.
# Idempotent and non-interactive: packages already present are skipped.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev libbullet-dev libpugixml-dev catch2
  libassimp-dev libtinygltf-dev libcli11-dev libspdlog-dev nlohmann-json3-dev libyaml-cpp-dev
  libompl-dev libboost-filesystem-dev libboost-serialization-dev libboost-system-dev
  libbenchmark-dev libsqlite3-dev sqlite3 libcgal-dev
  libfcl-dev libopenvdb-dev libboost-iostreams-dev libbullet-extras-dev  # only for bench_collision_libraries:
                 # our check against FCL's, OpenVDB's distance fields (its CMake module wants Boost
                 # iostreams, which the package does not pull) and Bullet's HACD decomposition
  libfastrtps-dev libfastcdr-dev fastddsgen fastdds-tools libssl-dev openssl
  libjs-three    # the designer's report carries three.js (built into cellctl and the twin)
  chromium ffmpeg  # cellctl plan --video renders the report headless; the tests open it
  clang libclang-rt-14-dev  # the sanitizer builds and the libFuzzer targets (deploy/test.sh)
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

# Node.js runs the Khronos glTF validator in the tests; a machine that has node and npm
# already (from whichever source) keeps them.
command -v node >/dev/null && command -v npm >/dev/null || missing+=(nodejs npm)

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all packages present"
else
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  echo "install-deps: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq
  $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# The glTF validator, pinned by tests/gltf/package-lock.json.
cd "$(dirname "$0")/.."
[ -d tests/gltf/node_modules/gltf-validator ] || npm ci --prefix tests/gltf --no-audit --no-fund --loglevel=error
# puppeteer-core, which drives Debian's chromium for the report's tests (it fetches no browser).
[ -d tests/browser/node_modules/puppeteer-core ] || npm ci --prefix tests/browser --no-audit --no-fund --loglevel=error
