#!/usr/bin/env bash
# Two mirage builds side by side on one session: `mirage bench` of each in turn, in ABBA order
# (A B, B A, A B, ...), so that drift of a shared machine falls on both alike; then per round the
# ratio B / A of the frame time, and their median and range.
#
# usage: A=OLD_MIRAGE B=NEW_MIRAGE scripts/bench-abba.sh SESSION ROUNDS OUTDIR [bench args...]
#   A_KNOBS / B_KNOBS: extra arguments for one build only (e.g. knobs whose defaults differ, so
#   that both render the same effects). The bench args go to both; add at least --knob
#   resolution=... and --repeat N. Each run writes OUTDIR/{a,b}-ROUND/ (bench.csv, bench.md).
# Figures: wall ms with sync_passes=off (as replay renders), GPU ms with sync_passes=on, PSNR over
# the influenced pixels; the load average before each run is printed beside it.
set -euo pipefail

if [ $# -lt 3 ] || [ -z "${A:-}" ] || [ -z "${B:-}" ]; then
    sed -n '2,11p' "$0" | sed 's/^# \{0,1\}//'
    exit 2
fi
session=$1
rounds=$2
out=$3
shift 3
for bin in "$A" "$B"; do
    [ -x "$bin" ] || { echo "bench-abba: $bin is not an executable mirage" >&2; exit 2; }
done
[ -d "$session" ] || { echo "bench-abba: session $session is not a directory" >&2; exit 2; }
mkdir -p "$out"

run() {  # which round [bench args...]
    local which=$1 round=$2 bin knobs
    shift 2
    if [ "$which" = a ]; then bin=$A knobs=${A_KNOBS:-}; else bin=$B knobs=${B_KNOBS:-}; fi
    echo "round $round $which: load $(cut -d' ' -f1-3 /proc/loadavg)"
    # shellcheck disable=SC2086  # the knob strings are word lists
    "$bin" bench "$session" -o "$out/$which-$round" --knob sync_passes=on,off --no-baseline \
        "$@" $knobs >"$out/$which-$round.log" 2>&1 ||
        { echo "bench-abba: $bin failed, see $out/$which-$round.log" >&2; exit 1; }
}

for round in $(seq 1 "$rounds"); do
    if [ $((round % 2)) = 1 ]; then
        run a "$round" "$@"
        run b "$round" "$@"
    else
        run b "$round" "$@"
        run a "$round" "$@"
    fi
done

# One line per run: sync_passes, wall ms, GPU ms, PSNR (bench.csv, columns found by name).
values() {
    awk -F, '/^#/ { next }
        !header { for (i = 1; i <= NF; ++i) col[$i] = i; header = 1; next }
        { print $col["sync_passes"], $col["wall_ms"], $col["gpu_ms"], $col["psnr_influenced_db"] }' \
        "$1/bench.csv"
}

{
    for round in $(seq 1 "$rounds"); do
        paste -d' ' <(values "$out/a-$round") <(values "$out/b-$round") | sed "s/^/$round /"
    done
} | awk '
    # round sync wallA gpuA psnrA sync wallB gpuB psnrB
    $2 == "off" { wall[++n] = $7 / $3; wa[n] = $3; wb[n] = $7; pa = $5; pb = $9 }
    $2 == "on" { gpu[++m] = $8 / $4 }
    function median(v, k,   s, i, j, t) {
        for (i = 1; i <= k; ++i) s[i] = v[i]
        for (i = 1; i <= k; ++i) for (j = i + 1; j <= k; ++j) if (s[j] < s[i]) { t = s[i]; s[i] = s[j]; s[j] = t }
        return k % 2 ? s[(k + 1) / 2] : (s[k / 2] + s[k / 2 + 1]) / 2
    }
    function range(v, k,   lo, hi, i) {
        lo = hi = v[1]
        for (i = 2; i <= k; ++i) { if (v[i] < lo) lo = v[i]; if (v[i] > hi) hi = v[i] }
        return sprintf("[%.2f..%.2f]", lo, hi)
    }
    END {
        for (i = 1; i <= n; ++i) printf "round %d: wall %.1f / %.1f ms, B/A %.3f\n", i, wb[i], wa[i], wall[i]
        printf "B/A wall (sync_passes=off): median %.3f %s over %d rounds\n", median(wall, n), range(wall, n), n
        printf "B/A GPU (sync_passes=on):   median %.3f %s over %d rounds\n", median(gpu, m), range(gpu, m), m
        printf "median wall ms: A %.1f, B %.1f; PSNR influenced (last round): A %s, B %s dB\n", median(wa, n), median(wb, n), pa, pb
    }'
