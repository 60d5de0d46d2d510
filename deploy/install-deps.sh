#!/usr/bin/env bash
# Installs the Debian packages the project needs: with no argument, what building and running
# the cell takes (deploy/run-example.sh); with --tests, also what the tests, the benchmarks,
# the sanitizer builds and the fuzzers take (deploy/test.sh).
# Idempotent and non-interactive: packages already present are skipped.
set -euo pipefail

tests=false
case "${1:-}" in
  "") ;;
  --tests) tests=true ;;
  *) echo "usage: $0 [--tests]" >&2; exit 2 ;;
esac

packages=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev libbullet-dev libpugixml-dev libcgal-dev
  coinor-libclp-dev  # the linear programs of the gravity check (twin/planning/stability.cpp)
  libassimp-dev libtinygltf-dev libcli11-dev nlohmann-json3-dev libyaml-cpp-dev
  libompl-dev libboost-filesystem-dev libboost-serialization-dev libboost-system-dev
  libsqlite3-dev sqlite3
  nettle-dev     # SHA-256 of the mesh cache's keys, base64 (light to load: cellctl plan's start)
  libfastrtps-dev libfastcdr-dev fastddsgen fastdds-tools libssl-dev openssl
  libjs-three    # the designer's report carries three.js (built into cellctl and the twin)
  libcpp-httplib-dev  # cellctl up's dashboard: its HTTP server
  libminizip-dev      # the dashboard's uploads: a product as one zip
)
if $tests; then
  packages+=(
    catch2 libbenchmark-dev
    libfcl-dev libopenvdb-dev libboost-iostreams-dev libbullet-extras-dev  # only for bench_collision_libraries:
                   # our check against FCL's, OpenVDB's distance fields (its CMake module wants Boost
                   # iostreams, which the package does not pull) and Bullet's HACD decomposition
    libcivetweb-dev  # only for bench_http_servers: the dashboard's HTTP library against civetweb
    chromium ffmpeg  # cellctl plan --video renders the report headless; the tests open it
    clang libclang-rt-14-dev  # the sanitizer builds and the libFuzzer targets (deploy/test.sh)
  )
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

# Node.js runs the Khronos glTF validator in the tests; a machine that has node and npm
# already (from whichever source) keeps them.
if $tests; then
  command -v node >/dev/null && command -v npm >/dev/null || missing+=(nodejs npm)
fi

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

$tests || exit 0
# The glTF validator, pinned by tests/gltf/package-lock.json.
cd "$(dirname "$0")/.."
[ -d tests/gltf/node_modules/gltf-validator ] || npm ci --prefix tests/gltf --no-audit --no-fund --loglevel=error
# puppeteer-core, which drives Debian's chromium for the report's tests (it fetches no browser).
[ -d tests/browser/node_modules/puppeteer-core ] || npm ci --prefix tests/browser --no-audit --no-fund --loglevel=error
