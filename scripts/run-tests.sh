#!/usr/bin/env bash
# README command (2): install what is missing, build with warnings as errors, run every test.
# Headless: GL tests use EGL's surfaceless platform, so no display or Xvfb is needed.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/install-deps.sh"
"$root/scripts/build.sh" -DMIRAGE_WERROR=ON "$@"
build="${MIRAGE_BUILD_DIR:-$root/build}"
cd "$build"
ctest --output-on-failure -j "$(nproc)" --timeout 900
