#!/usr/bin/python3
"""Per-class score stability of the proposed planner over plan seeds (issue: robust selection).

For each scenario, plans with `tgnav plan --planner proposed --seed S` for S = 1..N and reports,
per homology class, the median, min and max of its weakest-segment score c_p,min, and how many
seeds fall outside the band median +- max(10 % of |median|, 1.0); and which class each seed chose.
Exit status 1 when any class leaves the band (or a plan fails), else 0.

Usage: plan_stability.py [--tgnav BIN] [--seeds N] [--map-cache DIR]
                         --out DIR SCENARIO...
Writes DIR/<scenario>-<seed>/ (the plans) and DIR/stability.md (the table).
"""
import argparse
import json
import os
import statistics
import subprocess
import sys


def plan(args, scenario, seed, out):
    cmd = [args.tgnav, "plan", "--scenario", scenario, "--planner", "proposed", "--seed", str(seed),
           "--out", out]
    if args.map_cache:
        cmd += ["--map-cache", args.map_cache]
    if os.path.exists(out):
        subprocess.run(["rm", "-rf", out], check=True)
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if r.returncode != 0:
        sys.stderr.write(r.stdout)
        return None
    with open(os.path.join(out, "plan.json")) as f:
        return json.load(f)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tgnav", default=os.path.join(os.path.dirname(__file__), "..", "build", "harness", "tgnav"))
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--map-cache", default="")
    ap.add_argument("--out", required=True)
    ap.add_argument("scenarios", nargs="+")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    lines = ["| scenario | class | median c_p,min | min | max | seeds outside ±max(10 %, 1.0) |",
             "|---|---|---|---|---|---|"]
    choices = []
    stable = True
    for scenario in args.scenarios:
        name = os.path.splitext(os.path.basename(scenario))[0]
        plans = [plan(args, scenario, s, os.path.join(args.out, f"{name}-{s}")) for s in range(1, args.seeds + 1)]
        if any(p is None for p in plans):
            print(f"{name}: a plan failed", file=sys.stderr)
            stable = False
            continue
        for k in range(len(plans[0]["classes"])):
            v = [p["classes"][k]["c_p_min"] for p in plans if p["classes"][k]["feasible"]]
            if not v:
                lines.append(f"| {name} | {k} | infeasible | | | |")
                continue
            m = statistics.median(v)
            tol = max(0.1 * abs(m), 1.0)
            outside = sum(abs(x - m) > tol for x in v)
            stable &= outside == 0
            lines.append(f"| {name} | {k} | {m:.2f} | {min(v):.2f} | {max(v):.2f} | {outside}/{len(v)} |")
        times = [p["plan_time_s"] for p in plans]
        choices.append(f"- {name}: chosen class per seed {[p['chosen_class'] for p in plans]}, "
                       f"plan time mean {statistics.mean(times):.2f} s")
    text = "\n".join(lines + [""] + choices) + "\n"
    with open(os.path.join(args.out, "stability.md"), "w") as f:
        f.write(text)
    print(text, end="")
    return 0 if stable else 1


if __name__ == "__main__":
    sys.exit(main())
