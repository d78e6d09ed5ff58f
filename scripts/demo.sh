#!/usr/bin/env bash
# The main job: one closed-loop trial on the embedded default (the storage scene, the paper's
# proposed planner): plan on the scene's feature map (built by rendering on first use, then
# cached), generate the trajectory, fly it in MuJoCo through the PX4-like cascade while the
# onboard camera renders and the VO tracks, and score it. Checks its own results and prints the
# summary and where they are. Extra arguments go to `tgnav trial` (e.g. --planner agnostic,
# --seed 3, --set trial.state_source=vo, --set camera.width_px=320 --set camera.height_px=240).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$root/scripts/setup.sh"
out="$root/results/demo"
echo "demo: running the trial (tgnav trial, storage, proposed planner; the feature map is built on first use)" >&2
"$root/build/harness/tgnav" trial --scenario "$root/configs/scenarios/storage.yaml" --planner proposed \
  --out "$out" --force "$@"
for f in metrics.json gt.tum est.tum plan.json config.yaml topdown.png ate.png vo.csv trajectory.csv; do
  [ -s "$out/$f" ] || { echo "demo: $out/$f is missing" >&2; exit 1; }
done
status=$(sed -n 's/^  "status": "\(.*\)",$/\1/p' "$out/metrics.json")
[ -n "$status" ] || { echo "demo: $out/metrics.json has no status" >&2; exit 1; }
echo "demo: trial status '$status'; results in $out (metrics.json, topdown.png, ate.png, gt.tum, est.tum, ...)"
