#pragma once
// The `tgnav plan` job, in one of two forms:
//  - on a scene's feature map (a scenario): the proposed, agnostic or RRT* planner, the trajectory
//    generated from its path, written as plan.json, trajectory.csv, the map layer and plan.<format>;
//  - topological planning (paper Sec. V-B) on a 2D occupancy grid (ROS map_server or MovingAI):
//    plan.json, the map layer (occupancy and the GVD) and plan.<format>.
// Files are staged and moved into the output folder together.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "harness/io/figures.h"
#include "planner/planner.h"

namespace tgnav::harness {

struct ScenarioPlanJob {
  std::filesystem::path scenario;
  planner::PlannerKind planner = planner::PlannerKind::kProposed;
  int samples = 0;                    // RRT*'s budget; 0: the planner config's
  std::optional<std::uint64_t> seed;  // default: the scenario's
  std::string map;                    // feature map folder; "" = the cache
  std::string map_cache;
  std::filesystem::path out;
  FigureFormat figure_format = FigureFormat::kPng;
  std::optional<int> homology_class;  // the oracle: fly this class (planner.oracle_class)
  std::vector<std::string> set;       // --set dotted.key=value overrides, as `tgnav trial` takes
};

struct GridPlanJob {
  std::filesystem::path grid;  // .yaml (+ .pgm) or .map
  std::string start;           // "X,Y", metres in the map frame
  std::string goal;
  double resolution_m = 1.0;  // of a MovingAI map
  double robot_radius_m = 0.3;
  int max_classes = 10;
  std::filesystem::path out;
  FigureFormat figure_format = FigureFormat::kPng;
};

// Every row of a MovingAI .scen file (or of one bucket) planned on its map: the map's graph is
// built once, then each row is a query. Writes scen.csv (a row per problem) and scen.json (the
// summary and timing).
struct GridScenJob {
  std::filesystem::path grid;  // the .map
  std::filesystem::path scen;
  std::optional<int> bucket;  // only this bucket's rows
  double resolution_m = 1.0;
  double robot_radius_m = 0.3;
  int max_classes = 10;
  std::filesystem::path out;
};

struct PlanJobResult {
  std::string summary;  // the line `tgnav plan` prints
  std::string warning;  // a line for stderr, or ""
  FigureOutcome figures;
  bool trajectory_failed = false;  // a scenario plan whose path could not become a trajectory
};

// InputError for bad input; an unreachable goal is a result (status no_path).
PlanJobResult runScenarioPlan(const ScenarioPlanJob& job);
PlanJobResult runGridPlan(const GridPlanJob& job);
PlanJobResult runGridScen(const GridScenJob& job);

}  // namespace tgnav::harness
