#!/usr/bin/python3
"""Pairs the truth-pose ablation with the VO trials, seed by seed (issue 40).

    /usr/bin/python3 docs/results/online10/truth/pairs.py results/online10 results/online10_truth \
        --out docs/results/online10/truth

Reads each sweep's trials/<id>/metrics.json (the proposed planner's), writes pairs.csv (one row per
scene and seed) and summary.md (counts, the exact McNemar test on each outcome, the Wilcoxon
signed-rank test on the map error, the medians)."""
import argparse
import csv
import json
import pathlib
import sys

from scipy import stats


def load(sweep, scene, seed):
    f = pathlib.Path(sweep) / "trials" / f"{scene}__proposed__s{seed:02d}" / "metrics.json"
    if not f.is_file():
        sys.exit(f"pairs.py: {f}: not found (is {sweep} a sweep folder with the proposed planner's trials?)")
    return json.loads(f.read_text())


def outcomes(m):
    return {
        "status": m["status"],
        "vo_to_goal": m["status"] == "success",
        "reached": bool(m["online"]["time_to_goal_s"] is not None and m["collision"] is None),
        "goal_error_m": m["goal_error_m"],
        "map_error_mean_m": m["online"]["map_error_mean_m"],
        "map_error_far_share": m["online"]["map_error_far_share"],
        "ate_rmse_m": m["ate_rmse_m"],
        "vo_lost_at_s": m["vo_lost_at_s"],
    }


def mcnemar(a, b):
    """Exact two-sided McNemar p from the discordant pairs (a only, b only)."""
    n = a + b
    if n == 0:
        return 1.0
    return min(1.0, 2.0 * stats.binom.cdf(min(a, b), n, 0.5))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("vo")
    ap.add_argument("truth")
    ap.add_argument("--out", required=True)
    ap.add_argument("--seeds", type=int, default=10)
    args = ap.parse_args()
    out = pathlib.Path(args.out)
    rows = []
    for scene in ("storage", "gallery"):
        for seed in range(1, args.seeds + 1):
            v = outcomes(load(args.vo, scene, seed))
            t = outcomes(load(args.truth, scene, seed))
            row = {"scene": scene, "seed": seed}
            row.update({f"vo_{k}": x for k, x in v.items()})
            row.update({f"truth_{k}": x for k, x in t.items()})
            rows.append(row)
    with open(out / "pairs.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    lines = ["| scene | outcome | at the VO's pose | at the true pose | VO only | truth only | McNemar p |",
             "|---|---|---|---|---|---|---|"]
    for scene in ("storage", "gallery", "both"):
        sel = [r for r in rows if scene in ("both", r["scene"])]
        for key, name in (("vo_to_goal", "VO kept to the goal (success)"), ("reached", "reached the goal, no collision")):
            a = sum(1 for r in sel if r[f"vo_{key}"] and not r[f"truth_{key}"])
            b = sum(1 for r in sel if r[f"truth_{key}"] and not r[f"vo_{key}"])
            nv = sum(1 for r in sel if r[f"vo_{key}"])
            nt = sum(1 for r in sel if r[f"truth_{key}"])
            lines.append(f"| {scene} | {name} | {nv}/{len(sel)} | {nt}/{len(sel)} | {a} | {b} | {mcnemar(a, b):.3g} |")
    lines += ["", "| scene | map error mean (median over seeds), m: VO | truth | Wilcoxon p (paired) | "
              "goal error (median, trials that reached), m: VO | truth |", "|---|---|---|---|---|---|"]
    for scene in ("storage", "gallery", "both"):
        sel = [r for r in rows if scene in ("both", r["scene"])]
        mv = [r["vo_map_error_mean_m"] for r in sel]
        mt = [r["truth_map_error_mean_m"] for r in sel]
        p = stats.wilcoxon(mv, mt).pvalue if any(a != b for a, b in zip(mv, mt)) else 1.0
        gv = [r["vo_goal_error_m"] for r in sel if r["vo_goal_error_m"] is not None]
        gt = [r["truth_goal_error_m"] for r in sel if r["truth_goal_error_m"] is not None]
        med = lambda x: f"{stats.scoreatpercentile(x, 50):.4f} (n={len(x)})" if x else "-"
        lines.append(f"| {scene} | {med(mv)} | {med(mt)} | {p:.3g} | {med(gv)} | {med(gt)} |")
    (out / "summary.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
