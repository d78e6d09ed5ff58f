#!/usr/bin/python3
"""Did the online map foresee the views that lost the VO? (issue 40; docs/results/flown_views)

Each plan of an online trial that is flown (adopted, or its views renewed) rates, on the map it was
made on, the views the vehicle then flies over the replan period: online.json's flown_min_p (the
learned model's least probability of tracking), flown_min_at_s (when), and own_min_p (the plan's
own views before the look-ahead turned them; asked only where the flown ones rate blind). This
script reads a sweep's trials (or trial folders) and reports, per trial, the plan in force when
the VO was lost and what it had rated, and, over all rated windows the VO came through, how often
a window was rated blind anyway (the rating's false alarms).

A window is [effective_s, the next rated plan's effective_s or effective_s + replan_period_s]; its
worst view counts only if it lies inside the window (a later plan replaced the views after it).
A plan made on a map with no landmarks, mapped or of trial.unseen_prior (from no map, the plan before
take-off), rates every view blind: a loss in its window says 'nothing mapped yet', and its window is
not counted among those the VO came through.

usage: flown_views.py RESULTS... [--out CSV] [--threshold P]
RESULTS: sweep folders (their trials/*) or trial folders (metrics.json, online.json, vo.csv).
"""
import argparse
import bisect
import csv
import glob
import json
import os
import statistics
import sys

import yaml


THRESHOLDS = (0.01, 0.02, 0.05, 0.1, 0.2, 0.35, 0.5)


class InputError(Exception):
    pass


def trial_dirs(paths):
    out = []
    for p in paths:
        if os.path.isfile(os.path.join(p, 'metrics.json')):
            out.append(p)
            continue
        found = sorted(d for d in glob.glob(os.path.join(p, 'trials', '*')) if os.path.isfile(os.path.join(d, 'metrics.json')))
        if not found:
            raise InputError(f'{p}: neither a trial folder (metrics.json) nor a sweep folder (trials/*/metrics.json)')
        out.extend(found)
    return out


def read_json(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError) as e:
        raise InputError(f'{path}: cannot read: {e}') from e


def vo_inliers(folder):
    path = os.path.join(folder, 'vo.csv')
    try:
        with open(path) as f:
            rows = list(csv.DictReader(f))
    except OSError as e:
        raise InputError(f'{path}: cannot read: {e}') from e
    if rows and 'inliers' not in rows[0]:
        raise InputError(f"{path}: no column 'inliers'")
    times = [float(r['t']) for r in rows]
    inliers = [int(r['inliers']) for r in rows]
    return times, inliers


def at(times, values, t):
    if not times:
        return None
    i = min(bisect.bisect_left(times, t - 1e-9), len(times) - 1)
    return values[i]


def replan_period(folder):
    path = os.path.join(folder, 'config.yaml')
    try:
        with open(path) as f:
            config = yaml.safe_load(f)
    except (OSError, yaml.YAMLError) as e:
        raise InputError(f'{path}: cannot read: {e}') from e
    try:
        period = float(config['trial']['replan_period_s'])
    except (KeyError, TypeError, ValueError) as e:
        raise InputError(f"{path}: key 'trial.replan_period_s' missing or not a number") from e
    if not period > 0.0:
        raise InputError(f"{path}: key 'trial.replan_period_s' has value {period}: must be > 0")
    return period


def windows(plans, period):
    rated = [p for p in plans if p.get('flown_min_p', -1.0) >= 0.0]
    out = []
    for k, p in enumerate(rated):
        start = p['effective_s']
        end = start + period
        if k + 1 < len(rated):
            end = min(end, rated[k + 1]['effective_s'])
        out.append((start, end, p))
    return out


def foreseen(p, lost, threshold):
    """Whether plan p rated a view blind at or before the loss (0.5 s: a frame or so after it)."""
    return p['flown_min_p'] < threshold and p['flown_min_at_s'] <= lost + 0.5


def empty_map(p):
    return p['landmarks'] + p['prior_landmarks'] == 0


def attribution(p, lost, threshold):
    if empty_map(p):
        return 'rated blind: nothing mapped yet'
    if p['flown_min_p'] >= threshold:
        return 'rated trackable'
    if not foreseen(p, lost, threshold):
        return 'its worst view after the loss'  # the views at the loss not known (only the worst is kept)
    if p['own_min_p'] >= threshold:
        return 'rated blind: turned by the look-ahead or splice'
    return "rated blind: the plan's own views"


def analyse(folder, threshold):
    m = read_json(os.path.join(folder, 'metrics.json'))
    if m.get('mode') != 'online':
        raise InputError(f"{folder}/metrics.json: key 'mode' has value '{m.get('mode')}': not an online trial")
    online = read_json(os.path.join(folder, 'online.json'))
    plans = online.get('plans')
    if not isinstance(plans, list):
        raise InputError(f"{folder}/online.json: key 'plans' missing")
    for key, why in (('flown_min_p', ' (flown before the flown views were rated)'), ('landmarks', ''),
                     ('prior_landmarks', '')):
        if plans and key not in plans[0]:
            raise InputError(f"{folder}/online.json: key '{key}' missing{why}")
    period = replan_period(folder)
    lost = m.get('vo_lost_at_s')
    times, inliers = vo_inliers(folder)
    row = {'trial': os.path.basename(folder.rstrip('/')), 'planner': m.get('planner', ''), 'scene': m.get('scene', ''),
           'status': m.get('status', ''), 'vo_lost_at_s': '' if lost is None else lost}
    passed = []  # (window's worst p, VO inliers at that view) for windows the VO came through
    in_force = None  # the plan whose window holds the loss
    for start, end, p in windows(plans, period):
        if lost is not None and lost < end + 1e-9:
            if start <= lost:
                in_force = p
            continue
        if p['flown_min_at_s'] > end + 1e-9:
            continue  # replaced before that view was flown
        if empty_map(p):
            continue  # nothing mapped: every view rates blind
        passed.append((p['flown_min_p'], at(times, inliers, p['flown_min_at_s'])))
    row.update(loss_plan_s='', flown_min_p='', flown_min_at_s='', own_min_p='', attribution='')
    if in_force is not None:
        p = in_force
        row.update(loss_plan_s=p['t_s'], flown_min_p=p['flown_min_p'], flown_min_at_s=p['flown_min_at_s'],
                   own_min_p=p['own_min_p'], attribution=attribution(p, lost, threshold))
    elif lost is not None:
        row['attribution'] = 'no rated plan'
    row['windows_passed'] = len(passed)
    row['windows_passed_rated_blind'] = sum(1 for q, _ in passed if q < threshold)
    return row, passed


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('results', nargs='+')
    ap.add_argument('--out', help='per-trial CSV')
    ap.add_argument('--threshold', type=float, default=0.35, help='blind below this probability (the planner default)')
    args = ap.parse_args(argv)
    if not 0.0 < args.threshold < 1.0:
        raise InputError(f'--threshold: value {args.threshold}: must lie in (0, 1)')
    rows, passed_all = [], []
    for d in trial_dirs(args.results):
        row, passed = analyse(d, args.threshold)
        rows.append(row)
        passed_all.extend((row['planner'], q, n) for q, n in passed)
    fields = ['trial', 'planner', 'scene', 'status', 'vo_lost_at_s', 'loss_plan_s', 'flown_min_p', 'flown_min_at_s',
              'own_min_p', 'attribution', 'windows_passed', 'windows_passed_rated_blind']
    if args.out:
        tmp = args.out + '.tmp'
        with open(tmp, 'w', newline='') as f:
            w = csv.DictWriter(f, fieldnames=fields)
            w.writeheader()
            w.writerows(rows)
        os.replace(tmp, args.out)
    for planner in sorted(set(r['planner'] for r in rows)):
        rs = [r for r in rows if r['planner'] == planner]
        losses = [r for r in rs if r['vo_lost_at_s'] != '']
        print(f'{planner}: {len(rs)} trials, {len(losses)} VO losses')
        kinds = {}
        for r in losses:
            kinds[r['attribution']] = kinds.get(r['attribution'], 0) + 1
        for k, n in sorted(kinds.items(), key=lambda kv: -kv[1]):
            print(f'  at the loss, the plan in force had {k}: {n}')
        ps = [(q, n) for pl, q, n in passed_all if pl == planner]
        blind = [n for q, n in ps if q < args.threshold and n is not None]
        print(f'  windows the VO came through: {len(ps)}; rated blind anyway: {len(blind)}'
              + (f' (VO inliers at that view: median {statistics.median(blind):.0f})' if blind else ''))
        # Were the plans to stop short of every view rated below a threshold: the losses that would
        # have been foreseen, against the windows the VO came through that would have been stopped.
        for t in THRESHOLDS:
            seen = sum(1 for r in losses if r['flown_min_p'] != '' and foreseen(r, r['vo_lost_at_s'], t))
            alarms = sum(1 for q, _ in ps if q < t)
            print(f'  below {t:g}: {seen} of {len(losses)} losses foreseen; {alarms} of the {len(ps)} windows the VO came through rated so too')
    return 0


if __name__ == '__main__':
    try:
        sys.exit(main(sys.argv[1:]))
    except InputError as e:
        print(f'flown_views.py: {e}', file=sys.stderr)
        sys.exit(2)
