#!/usr/bin/python3
"""How well the planner's perception model predicts the VO, from a sweep's trials (issue 18).

Reads every trials/<id>/vo.csv (per camera frame: the VO's status and inliers beside the model's
predicted_score and predicted_landmarks at the true pose) and, for each candidate minimum of
landmarks m (information.min_landmarks: a pose with fewer landmarks that count scores as blind),
reports over the airborne frames (true z above 0.5 m):
  - of the frames predicted at or above c_p,thr, the share where the VO was still tracking;
  - of the frames predicted below it, the share where it was lost within the next 2 s;
  - per trial that was lost: whether the model predicted below c_p,thr somewhere in the 2 s
    before the loss (a warning), and the predicted value there.
Usage: calibrate_model.py SWEEP_DIR [--threshold 6.0] [--min-landmarks 0,10,20,...]
The min_landmarks that is emulated here is exact: the score only changes to the blind score
6 ln(epsilon) where the landmark count falls below m.
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
    rows = []
    with open(path) as f:
        f.readline()
        for line in f:
            p = line.rstrip("\n").split(",")
            rows.append((float(p[cols[0]]), p[cols[1]] == "lost", float(p[cols[2]]), float(p[cols[3]]),
                         float(p[cols[4]]), float(p[cols[5]])))
    return np.array(rows, dtype=float) if rows else None


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("sweep")
    ap.add_argument("--threshold", type=float, default=6.0)
    ap.add_argument("--epsilon", type=float, default=0.01)
    ap.add_argument("--min-landmarks", default="0,25,50,100,150,200,300,400")
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
    print("| min_landmarks | frames >= thr: VO tracking | frames < thr: lost within 2 s | lost trials warned |")
    print("|---|---|---|---|")
    for m in [float(x) for x in args.min_landmarks.split(",")]:
        above = tracked_above = below = lost_soon = warned = lost_trials = 0
        for a in trials.values():
            t, lost, _, z, score, lm = a.T
            s = np.where(lm < m, blind, score)
            air = z > 0.5
            first = np.argmax(lost) if lost.any() else -1
            for i in np.nonzero(air)[0]:
                if first >= 0 and i > first:
                    break
                if s[i] >= args.threshold:
                    above += 1
                    tracked_above += not lost[i]
                else:
                    below += 1
                    lost_soon += first >= 0 and t[first] - t[i] <= 2.0
            if first >= 0:
                lost_trials += 1
                window = air & (t >= t[first] - 2.0) & (t <= t[first])
                warned += bool((s[window] < args.threshold).any())
        print(f"| {m:g} | {tracked_above}/{above} | {lost_soon}/{below} | {warned}/{lost_trials} |")
    print()
    for name, a in trials.items():
        t, lost, inl, z, score, lm = a.T
        if lost.any():
            i = int(np.argmax(lost))
            w = (t >= t[i] - 2.0) & (t <= t[i])
            print(f"{name}: lost at t={t[i]:.2f}; over the 2 s before: score min {score[w].min():.1f}, "
                  f"landmarks min {lm[w].min():.0f}, inliers min {inl[w].min():.0f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
