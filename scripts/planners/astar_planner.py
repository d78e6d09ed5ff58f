#!/usr/bin/env python3
"""A perception-agnostic example planner for tgnav's external planner protocol
(docs/PLANNER_PROTOCOL.md): the shortest grid route, nothing else.

A* on the request's occupancy slice inflated by robot_radius_m + a margin, shortcut by line of
sight, flown at flight_height_m with the camera looking along the direction of travel. Waypoints
are at most 0.5 m apart.

    tgnav trial --scenario configs/scenarios/storage.yaml \\
        --planner-command "/usr/bin/python3 scripts/planners/astar_planner.py" --planner-name astar

Standard library + numpy only.
"""
import argparse
import math
import os
import sys

import numpy as np

sys.dont_write_bytecode = True  # no __pycache__ left in the repository by a trial
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import tgnav_planner as tp  # noqa: E402


def travel_yaw(xyz, start_yaw, goal_yaw):
    """Yaw per waypoint: the start's yaw first, the goal's yaw last, and in between the direction
    of the segment that arrives at the waypoint."""
    d = np.diff(xyz[:, :2], axis=0)
    yaw = np.concatenate([[start_yaw], np.arctan2(d[:, 1], d[:, 0])])
    yaw[-1] = goal_yaw
    return tp.wrap(yaw)


def make_plan(margin_m, max_step_m):
    """The plan function for tp.serve."""

    def plan(req):
        grid, free = tp.free_space(req, margin_m)
        route = tp.grid_route(req, grid, free)
        route = tp.shortcut(route, grid, free)
        xyz, _ = tp.waypoints_3d(req, route, max_step_m)
        yaw = travel_yaw(xyz, float(req["start"][3]), float(req["goal"][3]))
        length = float(np.sum(np.linalg.norm(np.diff(xyz, axis=0), axis=1)))
        tp.log("request %s: %d waypoints, %.2f m" % (req.get("id"), len(xyz), length))
        return {"path": tp.path_rows(xyz, yaw)}

    return plan


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--margin", type=float, default=0.1,
                    help="metres of clearance kept beyond robot_radius_m (default 0.1)")
    ap.add_argument("--max-step", type=float, default=0.5,
                    help="largest distance between consecutive waypoints, metres (default 0.5)")
    args = ap.parse_args(argv)
    if not (args.margin >= 0 and args.max_step > 0 and math.isfinite(args.max_step)):
        ap.error("--margin must be >= 0 and --max-step > 0")
    tp.serve(make_plan(args.margin, args.max_step))
    return 0


if __name__ == "__main__":
    sys.exit(main())
