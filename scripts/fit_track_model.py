#!/usr/bin/python3
"""The learned perception model (issue 38): fit it on trials, evaluate it on others.

A trial's vo.csv holds, per camera frame, what the VO did (status, inliers) beside the planner's
view features at the true camera pose (predicted_detections, predicted_landmarks,
predicted_coverage, predicted_near_detections, predicted_mean_range_m, predicted_column_span,
predicted_row_span, predicted_inner_detections, predicted_inner_near_detections: planner/perception.h's
ViewSupport over every landmark of the map in view).
The model is a logistic regression of "the VO tracks this frame" on those features, as
planner/track_model.h evaluates it; its JSON file is what `planner.information.track_model` reads.
The texture features' weights are held >= 0 (MONOTONE; --free-signs lets them take either sign).
--ramps FEATURE=K1,K2,... replaces a feature by ramps between consecutive knots (in the feature's raw
units: detections for a log_ feature), each clamp((f - lo) / (hi - lo), 0, 1) of the feature's value
f: with the weights held >= 0 the model is then any monotone piecewise-linear function of it, and not
only a straight line in the logit (a straight line cannot follow the VO's sharp step from lost to
tracked between about 10 and 25 detections). A model with ramps is the file's version 2.

Frames used: airborne (true z above --min-z), not an initialisation (a frame the VO started or
restarted on: not lost, no matches). A frame the VO could not restart on is a lost one. Label: tracked with at least min_inliers
PnP inliers (the trial's config.yaml vo.min_inliers).

  fit_track_model.py fit SWEEP_DIR [SWEEP_DIR...] --out MODEL.json
      fits on every trial of the sweeps; reports leave-one-scene-out ROC AUC (each scene's frames
      scored by a model fitted on the other scenes) beside the training AUC, and the AUC a model
      with the motion (speed, yaw rate from gt.tum) would reach, which the planner does not use.
  fit_track_model.py evaluate SWEEP_DIR [...] --model MODEL.json --out DIR
      scores another set of trials (scenes the model never saw): per-frame ROC AUC, a reliability
      diagram (DIR/reliability.png, DIR/reliability.csv), and, for the oracle trials
      (planner.oracle_class set), "class flyable" as predicted (every frame of the flown class at
      or above --threshold) against what the VO did (tracked to the goal). Writes DIR/evaluation.json.
Both take --views NAME: the features from the file NAME of each trial folder, written by
`tgnav views --trial FOLDER --out FOLDER/NAME [--set ...]` (the same columns computed again at the
true camera poses with other planner settings), instead of vo.csv's.
Exit status 2 with one line naming the file on bad input.
"""
import argparse
import glob
import hashlib
import json
import math
import os
import sys

import numpy as np

FEATURES = ["log_detections", "log_landmarks", "coverage", "column_span", "row_span", "log_near_detections",
            "mean_range_m", "log_inner_detections", "log_inner_near_detections"]
COLUMNS = {"log_detections": "predicted_detections", "log_landmarks": "predicted_landmarks",
           "coverage": "predicted_coverage", "column_span": "predicted_column_span",
           "row_span": "predicted_row_span", "log_near_detections": "predicted_near_detections",
           "mean_range_m": "predicted_mean_range_m", "log_inner_detections": "predicted_inner_detections",
           "log_inner_near_detections": "predicted_inner_near_detections"}
LOGGED = {"log_detections", "log_landmarks", "log_near_detections", "log_inner_detections",
          "log_inner_near_detections"}
# Features that measure the texture in view: the fit holds their weights >= 0 (unless --free-signs),
# so that a view never loses probability by showing more. Free, correlated weights extrapolate
# badly: a fit that weighs coverage up and column span down rates a few textured columns at the
# image's edge as safe as a view full of texture.
MONOTONE = set(FEATURES) - {"mean_range_m"}


class InputError(Exception):
    pass


def read_config(config_path):
    """A trial's resolved config.yaml as a dict ({} when the trial has none)."""
    import yaml
    try:
        with open(config_path) as f:
            doc = yaml.safe_load(f)
    except OSError:
        return {}
    except yaml.YAMLError as e:
        raise InputError(f"{config_path}: not YAML ({str(e).splitlines()[0]})")
    return doc if isinstance(doc, dict) else {}


def config_value(config, section, key, default):
    """config[section][key], or default."""
    node = config.get(section)
    return node.get(key, default) if isinstance(node, dict) else default


def read_gt_yaw(path):
    """(t, yaw of the optical axis) from a gt.tum of camera poses (z forward)."""
    try:
        data = np.loadtxt(path, ndmin=2)
    except (OSError, ValueError):
        return None
    if data.size == 0 or data.shape[1] != 8:
        return None
    qx, qy, qz, qw = data[:, 4], data[:, 5], data[:, 6], data[:, 7]
    # third column of the rotation matrix: the optical axis in the world
    fx = 2 * (qx * qz + qw * qy)
    fy = 2 * (qy * qz - qw * qx)
    return data[:, 0], np.unwrap(np.arctan2(fy, fx))


def read_views(folder, views, vo_header, vo_rows):
    """vo.csv's header and rows with their predicted_* columns taken from FOLDER/VIEWS (a `tgnav views`
    CSV); a column vo.csv lacks (a trial flown before it was logged) is added."""
    path = os.path.join(folder, views)
    if not os.path.isfile(path):
        raise InputError(f"{path}: not found (--views: make it with tgnav views --trial {folder} --out {path})")
    with open(path) as f:
        first = f.readline()
        settings = parse_view_settings(path, first)
        header = f.readline().strip().split(",")
        rows = [line.rstrip("\n").split(",") for line in f if line.strip()]
    if "t" not in header or len(rows) != len(vo_rows):
        raise InputError(f"{path}: {len(rows)} rows against vo.csv's {len(vo_rows)} (not this trial's views)")
    t_vo, t_views = vo_header.index("t"), header.index("t")
    out_header = list(vo_header) + [n for n in header if n.startswith("predicted_") and n not in vo_header]
    # (views column, output column) of each predicted_* column
    moves = [(i, out_header.index(name)) for i, name in enumerate(header) if name.startswith("predicted_")]
    out = []
    for n, (a, b) in enumerate(zip(vo_rows, rows)):
        if len(b) != len(header) or abs(float(a[t_vo]) - float(b[t_views])) > 1e-4:
            raise InputError(f"{path}: line {n + 2} is not vo.csv's frame at t = {a[t_vo]}")
        row = list(a) + [""] * (len(out_header) - len(vo_header))
        for i, j in moves:
            row[j] = b[i]
        out.append(row)
    return out_header, out, settings


VIEW_SETTINGS = ["hfov_rad", "vfov_rad", "min_range_m", "max_range_m", "max_incidence_rad", "sight_to_face"]
# Settings that files from before them lack: absent, they had this value.
VIEW_SETTING_DEFAULTS = {"sight_to_face": 0.0}


def parse_view_settings(path, line):
    """The '# view_settings: k=v ...' line `tgnav views` writes first, as a dict."""
    prefix = "# view_settings:"
    if not line.startswith(prefix):
        raise InputError(f"{path}: the first line is not '{prefix} ...' (not written by tgnav views)")
    try:
        settings = {k: float(v) for k, v in (item.split("=") for item in line[len(prefix):].split())}
    except ValueError:
        raise InputError(f"{path}: the first line '{line.strip()}' does not parse")
    settings = {**VIEW_SETTING_DEFAULTS, **settings}
    missing = [k for k in VIEW_SETTINGS if k not in settings]
    if missing:
        raise InputError(f"{path}: the first line has no {missing[0]}")
    return {k: settings[k] for k in VIEW_SETTINGS}


def config_view_settings(config, folder):
    """The view settings a trial's vo.csv features were computed with (its config.yaml)."""
    vis = (config.get("planner") or {}).get("visibility") or {}
    info = (config.get("planner") or {}).get("information") or {}
    values = {k: vis.get(k) for k in VIEW_SETTINGS[:4]}
    values["max_incidence_rad"] = info.get("max_incidence_rad")
    values["sight_to_face"] = 1.0 if vis.get("sight_to_face", False) is True else 0.0
    missing = [k for k, v in values.items() if v is None]
    if missing:
        raise InputError(f"{os.path.join(folder, 'config.yaml')}: no planner setting {missing[0]} (the view settings "
                         "of vo.csv's features)")
    return {k: float(v) for k, v in values.items()}


def read_trial(folder, min_z, views=None):
    """Per-frame features, labels and motion of one trial folder, or None without a vo.csv. With
    `views`, the features come from that file of the folder (`tgnav views`) instead of vo.csv."""
    path = os.path.join(folder, "vo.csv")
    if not os.path.isfile(path):
        return None
    with open(path) as f:
        header = f.readline().strip().split(",")
        rows = [line.rstrip("\n").split(",") for line in f if line.strip()]
    settings = None
    if views:
        try:
            header, rows, settings = read_views(folder, views, header, rows)
        except ValueError as e:
            raise InputError(f"{os.path.join(folder, views)}: a row does not parse ({e})")
    need = ["t", "status", "matches", "inliers", "x_true", "y_true", "z_true"] + [COLUMNS[n] for n in FEATURES]
    missing = [n for n in need if n not in header]
    if missing:
        raise InputError(f"{path}: column '{missing[0]}' is missing (trials from before the model's features were logged)")
    idx = {n: header.index(n) for n in need}
    try:
        t = np.array([float(r[idx["t"]]) for r in rows])
        status = [r[idx["status"]] for r in rows]
        matches = np.array([float(r[idx["matches"]]) for r in rows])
        inliers = np.array([float(r[idx["inliers"]]) for r in rows])
        pos = np.array([[float(r[idx[c]]) for c in ("x_true", "y_true", "z_true")] for r in rows])
        raw = {n: np.array([float(r[idx[COLUMNS[n]]]) for r in rows]) for n in FEATURES}
    except (ValueError, IndexError) as e:
        raise InputError(f"{path}: a row does not parse ({e})")
    if len(t) == 0:
        return None
    config = read_config(os.path.join(folder, "config.yaml"))
    if settings is None:
        settings = config_view_settings(config, folder)
    min_inliers = float(config_value(config, "vo", "min_inliers", 30))
    x = np.column_stack([np.log1p(raw[n]) if n in LOGGED else raw[n] for n in FEATURES])
    label = np.array([s != "lost" for s in status]) & (inliers >= min_inliers)
    lost = np.array([s == "lost" for s in status])
    initialisation = ~lost & (matches == 0)  # the VO (re)started on this frame: nothing was tracked
    keep = (pos[:, 2] > min_z) & ~initialisation
    # motion: speed from the true positions, yaw rate from gt.tum
    speed = np.zeros(len(t))
    if len(t) > 1:
        v = np.gradient(pos, t, axis=0)
        speed = np.linalg.norm(v[:, :2], axis=1)
    yaw_rate = np.zeros(len(t))
    gt = read_gt_yaw(os.path.join(folder, "gt.tum"))
    if gt is not None and len(gt[0]) > 2:
        rate = np.gradient(gt[1], gt[0])
        yaw_rate = np.abs(np.interp(t, gt[0], rate))
    oracle = config_value(config, "planner", "oracle_class", -1)
    scene = os.path.basename(folder).split("__")[0]
    return {"folder": folder, "scene": scene, "view_settings": settings, "x": x[keep], "y": label[keep], "motion": np.column_stack(
        [speed, yaw_rate])[keep], "oracle": int(oracle) if oracle is not None else -1, "t": t[keep],
        "all_frames": len(t)}


def read_sweeps(dirs, min_z, views=None):
    trials = []
    for d in dirs:
        if not os.path.isdir(d):
            raise InputError(f"{d}: not a folder")
        folders = sorted(glob.glob(os.path.join(d, "trials", "*")))
        if not folders:
            raise InputError(f"{d}: no trials/ folders (a sweep's output folder is expected)")
        for folder in folders:
            tr = read_trial(folder, min_z, views)
            if tr is not None and len(tr["y"]) > 0:
                trials.append(tr)
    if not trials:
        raise InputError(f"{', '.join(dirs)}: no trial has airborne frames")
    return trials


def stack(trials, key):
    return np.concatenate([tr[key] for tr in trials])


def fit_logistic(x, y, c, monotone=None):
    """L2-regularised logistic regression on standardised features (sklearn's objective:
    0.5 |w|^2 + c * sum of log losses). `monotone`: one flag per feature; a flagged feature's weight
    is held >= 0 (more evidence of texture never lowers the probability), by L-BFGS-B bounds."""
    from scipy.optimize import minimize
    mean = x.mean(axis=0)
    scale = x.std(axis=0)
    scale[scale <= 0] = 1.0
    xs = (x - mean) / scale
    sign = np.where(y, 1.0, -1.0)

    def loss(theta):
        w, b = theta[:-1], theta[-1]
        m = sign * (xs @ w + b)
        # log(1 + exp(-m)) and its derivative, stable for large |m|
        value = 0.5 * w @ w + c * np.logaddexp(0.0, -m).sum()
        r = -c * sign * 0.5 * (1.0 - np.tanh(0.5 * m))  # d(c * log loss)/d(score)
        return value, np.append(w + xs.T @ r, r.sum())

    bounds = [(0.0, None) if monotone is not None and monotone[i] else (None, None) for i in range(x.shape[1])]
    theta0 = np.zeros(x.shape[1] + 1)
    theta0[-1] = math.log(max(y.mean(), 1e-9) / max(1.0 - y.mean(), 1e-9))
    result = minimize(loss, theta0, jac=True, method="L-BFGS-B", bounds=bounds + [(None, None)],
                      options={"maxiter": 5000, "gtol": 1e-8})
    return mean, scale, result.x[:-1], float(result.x[-1])


def probability(x, mean, scale, weights, intercept):
    z = intercept + ((x - mean) / scale) @ weights
    return 1.0 / (1.0 + np.exp(-z))


def auc(y, p):
    from sklearn.metrics import roc_auc_score
    return float(roc_auc_score(y, p)) if 0 < y.sum() < len(y) else float("nan")


def leave_one_scene_out(trials, c, monotone, with_motion=False):
    scenes = sorted({tr["scene"] for tr in trials})
    ys, ps = [], []
    for s in scenes:
        train = [tr for tr in trials if tr["scene"] != s]
        test = [tr for tr in trials if tr["scene"] == s]
        xtr = stack(train, "x")
        xte = stack(test, "x")
        if with_motion:
            xtr = np.column_stack([xtr, stack(train, "motion")])
            xte = np.column_stack([xte, stack(test, "motion")])
        ytr = stack(train, "y")
        if ytr.min() == ytr.max():
            continue
        m, sc, w, b = fit_logistic(xtr, ytr, c, list(monotone) + [False] * (xtr.shape[1] - len(monotone)))
        ys.append(stack(test, "y"))
        ps.append(probability(xte, m, sc, w, b))
    return auc(np.concatenate(ys), np.concatenate(ps))


def select(trials, names):
    """The trials with only the named feature columns, in the order of `names`."""
    cols = [FEATURES.index(n) for n in names]
    return [dict(tr, x=tr["x"][:, cols]) for tr in trials]


def parse_ramps(text, names):
    """--ramps 'FEATURE=K1,K2,...[;FEATURE=...]' as {feature: [knots in the feature's value units]}."""
    out = {}
    for item in [i for i in (text or "").split(";") if i.strip()]:
        name, _, knots = item.partition("=")
        name = name.strip()
        if name not in names:
            raise InputError(f"--ramps: '{name}' is not one of the model's features ({', '.join(names)})")
        try:
            raw = [float(k) for k in knots.split(",")]
        except ValueError:
            raise InputError(f"--ramps: '{item}' does not parse (FEATURE=K1,K2,...)")
        if len(raw) < 2 or any(b <= a for a, b in zip(raw, raw[1:])) or (name in LOGGED and raw[0] <= -1):
            raise InputError(f"--ramps: '{item}' needs two or more increasing knots")
        out[name] = [math.log1p(k) for k in raw] if name in LOGGED else raw
    return out


def model_terms(names, ramps):
    """(feature name, column in names, (lo, hi) or None) for each term of the model."""
    terms = []
    for i, n in enumerate(names):
        knots = ramps.get(n)
        if knots:
            terms += [(n, i, (lo, hi)) for lo, hi in zip(knots, knots[1:])]
        else:
            terms.append((n, i, None))
    return terms


def design(x, terms):
    """The model's term values from the named feature columns x."""
    cols = []
    for _, i, ramp in terms:
        v = x[:, i]
        cols.append(v if ramp is None else np.clip((v - ramp[0]) / (ramp[1] - ramp[0]), 0.0, 1.0))
    return np.column_stack(cols)


def cmd_fit(args):
    names = [n for n in args.features.split(",") if n]
    unknown = [n for n in names if n not in FEATURES]
    if unknown or not names:
        raise InputError(f"--features: '{unknown[0] if unknown else args.features}' is not one of {', '.join(FEATURES)}")
    terms = model_terms(names, parse_ramps(args.ramps, names))
    trials = select(read_sweeps(args.sweeps, args.min_z, args.views), names)
    y = stack(trials, "y")
    if y.min() == y.max():
        raise InputError(f"{', '.join(args.sweeps)}: every frame has the same label; nothing to fit")
    settings = trials[0]["view_settings"]
    for tr in trials:
        if tr["view_settings"] != settings:
            raise InputError(f"{tr['folder']}: view settings {tr['view_settings']} differ from "
                             f"{trials[0]['folder']}'s {settings}: one model is fitted on features counted one way "
                             "(--views)")
    trials = [dict(tr, x=design(tr["x"], terms)) for tr in trials]
    x = stack(trials, "x")
    # a ramp is monotone in its feature: held >= 0 with it (a ramp of mean_range_m too)
    monotone = [(n in MONOTONE or r is not None) and not args.free_signs for n, _, r in terms]
    mean, scale, weights, intercept = fit_logistic(x, y, args.c, monotone)
    train_auc = auc(y, probability(x, mean, scale, weights, intercept))
    loso = leave_one_scene_out(trials, args.c, monotone)
    loso_motion = leave_one_scene_out(trials, args.c, monotone, with_motion=True)
    scenes = sorted({tr["scene"] for tr in trials})
    threshold, accuracy, flights = choose_threshold(trials, mean, scale, weights, intercept)
    has_ramps = any(r is not None for _, _, r in terms)
    doc = {
        "format": "tgnav-track-model", "version": 2 if has_ramps else 1, "kind": "logistic",
        "label": "the VO tracks the frame with at least vo.min_inliers PnP inliers",
        "features": [n for n, _, _ in terms]}
    if has_ramps:
        doc["ramps"] = [list(r) if r is not None else None for _, _, r in terms]
    doc.update({
        "mean": mean.tolist(), "scale": scale.tolist(), "weights": weights.tolist(),
        "intercept": intercept,
        "view_settings": settings,
        "fitted_on": {"sweeps": [os.path.normpath(d) for d in args.sweeps], "scenes": scenes,
                      "trials": len(trials), "frames": int(len(y)), "tracked": int(y.sum()),
                      "views": args.views or "vo.csv",
                      "command": "scripts/fit_track_model.py fit " + " ".join(args.sweeps) + f" --c {args.c}"
                                 + f" --features {','.join(names)}" + (f" --views {args.views}" if args.views else "")
                                 + (f" --ramps '{args.ramps}'" if args.ramps else "")
                                 + (" --free-signs" if args.free_signs else ""),
                      "weights_held_non_negative": list(dict.fromkeys(n for (n, _, _), m in zip(terms, monotone) if m))},
        "scores": {"train_auc": train_auc, "leave_one_scene_out_auc": loso,
                   "leave_one_scene_out_auc_with_motion": loso_motion},
        "suggested_min_track_probability": threshold,
        "class_flyable_accuracy_there": accuracy, "oracle_trials": flights,
    })
    text = json.dumps(doc, indent=2) + "\n"
    tmp = args.out + ".tmp"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, args.out)
    print(f"fitted on {len(trials)} trials of {len(scenes)} scenes, {len(y)} frames ({int(y.sum())} tracked): "
          f"training AUC {train_auc:.3f}, leave-one-scene-out AUC {loso:.3f} "
          f"(with speed and yaw rate {loso_motion:.3f}) -> {args.out}")
    for (n, _, r), w in zip(terms, weights):
        where = f" ramp {r[0]:.3f}..{r[1]:.3f}" if r is not None else ""
        print(f"  {n:22s}{where} weight {w:+.3f}")
    print(f"  class flyable (every frame at or above p) on its {flights} oracle trials: best p = {threshold:.2f}, "
          f"{accuracy:.3f} right")


def class_flyable(trials, threshold):
    """(right, of) over the oracle trials: every frame at or above threshold <=> the VO never lost."""
    right = n = 0
    for tr in trials:
        if tr["oracle"] < 0:
            continue
        n += 1
        right += bool((tr["p"] >= threshold).all()) == bool(tr["y"].all())
    return right, n


def choose_threshold(trials, mean, scale, weights, intercept):
    """The probability threshold with the most right "class flyable" calls on the oracle trials
    (the highest of equals: the cautious one), its accuracy and the number of trials."""
    for tr in trials:
        tr["p"] = probability(tr["x"], mean, scale, weights, intercept)
    best = (0.5, -1, 0)
    for threshold in np.round(np.arange(0.05, 0.96, 0.05), 2):
        right, n = class_flyable(trials, threshold)
        if right >= best[1]:
            best = (float(threshold), right, n)
    return best[0], (best[1] / best[2] if best[2] else float("nan")), best[2]


def load_model(path):
    try:
        with open(path) as f:
            doc = json.load(f)
    except (OSError, ValueError) as e:
        raise InputError(f"{path}: cannot read the model ({e})")
    features = doc.get("features") if isinstance(doc, dict) else None
    if not isinstance(doc, dict) or doc.get("format") != "tgnav-track-model":
        raise InputError(f"{path}: key 'format' is not \"tgnav-track-model\"")
    if not isinstance(features, list) or not features or any(n not in FEATURES for n in features):
        raise InputError(f"{path}: key 'features' has value '{features}', expected names among {FEATURES}")
    for key in ("mean", "scale", "weights", "intercept"):
        if key not in doc:
            raise InputError(f"{path}: key '{key}' is missing")
    ramps = doc.get("ramps", [None] * len(features))
    if not isinstance(ramps, list) or len(ramps) != len(features) or any(
            r is not None and (not isinstance(r, list) or len(r) != 2 or not r[1] > r[0]) for r in ramps):
        raise InputError(f"{path}: key 'ramps' has value '{ramps}', expected null or [lo, hi] per feature")
    names = list(dict.fromkeys(features))  # the distinct features, in order
    terms = [(n, names.index(n), tuple(r) if r is not None else None) for n, r in zip(features, ramps)]
    with open(path, "rb") as f:
        sha = hashlib.sha256(f.read()).hexdigest()[:16]
    return (names, terms, np.array(doc["mean"]), np.array(doc["scale"]), np.array(doc["weights"]),
            float(doc["intercept"]), sha)


def reliability(y, p, bins=10):
    edges = np.linspace(0, 1, bins + 1)
    rows = []
    for i in range(bins):
        sel = (p >= edges[i]) & ((p < edges[i + 1]) if i + 1 < bins else (p <= 1))
        if sel.sum():
            rows.append((edges[i], edges[i + 1], int(sel.sum()), float(p[sel].mean()), float(y[sel].mean())))
    return rows


def cmd_evaluate(args):
    names, terms, mean, scale, weights, intercept, sha = load_model(args.model)
    all_trials = read_sweeps(args.sweeps, args.min_z, args.views)
    with open(args.model) as f:
        fitted = json.load(f).get("view_settings")
    for tr in all_trials if fitted else []:
        if tr["view_settings"] != {k: float(fitted.get(k, VIEW_SETTING_DEFAULTS.get(k, float("nan"))))
                                   for k in VIEW_SETTINGS}:
            raise InputError(f"{tr['folder']}: its features were counted with {tr['view_settings']}, the model "
                             f"{args.model} with {fitted} (--views: features computed again with the model's settings)")
    trials = [dict(tr, x=design(tr["x"], terms)) for tr in select(all_trials, names)]
    for tr in trials:
        tr["p"] = probability(tr["x"], mean, scale, weights, intercept)
    y, p = stack(trials, "y"), stack(trials, "p")
    result = {"model": os.path.normpath(args.model), "model_sha256_16": sha, "views": args.views or "vo.csv",
              "sweeps": [os.path.normpath(d) for d in args.sweeps], "trials": len(trials), "frames": int(len(y)),
              "tracked": int(y.sum()), "roc_auc": auc(y, p), "threshold": args.threshold}
    # one feature alone, for comparison (the gates threshold detections and coverage)
    x = stack(all_trials, "x")
    result["single_feature_auc"] = {n: auc(y, x[:, i]) for i, n in enumerate(FEATURES)}
    rel = reliability(y, p)
    result["reliability"] = [{"from": a, "to": b, "frames": n, "mean_predicted": mp, "tracked": ot}
                             for a, b, n, mp, ot in rel]
    # class flyable (oracle trials): predicted = every airborne frame of the flown class at or above
    # the threshold; flown = the VO never lost.
    confusion = {"tp": 0, "fp": 0, "tn": 0, "fn": 0}
    per_trial = []
    for tr in trials:
        if tr["oracle"] < 0:
            continue
        predicted = bool((tr["p"] >= args.threshold).all())
        flown = bool(tr["y"].all())
        key = ("t" if predicted == flown else "f") + ("p" if predicted else "n")
        confusion[key] += 1
        per_trial.append({"trial": os.path.basename(tr["folder"]), "predicted_flyable": predicted,
                          "vo_kept": flown, "min_probability": float(tr["p"].min())})
    n = sum(confusion.values())
    result["class_flyable_by_threshold"] = [
        {"threshold": float(th), "right": r, "of": k}
        for th in np.round(np.arange(0.1, 0.91, 0.1), 1) for r, k in [class_flyable(trials, th)]]
    result["class_flyable"] = dict(confusion, accuracy=(confusion["tp"] + confusion["tn"]) / n if n else float("nan"),
                                   trials=per_trial)
    os.makedirs(args.out, exist_ok=True)
    with open(os.path.join(args.out, "reliability.csv"), "w") as f:
        f.write("from,to,frames,mean_predicted,tracked\n")
        for a, b, k, mp, ot in rel:
            f.write(f"{a:.2f},{b:.2f},{k},{mp:.4f},{ot:.4f}\n")
    with open(os.path.join(args.out, "evaluation.json"), "w") as f:
        json.dump(result, f, indent=2)
        f.write("\n")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        from sklearn.metrics import roc_curve
        fig, ax = plt.subplots(1, 2, figsize=(9, 4))
        ax[0].plot([0, 1], [0, 1], color="0.6", lw=1)
        ax[0].plot([r[3] for r in rel], [r[4] for r in rel], "o-")
        for r in rel:
            ax[0].annotate(str(r[2]), (r[3], r[4]), fontsize=7, xytext=(3, -9), textcoords="offset points")
        ax[0].set(xlabel="predicted probability of tracking", ylabel="share of frames tracked",
                  title="reliability (frames per bin)", xlim=(0, 1), ylim=(0, 1.02))
        fpr, tpr, _ = roc_curve(y, p)
        ax[1].plot(fpr, tpr)
        ax[1].plot([0, 1], [0, 1], color="0.6", lw=1)
        ax[1].set(xlabel="false positive rate", ylabel="true positive rate",
                  title=f"ROC, AUC {result['roc_auc']:.3f} ({len(y)} frames)")
        fig.tight_layout()
        fig.savefig(os.path.join(args.out, "reliability.png"), dpi=120)
    except ImportError:
        print("fit_track_model.py: figures skipped: matplotlib is not installed", file=sys.stderr)
    cf = result["class_flyable"]
    print(f"{len(trials)} trials, {len(y)} frames ({int(y.sum())} tracked): per-frame ROC AUC {result['roc_auc']:.3f}; "
          f"class flyable at p >= {args.threshold}: {cf['tp'] + cf['tn']}/{n} right "
          f"(tp {cf['tp']}, fp {cf['fp']}, tn {cf['tn']}, fn {cf['fn']}) -> {args.out}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="command", required=True)
    f = sub.add_parser("fit")
    f.add_argument("sweeps", nargs="+")
    f.add_argument("--out", required=True)
    f.add_argument("--c", type=float, default=1.0, help="inverse L2 regularisation of the logistic regression")
    f.add_argument("--min-z", type=float, default=0.5)
    f.add_argument("--free-signs", action="store_true",
                   help="let every weight take either sign (default: the texture features' weights are held >= 0)")
    f.add_argument("--features", default=",".join(FEATURES),
                   help="comma-separated subset of the features the model uses (default: all)")
    f.add_argument("--ramps", help="FEATURE=K1,K2,...[;FEATURE=...]: that feature as monotone ramps between "
                                   "consecutive knots (raw units: detections for a log_ feature)")
    e = sub.add_parser("evaluate")
    e.add_argument("sweeps", nargs="+")
    e.add_argument("--model", required=True)
    e.add_argument("--out", required=True)
    e.add_argument("--threshold", type=float, default=0.5)
    e.add_argument("--min-z", type=float, default=0.5)
    for p in (f, e):
        p.add_argument("--views", help="take the features from this file of each trial folder (a `tgnav views` CSV, "
                                       "e.g. at another visibility range) instead of vo.csv's predicted_* columns")
    args = ap.parse_args()
    try:
        cmd_fit(args) if args.command == "fit" else cmd_evaluate(args)
    except InputError as err:
        print(f"fit_track_model.py: {err}", file=sys.stderr)
        sys.exit(2)


if __name__ == "__main__":
    main()
