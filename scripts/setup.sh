#!/usr/bin/env bash
# Installs planeloc's Debian build and run dependencies. Idempotent: runs `apt-get update` and
# `apt-get install` only when a package is missing.
set -euo pipefail

PACKAGES=(
  build-essential cmake pkg-config git clang-format
  libopencv-dev libceres-dev libeigen3-dev libopen3d-dev libtbb-dev
  libcli11-dev libspdlog-dev libfmt-dev nlohmann-json3-dev libyaml-cpp-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  python3 python3-matplotlib python3-numpy python3-pil
  # `import planeloc` (python/, issue 36) and its pytest suite.
  pybind11-dev python3-dev python3-pytest
  libjs-three chromium
  # cpp-httplib: the live view of `planeloc run --view` (issue 36).
  libcpp-httplib-dev
  # clang and its sanitizer and libFuzzer runtimes: scripts/test.sh --sanitize, scripts/fuzz.sh.
  clang libclang-rt-14-dev
  # Open MPI: `mpirun -n N planeloc map planes --tiles ...` (issue 15; the build finds it and
  # turns PLANELOC_WITH_MPI on).
  libopenmpi-dev openmpi-bin
  # ROS 1 (issue 14): rosbag input (`run --bag`, `convert kitti-to-bag`) and planeloc_node. The
  # build works without them (cmake/PlanelocRos.cmake turns both off and says so).
  ros-core-dev librosbag-dev libcv-bridge-dev libtf2-ros-dev ros-sensor-msgs ros-nav-msgs
  libsensor-msgs-dev libnav-msgs-dev libvisualization-msgs-dev ros-visualization-msgs
  python3-rosmaster
)
# libjs-three: three.js, inlined into the pages of `planeloc report`. chromium and python3-pil:
# tests/report_browser_test.sh opens such a page headless and measures its screenshot.

missing=()
for pkg in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$pkg")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "[setup] all ${#PACKAGES[@]} Debian packages present"
  exit 0
fi

echo "[setup] missing Debian packages: ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then
    SUDO="sudo"
  else
    echo "[setup] error: not root and no sudo. Run as root:" >&2
    echo "  apt-get update && apt-get install -y ${missing[*]}" >&2
    exit 2
  fi
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
echo "[setup] installed: ${missing[*]}"
