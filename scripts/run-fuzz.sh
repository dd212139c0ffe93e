#!/usr/bin/env bash
# Long runs of every loader's fuzz target (docs/development.md, "Fuzzing"): each target runs until
# it has executed MIRAGE_FUZZ_RUNS inputs or MIRAGE_FUZZ_SECONDS have passed, whichever is first,
# one target after another, and prints one summary line per target. Crashing inputs are saved to
# BUILD_DIR/tests/output/fuzz. Exits non-zero if any target found something.
#
#   scripts/run-fuzz.sh                          # build/, 10^6 inputs each, at most 1 h each
#   scripts/run-fuzz.sh build-asan               # the sanitizer build (scripts/run-sanitizers.sh)
#   MIRAGE_FUZZ_RUNS=100000 MIRAGE_FUZZ_SEED=3 scripts/run-fuzz.sh
set -uo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$root/build}"
case "$build" in /*) ;; *) build="$root/$build" ;; esac
runs="${MIRAGE_FUZZ_RUNS:-1000000}"
seconds="${MIRAGE_FUZZ_SECONDS:-3600}"
seed="${MIRAGE_FUZZ_SEED:-7}"
crashes="$build/tests/output/fuzz"
corpus="$root/tests/fuzz/corpus"
mkdir -p "$crashes"
export ASAN_OPTIONS="detect_leaks=0:abort_on_error=1:${ASAN_OPTIONS:-}"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1:${UBSAN_OPTIONS:-}"

failed=0
run() {  # target corpus-dirs...
  local target=$1
  shift
  local exe="$build/tests/$target"
  if [ ! -x "$exe" ]; then
    echo "run-fuzz: $exe is missing (build it: ninja -C $build $target)" >&2
    failed=1
    return
  fi
  local args=()
  for d in "$@"; do args+=(--corpus "$d"); done
  # OpenCV's decoders print a line per rejected image on stderr; keep only the summary.
  local log
  log="$("$exe" --runs "$runs" --seconds "$seconds" --seed "$seed" "${args[@]}" \
    --crash-dir "$crashes" 2>&1)"
  local rc=$?
  local summary
  summary="$(grep -E "^$target: [0-9]+ inputs" <<<"$log" | tail -1)"
  if [ $rc -ne 0 ] || [ -z "$summary" ]; then
    echo "$target: FAILED (exit $rc)"
    grep -E "fuzz:|ERROR|runtime error|Sanitizer" <<<"$log" | head -20
    failed=1
  else
    echo "$summary"
  fi
}

run scene_loader_fuzz "$root/tests/data/scenes/good" "$root/tests/data/scenes/bad"
run calibration_fuzz "$root/tests/data/calib" "$root/tests/data/calib/bad"
run board_fuzz "$root/data/boards" "$corpus/board"
run session_fuzz "$corpus/session"
run poses_csv_fuzz "$corpus/poses"
run matroska_fuzz "$corpus/matroska"
run env_image_fuzz "$corpus/envimage" "$root/tests/data/scenes/good"
run density_grid_fuzz "$corpus/density" "$root/tests/data/scenes/good"
exit $failed
