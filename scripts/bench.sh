#!/usr/bin/env bash
# Builds the Google Benchmark targets (build-bench/, Release) and prints one table of figures
# with git SHA, host and date; writes the same as JSON to results/bench/bench.json. Also builds
# the feature map of every scene (results/bench/maps/) to time the mapping run.
# Figures are measured, never asserted. Usage: scripts/bench.sh [--benchmark_filter=REGEX]
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$root/scripts/setup.sh"
build="$root/build-bench"
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DTGNAV_BUILD_TESTS=OFF \
  -DTGNAV_BUILD_BENCHMARKS=ON >/dev/null
cmake --build "$build" -j"$(nproc)" --target sim_benchmark map_benchmark planner_benchmark tgnav >&2
out="$root/results/bench"
mkdir -p "$out"
for b in sim map planner; do
  "$build/tests/bench/${b}_benchmark" --benchmark_out="$out/$b.json.tmp" \
    --benchmark_out_format=json --benchmark_min_time=1 "$@" >&2
  mv "$out/$b.json.tmp" "$out/$b.json"
done
# Map build time per scene: the whole mapping run of `tgnav map`.
for yaml in "$root"/configs/scenes/*.yaml; do
  name=$(basename "$yaml" .yaml)
  [ "$name" = empty ] && continue
  "$build/harness/tgnav" map --scene "$yaml" --out "$out/maps/$name" >&2
done

sha=$(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo unknown)
/usr/bin/python3 - "$out" "$sha" <<'PY'
import json, os, socket, sys, datetime
out, sha = sys.argv[1], sys.argv[2]
rows = []
maps = os.path.join(out, "maps")
for scene in sorted(os.listdir(maps)) if os.path.isdir(maps) else []:
    summary = json.load(open(os.path.join(maps, scene, "summary.json")))
    rows.append({"benchmark": f"map_build/{scene}", "figure": "s_per_map", "value": summary["timing"]["total_s"]})
    rows.append({"benchmark": f"map_build/{scene}", "figure": "landmarks", "value": summary["landmarks"]})
for name in sorted(f for f in os.listdir(out) if f.endswith(".json") and f != "bench.json"):
    data = json.load(open(os.path.join(out, name)))
    for b in data["benchmarks"]:
        for key, value in b.items():
            if key in ("ms_per_frame", "us_per_step", "us_per_cycle", "real_time_factor", "queries_per_s",
                       "landmarks_per_query", "ms_per_plan", "classes"):
                rows.append({"benchmark": b["name"], "figure": key, "value": value})
meta = {"git_sha": sha, "host": socket.gethostname(), "cpus": os.cpu_count(),
        "date": datetime.datetime.now().isoformat(timespec="seconds")}
print(f"tgnav benchmarks  sha {meta['git_sha']}  host {meta['host']} ({meta['cpus']} cpus)  {meta['date']}")
print(f"{'benchmark':<34} {'figure':<16} {'value':>10}")
for r in rows:
    print(f"{r['benchmark']:<34} {r['figure']:<16} {r['value']:>10.3f}")
with open(os.path.join(out, "bench.json.tmp"), "w") as f:
    json.dump({"meta": meta, "figures": rows}, f, indent=2)
os.replace(os.path.join(out, "bench.json.tmp"), os.path.join(out, "bench.json"))
print(f"written {os.path.join(out, 'bench.json')}")
PY
