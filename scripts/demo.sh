#!/usr/bin/env bash
# The main job, on the embedded default: renders the smoke scene's onboard RGB-D view from the
# start pose and from beside the crates, and checks the frames it wrote.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$root/scripts/setup.sh"
out="$root/results/demo"
tgnav="$root/build/harness/tgnav"
scene="$root/configs/scenes/smoke.yaml"
"$tgnav" render --scene "$scene" --out "$out/start"
"$tgnav" render --scene "$scene" --pose 1.2,0.2,1.0,0.0 --out "$out/crates"
for view in start crates; do
  for f in rgb.png depth.png intrinsics.yaml; do
    [ -s "$out/$view/$f" ] || { echo "demo: $out/$view/$f is missing" >&2; exit 1; }
  done
done
echo "demo: results in $out (start/, crates/: rgb.png, depth.png in mm, intrinsics.yaml)"
