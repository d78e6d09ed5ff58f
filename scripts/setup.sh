#!/usr/bin/env bash
# Installs the Debian 12 packages tgnav needs (only those missing), then configures and builds
# tgnav in build/ (Release, all cores). Idempotent: a second run only rebuilds what changed.
# Extra CMake arguments may be passed in TGNAV_CMAKE_ARGS.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)

packages=(
  g++ cmake make pkg-config
  libmujoco-dev libqhull-dev          # MuJoCo 2.2 (its CMake target names qhull's include dir)
  libegl-dev libegl-mesa0 libgl-dev libgl1-mesa-dri   # headless EGL, llvmpipe software GL
  libeigen3-dev libopencv-dev libyaml-cpp-dev libcli11-dev nlohmann-json3-dev liboctomap-dev
  libompl-dev libtbb-dev              # RRT* baseline; homology classes evaluated in parallel
  liblbfgspp-dev                      # trajectory optimisation (L-BFGS)
  libceres-dev                        # the VO's local bundle adjustment
  libopencv-contrib-dev               # cv::rgbd::RgbdOdometry, the peer in the VO benchmark
  libboost-serialization-dev libboost-filesystem-dev libboost-system-dev  # OMPL's CMake links these
  libgtest-dev libgmock-dev libbenchmark-dev
  python3-matplotlib                  # every figure (scripts/tgnav_plots.py)
  clang-format-14                     # the style check (scripts/check_format.sh, CTest format.check)
  clang-14 libclang-rt-14-dev clang-tidy-14  # sanitizers, libFuzzer, clang-tidy (scripts/sanitize.sh, tidy.sh)
  slurmctld slurmd slurm-client munge # the Slurm sweep backend's test (a private single-node cluster)
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}" >&2
  sudo=""
  if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null || { echo "setup: need root (or sudo) to apt-get install ${missing[*]}" >&2; exit 1; }
    sudo=sudo
  fi
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
fi

# shellcheck disable=SC2086
cmake -S "$root" -B "$root/build" -DCMAKE_BUILD_TYPE=Release -DTGNAV_BUILD_TESTS=ON \
  ${TGNAV_CMAKE_ARGS:-} >/dev/null
cmake --build "$root/build" -j"$(nproc)" >&2
