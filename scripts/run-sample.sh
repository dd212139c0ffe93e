#!/usr/bin/env bash
# README command (1): install what is missing, build, and run the main job on the bundled sample.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/install-deps.sh"
"$root/scripts/build.sh"
build="${MIRAGE_BUILD_DIR:-$root/build}"
out="$root/out/sample"
mkdir -p "$out"

"$root/scripts/sample-job.sh" "$build/app/mirage" "$root/data" "$out"
