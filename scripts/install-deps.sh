#!/usr/bin/env bash
# Installs what mirage needs from Debian 12 packages (nothing else is downloaded). Idempotent:
# packages already present are skipped, so re-running costs a second.
set -euo pipefail

packages=(
  cmake ninja-build pkg-config g++ git
  libopencv-dev libapriltag-dev libembree-dev libglfw3-dev libglm-dev libv4l-dev libepoxy-dev
  libtinygltf-dev libcli11-dev libspdlog-dev nlohmann-json3-dev libimgui-dev libjpeg62-turbo-dev
  libgtest-dev libgmock-dev libbenchmark-dev libopen3d-dev
  libegl-dev libgl-dev libegl-mesa0 libgl1-mesa-dri glslang-tools libopenexr-dev
  ffmpeg xvfb xauth clang-format
  slurm-wlm munge
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

sudo=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install-deps: need root or sudo to install: ${missing[*]}" >&2; exit 1; }
  sudo="sudo"
fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -q
$sudo apt-get install -y -q --no-install-recommends "${missing[@]}"
