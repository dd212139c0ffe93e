#!/usr/bin/env bash
# The sanitizer suite (docs/development.md): build everything with AddressSanitizer +
# UndefinedBehaviorSanitizer and run every test, the fuzz targets included, then give each fuzz
# target a longer run. UBSan stops at the first error; the leak checker is off (LeakSanitizer's
# tracer crashes at the exit of processes that ran llvmpipe's threads).
#
#   scripts/run-sanitizers.sh                 # build-asan/, fuzz targets 60 s each afterwards
#   MIRAGE_FUZZ_EXTRA_SECONDS=0 scripts/run-sanitizers.sh    # tests only
#   MIRAGE_BUILD_DIR=/tmp/asan scripts/run-sanitizers.sh
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${MIRAGE_BUILD_DIR:-$root/build-asan}"
extra="${MIRAGE_FUZZ_EXTRA_SECONDS:-60}"
jobs="${MIRAGE_JOBS:-$(nproc)}"

cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMIRAGE_SANITIZE=ON \
  -DMIRAGE_WERROR=ON "$@"
ninja -C "$build" -j "$jobs"

export ASAN_OPTIONS="detect_leaks=0:abort_on_error=1:${ASAN_OPTIONS:-}"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1:${UBSAN_OPTIONS:-}"
start=$(date +%s)
(cd "$build" && ctest -j "$jobs" --timeout 1500 --output-on-failure)
echo "run-sanitizers: tests passed in $(($(date +%s) - start)) s"

if [ "$extra" -gt 0 ]; then
  MIRAGE_FUZZ_SECONDS="$extra" MIRAGE_FUZZ_RUNS="${MIRAGE_FUZZ_RUNS:-0}" \
    "$root/scripts/run-fuzz.sh" "$build"
fi
