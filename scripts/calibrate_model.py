#!/usr/bin/python3
"""How well the planner's perception model predicts the VO, from a sweep's trials (issue 18).

Reads every trials/<id>/vo.csv (per camera frame: the VO's status and inliers beside the model's
predicted_score, predicted_landmarks, predicted_coverage and predicted_detections at the true
pose) and, for each candidate triple of trackability limits (information.min_landmarks m,
min_detections d and min_image_coverage c: a pose with fewer landmarks that count, promising
fewer detections, or covering less of the image, scores as blind), reports
over the airborne frames (true z above 0.5 m) up to a trial's first loss:
  - safe: frames predicted at or above c_p,thr; of those, how many had the VO lost within the
    next 2 s (the model promised what the VO did not deliver: these must be rare);
  - unsafe: frames predicted below c_p,thr; of those, how many had the VO lost within 2 s
    (the rest are false alarms: a model that cries wolf everywhere makes the planner avoid
    flyable classes);
  - per trial that was lost: whether the model predicted below c_p,thr somewhere in the 2 s
    before the loss (a warning).
Usage: calibrate_model.py SWEEP_DIR [--threshold 6.0] [--min-landmarks 0,100,...]
       [--min-detections 0,10,...] [--min-coverage 0,0.1,...]
The limits emulated here are exact: the score only changes to the blind score 6 ln(epsilon)
where the count, the detections or the coverage falls below the limit. Without a
predicted_coverage or predicted_detections column (trials from before it was logged) only c = 0
or d = 0 is evaluated.
"""
import argparse
import glob
import math
import os
import sys

import numpy as np


def read(path):
    with open(path) as f:
        header = f.readline().strip().split(",")
    need = ["t", "status", "inliers", "z_true", "predicted_score", "predicted_landmarks"]
    if any(n not in header for n in need):
        return None
    cols = [header.index(n) for n in need]
    cov = header.index("predicted_coverage") if "predicted_coverage" in header else -1
    det = header.index("predicted_detections") if "predicted_detections" in header else -1
    rows = []
    with open(path) as f:
        f.readline()
        for line in f:
            p = line.rstrip("\n").split(",")
            rows.append((float(p[cols[0]]), p[cols[1]] == "lost", float(p[cols[2]]), float(p[cols[3]]),
                         float(p[cols[4]]), float(p[cols[5]]), float(p[cov]) if cov >= 0 else math.nan,
                         float(p[det]) if det >= 0 else math.nan))
    return np.array(rows, dtype=float) if rows else None


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("sweep")
    ap.add_argument("--threshold", type=float, default=6.0)
    ap.add_argument("--epsilon", type=float, default=0.01)
    ap.add_argument("--min-landmarks", default="0")
    ap.add_argument("--min-detections", default="0,10,20,30,40,60,80")
    ap.add_argument("--min-coverage", default="0,0.1,0.2,0.25,0.3,0.35,0.4,0.5")
    args = ap.parse_args()
    blind = 6.0 * math.log(args.epsilon)
    trials = {}
    for path in sorted(glob.glob(os.path.join(args.sweep, "trials", "*", "vo.csv"))):
        a = read(path)
        if a is not None:
            trials[os.path.basename(os.path.dirname(path))] = a
    if not trials:
        print("no vo.csv with predictions under", args.sweep, file=sys.stderr)
        return 1
    print(f"{len(trials)} trials, {sum(len(a) for a in trials.values())} frames; c_p,thr {args.threshold}")
    has_coverage = all(not np.isnan(a[:, 6]).any() for a in trials.values())
    has_detections = all(not np.isnan(a[:, 7]).any() for a in trials.values())
    coverages = [float(x) for x in args.min_coverage.split(",")] if has_coverage else [0.0]
    detections = [float(x) for x in args.min_detections.split(",")] if has_detections else [0.0]
    print("| min_landmarks | min_detections | min_image_coverage | safe frames: lost within 2 s "
          "| unsafe frames: lost within 2 s | lost trials warned |")
    print("|---|---|---|---|---|---|")
    combos = [(m, d, c) for m in [float(x) for x in args.min_landmarks.split(",")] for d in detections for c in coverages]
    for m, d, c in combos:
        safe = safe_lost = unsafe = unsafe_lost = warned = lost_trials = 0
        for a in trials.values():
            t, lost, _, z, score, lm, cv, dt = a.T
            blinded = (lm < m) | ((cv < c) if c > 0 else False) | ((dt < d) if d > 0 else False)
            s = np.where(blinded, blind, score)
            air = z > 0.5
            first = int(np.argmax(lost)) if lost.any() else -1
            for i in np.nonzero(air)[0]:
                if first >= 0 and i >= first:
                    break
                soon = first >= 0 and t[first] - t[i] <= 2.0
                if s[i] >= args.threshold:
                    safe += 1
                    safe_lost += soon
                else:
                    unsafe += 1
                    unsafe_lost += soon
            if first >= 0:
                lost_trials += 1
                window = air & (t >= t[first] - 2.0) & (t <= t[first])
                warned += bool((s[window] < args.threshold).any())
        print(f"| {m:g} | {d:g} | {c:g} | {safe_lost}/{safe} | {unsafe_lost}/{unsafe} | {warned}/{lost_trials} |")
    print()
    for name, a in trials.items():
        t, lost, inl, z, score, lm, cv, dt = a.T
        if lost.any():
            i = int(np.argmax(lost))
            w = (t >= t[i] - 2.0) & (t <= t[i])
            print(f"{name}: lost at t={t[i]:.2f}; over the 2 s before: score min {score[w].min():.1f}, "
                  f"landmarks min {lm[w].min():.0f}, coverage min {np.nanmin(cv[w]) if has_coverage else math.nan:.2f}, "
                  f"detections min {np.nanmin(dt[w]) if has_detections else math.nan:.1f}, "
                  f"inliers min {inl[w].min():.0f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
