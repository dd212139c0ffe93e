#!/usr/bin/env bash
# The main job on the bundled sample, given the mirage binary, the data folder and an output
# folder. Kept apart from run-sample.sh so that a test can run exactly what the README runs.
set -euo pipefail
mirage="$1"; data="$2"; out="$3"
mkdir -p "$out"
"$mirage" info
echo "sample job: no renderer yet"
