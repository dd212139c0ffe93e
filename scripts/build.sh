#!/usr/bin/env bash
# Configures and builds mirage into build/ (or $MIRAGE_BUILD_DIR). Extra arguments go to cmake,
# e.g. scripts/build.sh -DMIRAGE_SANITIZE=ON.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${MIRAGE_BUILD_DIR:-$root/build}"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo "$@"
cmake --build "$build" -j "$(nproc)"
