#!/usr/bin/env bash
# The main job, on the embedded default scene (smoke): the mapping run (feature map from
# rendered RGB-D), a flight around the pillar through the PX4-like cascade, and one onboard
# RGB-D frame. Checks its own results and prints where they are.
# (The full plan-fly-score trial replaces this as the planner lands: issues 5-9.)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$root/scripts/setup.sh"
out="$root/results/demo"
tgnav="$root/build/harness/tgnav"
scene="$root/configs/scenes/smoke.yaml"
mkdir -p "$out"
"$tgnav" map --scene "$scene" --out "$out/map"
"$tgnav" fly --scene "$scene" --trajectory "$root/configs/trajectories/smoke_around_pillar.csv" --out "$out/flight"
"$tgnav" render --scene "$scene" --pose 1.2,0.2,1.0,0.0 --out "$out/view"
for f in map/map.bt map/landmarks.csv map/topdown.png map/summary.json flight/gt.tum flight/tracking.json \
         view/rgb.png view/depth.png; do
  [ -s "$out/$f" ] || { echo "demo: $out/$f is missing" >&2; exit 1; }
done
grep -q '"status": "completed"' "$out/flight/tracking.json" || { echo "demo: the flight did not complete" >&2; exit 1; }
echo "demo: results in $out (map/: feature map + topdown.png, flight/: gt.tum + tracking.json, view/: RGB-D)"
