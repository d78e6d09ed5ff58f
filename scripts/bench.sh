#!/usr/bin/env bash
# Builds the Google Benchmark targets (build-bench/, Release) and prints one table of figures
# with git SHA, host and date; writes the same as JSON to results/bench/bench.json. Also builds
# the feature map of every scene (results/bench/maps/) to time the mapping run, and plans on
# storage and gallery with every planner and on three generated scenes with the proposed one
# (results/bench/plans/), which also times trajectory generation on the chosen paths, runs closed-loop trials (results/bench/trials/) for their
# wall time, real-time factor, CPU seconds per simulated second of each stage and peak memory,
# and the smoke sweep with --jobs 1 and --jobs 2
# (results/bench/sweep-jobs*/) for the sweep throughput.
# Figures are measured, never asserted; the SHA is marked -dirty when tracked files had uncommitted
# changes (build-bench is built from the working tree: do not edit sources while it builds).
# Usage: scripts/bench.sh [--benchmark_filter=REGEX]
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$root/scripts/setup.sh"
build="$root/build-bench"
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DTGNAV_BUILD_TESTS=OFF \
  -DTGNAV_BUILD_BENCHMARKS=ON >/dev/null
cmake --build "$build" -j"$(nproc)" --target sim_benchmark map_benchmark planner_benchmark vo_benchmark tgnav >&2
out="$root/results/bench"
mkdir -p "$out"
for b in sim map planner vo; do
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

# Plan time per planner on the paper's scenes (Table II): the proposed planner and AP over three
# seeds, perception-aware RRT* at the paper's sample counts (one seed each).
rm -rf "$out/plans"
for scene in storage gallery; do
  map="$out/maps/$scene"
  for seed in 1 2 3; do
    for planner in proposed agnostic; do
      "$build/harness/tgnav" plan --scenario "$root/configs/scenarios/$scene.yaml" --map "$map" \
        --planner "$planner" --seed "$seed" --out "$out/plans/$scene-$planner-s$seed" >&2
    done
  done
  if [ "$scene" = storage ]; then samples="300 1000 2000"; else samples="1000 8000 15000"; fi
  for n in $samples; do
    "$build/harness/tgnav" plan --scenario "$root/configs/scenarios/$scene.yaml" --map "$map" \
      --planner rrtstar --samples "$n" --seed 1 --out "$out/plans/$scene-rrtstar$n-s1" >&2
  done
done

# Plan time on generated scenes (tgnav scene generate, seed 11 of each kind: a calibration seed,
# never a benchmark's), the proposed planner over three seeds.
rm -rf "$out/generated"
for kind in room corridors warehouse; do
  gen="$out/generated/$kind"
  "$build/harness/tgnav" scene generate --kind "$kind" --seed 11 --out "$gen" >&2
  "$build/harness/tgnav" map --scene "$gen/scenes/$kind-11.yaml" --out "$gen/map" >&2
  for seed in 1 2 3; do
    "$build/harness/tgnav" plan --scenario "$gen/scenarios/$kind-11.yaml" --map "$gen/map" --planner proposed \
      --seed "$seed" --out "$out/plans/$kind-11-proposed-s$seed" >&2
  done
done

# Closed-loop trials: storage, proposed planner (the VO tracks the whole flight, so every frame is
# rendered and tracked), at 640x480 and 320x240, camera and VO at 20 Hz, the three stages pipelined;
# TRIAL_RUNS runs of each (default 3), reported as their median.
rm -rf "$out/trials"
for size in 640x480 320x240; do
  for run in $(seq "${TRIAL_RUNS:-3}"); do
    "$build/harness/tgnav" trial --scenario "$root/configs/scenarios/storage.yaml" --map "$out/maps/storage" \
      --planner proposed --seed 1 --set camera.width_px="${size%x*}" --set camera.height_px="${size#*x}" \
      --out "$out/trials/storage-proposed-$size/run$run" >&2
  done
done
# The same trial online (issue 40): from no map, mapping the keyframes at the VO's pose and
# replanning (trial.mode online, flown on the VO + IMU estimate), 640x480; the figures add the map
# updates per camera frame and the plans' wall time.
for run in $(seq "${TRIAL_RUNS:-3}"); do
  "$build/harness/tgnav" trial --scenario "$root/configs/scenarios/storage.yaml" --map "$out/maps/storage" \
    --planner proposed --seed 1 --online --no-figures --out "$out/trials/storage-proposed-online-640x480/run$run" >&2
done
# The same 640x480 trial with MuJoCo's default 4x multisampling (the default before issue 21).
"$build/harness/tgnav" trial --scenario "$root/configs/scenarios/storage.yaml" \
  --map "$out/maps/storage" --planner proposed --seed 1 --set camera.offscreen_samples=4 \
  --out "$out/trials/storage-proposed-640x480-msaa4/run1" >&2

# Sweep throughput: the smoke sweep (6 trials, each single-threaded) one and two at a time.
for jobs in 1 2; do
  rm -rf "$out/sweep-jobs$jobs"
  t0=$(date +%s.%N)
  "$build/harness/tgnav" sweep --sweep "$root/configs/sweeps/smoke.yaml" --jobs "$jobs" \
    --out "$out/sweep-jobs$jobs" >&2
  t1=$(date +%s.%N)
  echo "$t0 $t1" >"$out/sweep-jobs$jobs/elapsed"
done

sha=$(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo unknown)
# Figures of uncommitted code say so (the binaries were built from the working tree as it was).
if [ -n "$(git -C "$root" status --porcelain --untracked-files=no 2>/dev/null)" ]; then sha="$sha-dirty"; fi
/usr/bin/python3 - "$out" "$sha" <<'PY'
import json, os, socket, sys, datetime
out, sha = sys.argv[1], sys.argv[2]
rows = []
maps = os.path.join(out, "maps")
for scene in sorted(os.listdir(maps)) if os.path.isdir(maps) else []:
    summary = json.load(open(os.path.join(maps, scene, "summary.json")))
    rows.append({"benchmark": f"map_build/{scene}", "figure": "s_per_map", "value": summary["timing"]["total_s"]})
    rows.append({"benchmark": f"map_build/{scene}", "figure": "landmarks", "value": summary["landmarks"]})
plans = os.path.join(out, "plans")
groups = {}
for run in sorted(os.listdir(plans)) if os.path.isdir(plans) else []:
    plan = json.load(open(os.path.join(plans, run, "plan.json")))
    groups.setdefault(run.rsplit("-s", 1)[0], []).append(plan)
for key, runs in groups.items():
    times = sorted(p["plan_time_s"] for p in runs)
    rows.append({"benchmark": f"plan/{key}", "figure": "median_plan_s", "value": times[len(times) // 2]})
    rows.append({"benchmark": f"plan/{key}", "figure": "path_length_m", "value": runs[0]["path_length_m"]})
    trajectory_s = sorted(p["timing"]["trajectory_s"] for p in runs)
    rows.append({"benchmark": f"plan/{key}", "figure": "median_traj_s", "value": trajectory_s[len(trajectory_s) // 2]})
trials = os.path.join(out, "trials")
renderer = None
def median(values):
    values = sorted(values)
    return values[len(values) // 2] if len(values) % 2 else 0.5 * (values[len(values) // 2 - 1] + values[len(values) // 2])
for run in sorted(os.listdir(trials)) if os.path.isdir(trials) else []:
    runs = [json.load(open(os.path.join(trials, run, r, "metrics.json")))
            for r in sorted(os.listdir(os.path.join(trials, run)))]
    # Wall-clock figures and CPU per simulated second: the median over the runs; the wall-clock
    # profile below is the median run's (by real-time factor).
    rows.append({"benchmark": f"trial/{run}", "figure": "runs", "value": len(runs)})
    for figure in ("wall_time_s", "flight_wall_s", "real_time_factor", "peak_rss_mb"):
        rows.append({"benchmark": f"trial/{run}", "figure": figure, "value": median([m["timing"][figure] for m in runs])})
    for figure in ("map_update_ms_per_frame", "online_plans_s"):
        if all(figure in m["timing"] for m in runs):
            rows.append({"benchmark": f"trial/{run}", "figure": figure, "value": median([m["timing"][figure] for m in runs])})
    rtfs = [m["timing"]["real_time_factor"] for m in runs]
    rows.append({"benchmark": f"trial/{run}", "figure": "rtf_min", "value": min(rtfs)})
    rows.append({"benchmark": f"trial/{run}", "figure": "rtf_max", "value": max(rtfs)})
    cpu_runs = [m["timing"].get("profile", {}).get("cpu_per_sim_second_s") for m in runs]
    if all(cpu_runs):
        for stage in cpu_runs[0]:
            values = [c[stage] for c in cpu_runs if c[stage] is not None]
            if values:
                rows.append({"benchmark": f"trial/{run}/cpu_s_per_sim_s", "figure": stage, "value": median(values)})
    m = sorted(runs, key=lambda m: m["timing"]["real_time_factor"])[len(runs) // 2]
    # The per-stage profile (metrics.json timing.profile): ms per camera frame of each stage,
    # per-thread totals and the critical path against the flight's wall time.
    profile = m["timing"].get("profile")
    if profile:
        renderer = renderer or profile.get("gl_renderer")
        for stage, ms in profile["per_frame_ms"].items():
            rows.append({"benchmark": f"trial/{run}/frame", "figure": f"ms_{stage}", "value": ms})
        for stage, ms in profile["per_sim_second_ms"].items():
            rows.append({"benchmark": f"trial/{run}/sim_second", "figure": f"ms_{stage}", "value": ms})
        for thread, totals in profile["threads"].items():
            for figure in ("busy_s", "wait_vo_s", "idle_s"):
                if figure in totals:
                    rows.append({"benchmark": f"trial/{run}/{thread}", "figure": figure, "value": totals[figure]})
        rows.append({"benchmark": f"trial/{run}/critical_path", "figure": "ms_per_tick",
                     "value": profile["critical_path"]["ms_per_tick"]})
        rows.append({"benchmark": f"trial/{run}/critical_path", "figure": "ratio_to_wall",
                     "value": profile["critical_path"]["ratio_to_wall"]})
per_min = {}
for jobs in (1, 2):
    elapsed = os.path.join(out, f"sweep-jobs{jobs}", "elapsed")
    if not os.path.exists(elapsed):
        continue
    t0, t1 = map(float, open(elapsed).read().split())
    trials = sum(1 for _ in open(os.path.join(out, f"sweep-jobs{jobs}", "index.csv"))) - 1
    per_min[jobs] = 60.0 * trials / (t1 - t0)
    rows.append({"benchmark": f"sweep/smoke/jobs{jobs}", "figure": "trials_per_min", "value": per_min[jobs]})
if len(per_min) == 2:
    rows.append({"benchmark": "sweep/smoke/jobs2_vs_jobs1", "figure": "speedup", "value": per_min[2] / per_min[1]})
for name in sorted(f for f in os.listdir(out) if f.endswith(".json") and f != "bench.json"):
    data = json.load(open(os.path.join(out, name)))
    for b in data["benchmarks"]:
        for key, value in b.items():
            if key in ("ms_per_frame", "us_per_step", "us_per_cycle", "real_time_factor", "queries_per_s",
                       "landmarks_per_query", "ms_per_plan", "classes", "ms_per_trajectory",
                       "path_length_m", "optimised", "ate_percent", "lost_frames", "ms_per_query",
                       "working_factor", "solved", "ms_total", "ms_overhead"):
                rows.append({"benchmark": b["name"], "figure": key, "value": value})
        if b["name"].startswith("BM_GridPreprocess"):  # a grid map's graph, built once per map and radius
            rows.append({"benchmark": b["name"], "figure": "ms_preprocess", "value": b["real_time"]})
cpu_model = "unknown"
if os.path.exists("/proc/cpuinfo"):
    for line in open("/proc/cpuinfo"):
        if line.startswith("model name"):
            cpu_model = line.split(":", 1)[1].strip()
            break
meta = {"git_sha": sha, "host": socket.gethostname(), "cpus": os.cpu_count(), "cpu_model": cpu_model,
        "gl_renderer": renderer, "date": datetime.datetime.now().isoformat(timespec="seconds")}
print(f"tgnav benchmarks  sha {meta['git_sha']}  host {meta['host']} ({meta['cpus']} cpus)  {meta['date']}")
print(f"cpu: {cpu_model}; renderer: {renderer}")
print(f"{'benchmark':<44} {'figure':<22} {'value':>10}")
for r in rows:
    print(f"{r['benchmark']:<44} {r['figure']:<22} {r['value']:>10.3f}")
with open(os.path.join(out, "bench.json.tmp"), "w") as f:
    json.dump({"meta": meta, "figures": rows}, f, indent=2)
os.replace(os.path.join(out, "bench.json.tmp"), os.path.join(out, "bench.json"))
print(f"written {os.path.join(out, 'bench.json')}")
PY
