#!/usr/bin/env bash
# Installs the Debian 12 packages tgnav needs (only those missing), then configures and builds
# tgnav in build/ (Release, all cores). Idempotent: a second run only rebuilds what changed.
# Extra CMake arguments may be passed in TGNAV_CMAKE_ARGS.
#
# Quiet: one line per step on stderr; apt-get's and the build's own output go to a log
# (build/setup.log, or TGNAV_SETUP_LOG), whose last lines and path are printed when a step
# fails. TGNAV_VERBOSE=1 shows everything as it happens instead.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
log=${TGNAV_SETUP_LOG:-$root/build/setup.log}
mkdir -p "$(dirname "$log")"
: >"$log"

# step DESCRIPTION COMMAND...: runs COMMAND into the log (or to the terminal with TGNAV_VERBOSE=1).
step() {
  local what=$1
  shift
  echo "setup: $what" >&2
  if [ "${TGNAV_VERBOSE:-0}" = 1 ]; then
    "$@" >&2 && return 0
  elif "$@" >>"$log" 2>&1; then
    return 0
  fi
  echo "setup: failed: $what; the end of $log:" >&2
  tail -n 25 "$log" >&2
  echo "setup: the whole log: $log" >&2
  exit 1
}

packages=(
  g++ cmake make pkg-config
  ninja-build                         # the sanitizer build (scripts/sanitize.sh: its targets in parallel)
  lld                                 # the linker (CMakeLists.txt: links about 5 times faster than ld.bfd)
  libmujoco-dev libqhull-dev          # MuJoCo 2.2 (its CMake target names qhull's include dir)
  libegl-dev libegl-mesa0 libgl-dev libgl1-mesa-dri   # headless EGL, llvmpipe software GL
  libeigen3-dev libopencv-dev libyaml-cpp-dev libcli11-dev nlohmann-json3-dev liboctomap-dev
  libompl-dev libtbb-dev              # RRT* baseline; homology classes evaluated in parallel
  liblbfgspp-dev                      # trajectory optimisation (L-BFGS)
  libceres-dev                        # the VO's reference bundle-adjustment solver (ba.solver ceres)
  libopencv-contrib-dev               # cv::rgbd::RgbdOdometry, the peer in the VO benchmark
  libboost-serialization-dev libboost-filesystem-dev libboost-system-dev  # OMPL's CMake links these
  libgtest-dev libgmock-dev libbenchmark-dev
  python3-matplotlib                  # every figure (scripts/tgnav_plots.py)
  python3-numpy                       # the example external planners (scripts/planners/)
  python3-sklearn python3-scipy       # the learned perception model (scripts/fit_track_model.py), route_oracle.py
  python3-yaml                        # scene and trial files in scripts/route_oracle.py
  clang-format-14                     # the style check (scripts/check_format.sh, CTest format.check)
  clang-14 libclang-rt-14-dev clang-tidy-14  # sanitizers, libFuzzer, clang-tidy (scripts/sanitize.sh, tidy.sh)
  slurmctld slurmd slurm-client munge # the Slurm sweep backend's test (a private single-node cluster)
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  sudo=""
  if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null || { echo "setup: need root (or sudo) to apt-get install ${missing[*]}" >&2; exit 1; }
    sudo=sudo
  fi
  names="${missing[*]:0:5}"
  ((${#missing[@]} <= 5)) || names="$names, ..."
  step "updating the package lists (apt-get update)" $sudo apt-get update -q
  step "installing ${#missing[@]} Debian packages ($names)" \
    $sudo env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

# shellcheck disable=SC2086
step "configuring build/ (CMake, Release)" cmake -S "$root" -B "$root/build" -DCMAKE_BUILD_TYPE=Release \
  -DTGNAV_BUILD_TESTS=ON ${TGNAV_CMAKE_ARGS:-}
step "building build/ with $(nproc) jobs (log: $log)" cmake --build "$root/build" -j"$(nproc)"
