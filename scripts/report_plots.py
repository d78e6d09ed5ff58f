#!/usr/bin/env python3
"""Figures of a `tgnav report` folder, drawn from its report.json (written by `tgnav report`):

  fig3_<scene>.png  every trial's true xy path over the scene's map, one panel per planner group
                    (the paper's Fig. 3); green: VO success, red: failed, x: where VO was lost
  fig4_<scene>.png  VO position error |p_est - p_true| against distance travelled along the true
                    path: per group the mean over the trials still tracking, with the min-max band,
                    and an x where each lost trial ended (the paper's Fig. 4)
  plan_time.png     mean planning time per group with std error bars, log scale

Usage: report_plots.py REPORT_DIR. Prints nothing on success; a failure ends with one line
"report_plots.py: error: ..." and exit status 1. Needs matplotlib (Debian: python3-matplotlib).
"""
import csv
import json
import math
import os
import sys


def fail(message):
    print(f"report_plots.py: error: {message}", file=sys.stderr)
    sys.exit(1)


def warn(message):
    print(f"report_plots.py: warning: {message}", file=sys.stderr)


try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    from matplotlib.lines import Line2D
except ImportError as e:
    fail(f"matplotlib is missing ({e}): install python3-matplotlib, or set TGNAV_PYTHON to a python3 that has it")

SUCCESS_COLOUR = "#2ca02c"
FAILED_COLOUR = "#d62728"
PALETTE = plt.get_cmap("tab10").colors
DPI = 150


def read_gt_xy(folder):
    """x, y columns of the trial's gt.tum (camera poses); None when the trial has none."""
    path = os.path.join(folder, "gt.tum")
    if not os.path.exists(path):
        return None
    rows = []
    with open(path) as f:
        for line in f:
            fields = line.split()
            if fields and not fields[0].startswith("#"):
                rows.append((float(fields[1]), float(fields[2])))
    return np.array(rows) if rows else None


def read_vo_error(folder):
    """(distance travelled along the true camera path, position error) at the tracked frames of
    vo.csv; None when the trial has no vo.csv or no frames."""
    path = os.path.join(folder, "vo.csv")
    if not os.path.exists(path):
        return None
    distance, travelled, errors = [], 0.0, []
    previous = None
    with open(path) as f:
        for row in csv.DictReader(f):
            p_true = np.array([float(row["x_true"]), float(row["y_true"]), float(row["z_true"])])
            if previous is not None:
                travelled += float(np.linalg.norm(p_true - previous))
            previous = p_true
            if row["x_est"] == "":
                continue
            p_est = np.array([float(row["x_est"]), float(row["y_est"]), float(row["z_est"])])
            distance.append(travelled)
            errors.append(float(np.linalg.norm(p_est - p_true)))
    if previous is None:
        return None
    return np.array(distance), np.array(errors)


def success_rate(group):
    n = len(group["trials"])
    return f"{group['successes']}/{n}"


def group_colours(groups):
    """One colour per planner label, the same in every figure."""
    labels = []
    for g in groups:
        if g["label"] not in labels:
            labels.append(g["label"])
    return {label: PALETTE[i % len(PALETTE)] for i, label in enumerate(labels)}


def scene_groups(report, scene):
    return [g for g in report["groups"] if g["scene"] == scene]


def trajectory_extent(groups, margin=0.5):
    """x0, x1, y0, y1 around every trial's true path."""
    paths = [read_gt_xy(t["folder"]) for g in groups for t in g["trials"]]
    points = np.concatenate([p for p in paths if p is not None] or [np.zeros((1, 2))])
    lo, hi = points.min(axis=0) - margin, points.max(axis=0) + margin
    return lo[0], hi[0], lo[1], hi[1]


def draw_fig3(report, scene, report_dir, path):
    groups = scene_groups(report, scene["name"])
    if scene["extent_m"] is not None:
        x0, x1, y0, y1 = scene["extent_m"]
    else:  # no map: the extent of the trajectories
        x0, x1, y0, y1 = trajectory_extent(groups)
    columns = min(len(groups), 3)
    rows = math.ceil(len(groups) / columns)
    panel_w = 4.6
    # Axes of equal aspect: about 0.8 in of each panel's width go to the y labels, 0.9 in of its
    # height to the title and x labels.
    panel_h = (panel_w - 0.8) * (y1 - y0) / (x1 - x0) + 0.9
    fig, axes = plt.subplots(rows, columns, figsize=(panel_w * columns, panel_h * rows + 0.9), squeeze=False)
    background = plt.imread(os.path.join(report_dir, scene["map"])) if scene["map"] else None
    for ax, group in zip(axes.flat, groups):
        if background is not None:
            ax.imshow(background, extent=(x0, x1, y0, y1), origin="upper", interpolation="bilinear", alpha=0.85)
        for trial in group["trials"]:
            xy = read_gt_xy(trial["folder"])
            if xy is None:
                if trial["status"] != "plan_failed":
                    warn(f"{trial['folder']}: no gt.tum; trial {trial['id']} left out of fig3")
                continue
            colour = SUCCESS_COLOUR if trial["status"] == "success" else FAILED_COLOUR
            ax.plot(xy[:, 0], xy[:, 1], color=colour, lw=1.3, alpha=0.75, solid_capstyle="round")
        for trial in group["trials"]:
            lost = trial["vo_lost_position"]
            if lost is not None:
                ax.plot(lost[0], lost[1], "x", color="black", ms=9, mew=2.4)
                ax.plot(lost[0], lost[1], "x", color=FAILED_COLOUR, ms=7, mew=1.2)
        if scene["start_xy"] is not None:
            ax.plot(*scene["start_xy"], "o", ms=9, mfc="white", mec="black", mew=1.5)
            ax.plot(*scene["goal_xy"], "*", ms=15, mfc="gold", mec="black", mew=1.0)
        ax.set_xlim(x0, x1)
        ax.set_ylim(y0, y1)
        ax.set_aspect("equal")
        ax.set_title(f"{group['label']}: {success_rate(group)} VO success", fontsize=11)
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.tick_params(labelsize=8)
    for ax in list(axes.flat)[len(groups):]:
        ax.axis("off")
    legend = [
        Line2D([], [], color=SUCCESS_COLOUR, lw=2, label="VO success"),
        Line2D([], [], color=FAILED_COLOUR, lw=2, label="failed"),
        Line2D([], [], ls="", marker="x", color="black", ms=9, mew=2.4, label="VO lost"),
    ]
    if scene["start_xy"] is not None:
        legend += [
            Line2D([], [], ls="", marker="o", ms=9, mfc="white", mec="black", mew=1.5, label="start"),
            Line2D([], [], ls="", marker="*", ms=14, mfc="gold", mec="black", label="goal"),
        ]
    fig.legend(handles=legend, loc="lower center", ncol=len(legend), frameon=False, fontsize=9)
    fig.suptitle(f"{scene['name']}: true trajectories (ground truth)", fontsize=12)
    fig.tight_layout(rect=(0, 0.05, 1, 1))
    fig.savefig(path, dpi=DPI)
    plt.close(fig)


def mean_curve(curves, grid):
    """Mean, min and max over the curves covering each grid distance (NaN where none does)."""
    stack = np.full((len(curves), grid.size), np.nan)
    for k, (d, e) in enumerate(curves):
        inside = grid <= d[-1]
        stack[k, inside] = np.interp(grid[inside], d, e)
    with np.errstate(all="ignore"):
        covered = np.any(~np.isnan(stack), axis=0)
        mean = np.full(grid.size, np.nan)
        lo = np.full(grid.size, np.nan)
        hi = np.full(grid.size, np.nan)
        mean[covered] = np.nanmean(stack[:, covered], axis=0)
        lo[covered] = np.nanmin(stack[:, covered], axis=0)
        hi[covered] = np.nanmax(stack[:, covered], axis=0)
    return mean, lo, hi


def draw_fig4(report, scene, colours, path):
    groups = scene_groups(report, scene["name"])
    data = []  # per group: [(distance, error)], [(lost distance, error)]
    longest = 0.0
    for group in groups:
        curves, ends = [], []
        for trial in group["trials"]:
            curve = read_vo_error(trial["folder"])
            if curve is None:
                if trial["status"] != "plan_failed":
                    warn(f"{trial['folder']}: no vo.csv; trial {trial['id']} left out of fig4")
                continue
            d, e = curve
            if d.size == 0:
                continue
            curves.append((d, e))
            longest = max(longest, d[-1])
            if trial["status"] == "vo_lost":
                ends.append((d[-1], e[-1]))
        data.append((curves, ends))
    fig, ax = plt.subplots(figsize=(10.0, 4.6))
    grid = np.linspace(0.0, longest if longest > 0 else 1.0, 400)
    for group, (curves, ends) in zip(groups, data):
        colour = colours[group["label"]]
        label = f"{group['label']} ({success_rate(group)})"
        if not curves:
            ax.plot([], [], color=colour, lw=2, label=label + ", no tracked frames")
            continue
        mean, lo, hi = mean_curve(curves, grid)
        ax.fill_between(grid, lo, hi, color=colour, alpha=0.18, lw=0)
        ax.plot(grid, mean, color=colour, lw=2, label=label)
        for d, e in ends:
            ax.plot(d, e, "X", ms=10, mfc=colour, mec="black", mew=1.0, zorder=5)
    if any(ends for _, ends in data):
        ax.plot([], [], "X", ms=10, mfc="white", mec="black", ls="", label="VO lost (end of trial)")
    ax.set_xlim(0.0, 1.02 * grid[-1])  # room for a lost marker at the end
    ax.set_ylim(bottom=0.0)
    ax.set_xlabel("distance travelled [m]")
    ax.set_ylabel("VO position error [m]")
    ax.set_title(f"{scene['name']}: VO position error (legend: VO success rate)", fontsize=12)
    ax.grid(True, color="#e0e0e0")
    ax.legend(fontsize=9, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    fig.text(0.99, 0.01, "line: mean over the trials still tracking; band: min–max over them", ha="right",
             va="bottom", fontsize=8, color="#555555")
    fig.tight_layout(rect=(0, 0.03, 1, 1))
    fig.savefig(path, dpi=DPI)
    plt.close(fig)


def draw_plan_time(report, colours, path):
    scenes = [s["name"] for s in report["scenes"]]
    fig, ax = plt.subplots(figsize=(max(5.0, 1.0 + 0.9 * len(report["groups"]) + 0.6 * len(scenes)), 4.6))
    x, ticks, tick_labels, centres, top = 0.0, [], [], [], 0.0
    bottom = math.inf
    for scene in scenes:
        first = x
        for group in scene_groups(report, scene):
            stat = group["plan_time_s"]
            if stat is None:
                x += 1.0
                continue
            mean, std = stat["mean"], stat["std"]
            # On a log axis the lower bar must stay above zero.
            low = min(std, 0.95 * mean)
            ax.bar(x, mean, width=0.75, color=colours[group["label"]], edgecolor="black", lw=0.6,
                   yerr=[[low], [std]] if stat["n"] > 1 else None, capsize=4, error_kw={"lw": 1})
            ax.text(x, (mean + std) * 1.12, f"{mean:.3g} s", ha="center", va="bottom", fontsize=8)
            ticks.append(x)
            tick_labels.append(group["label"].replace(" [", "\n["))  # params on a line of their own
            top = max(top, mean + std)
            bottom = min(bottom, mean - low)
            x += 1.0
        centres.append(((first + x - 1.0) / 2.0, scene))
        x += 0.8
    ax.set_yscale("log")
    if top > 0:
        ax.set_ylim(max(bottom, 1e-6) / 3.0, top * 4.0)
    ax.set_xticks(ticks)
    ax.set_xticklabels(tick_labels, fontsize=8 if len(ticks) > 6 else 9)
    ax.set_ylabel("plan time [s]")
    for centre, scene in centres:
        ax.text(centre, -0.16 if any("\n" in t for t in tick_labels) else -0.12, scene, transform=ax.get_xaxis_transform(), ha="center", va="top", fontsize=11,
                style="italic")
    ax.set_title("Planning time: mean ± std per group", fontsize=12)
    ax.grid(True, axis="y", which="both", color="#e6e6e6")
    ax.set_axisbelow(True)
    fig.tight_layout()
    fig.savefig(path, dpi=DPI)
    plt.close(fig)


def main():
    if len(sys.argv) != 2:
        fail("usage: report_plots.py REPORT_DIR")
    report_dir = sys.argv[1]
    report_path = os.path.join(report_dir, "report.json")
    try:
        with open(report_path) as f:
            report = json.load(f)
    except (OSError, ValueError) as e:
        fail(f"{report_path}: {e}")
    colours = group_colours(report["groups"])
    try:
        for scene in report["scenes"]:
            draw_fig3(report, scene, report_dir, os.path.join(report_dir, f"fig3_{scene['name']}.png"))
            draw_fig4(report, scene, colours, os.path.join(report_dir, f"fig4_{scene['name']}.png"))
        draw_plan_time(report, colours, os.path.join(report_dir, "plan_time.png"))
    except (OSError, ValueError, KeyError) as e:
        fail(f"{type(e).__name__}: {e}")


if __name__ == "__main__":
    main()
