#!/usr/bin/env bash
# The main job on the bundled sample, given the mirage binary, the data folder and an output
# folder: composite the tabletop scene's virtual objects into the sample session's footage, the
# camera tracked live from its AprilTag board (mirage replay), and report the tracking accuracy
# against the session's ground truth (mirage track). Kept apart from
# run-sample.sh so that a test can run exactly what the README runs (tests/app/SampleJob_test.cpp).
# The scene is the backlit tabletop: the sample was synthesised from it, so its real spot light is
# the one that lit the footage (data/README.md).
set -euo pipefail
mirage="$1"; data="$2"; out="$3"
mkdir -p "$out"
session="$data/sessions/sample"
scene="$data/scenes/tabletop/tabletop_backlit.gltf"

"$mirage" track "$session" -o "$out/poses.csv"
"$mirage" replay "$session" --scene "$scene" -o "$out/replay.mkv"

echo
echo "sample job done:"
echo "  composited video:        $out/replay.mkv"
echo "  per-frame timings/state: $out/replay.csv"
echo "  tracked camera poses:    $out/poses.csv"
