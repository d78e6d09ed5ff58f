#pragma once
// The planners of a sweep file's run (`planner:`): a built-in planner's name, or an external
// planner (docs/PLANNER_PROTOCOL.md) as a mapping, one or a list of them:
//
//   planner: [proposed, {external: "/usr/bin/python3 my_planner.py --fast", name: mine}]
//
// An external entry takes `external` (the command, run with /bin/sh -c in the sweep file's
// folder), `name` (its label: trial ids, metrics, reports) and optionally `timeout_s` and
// `classes` (planner.external's keys).
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "harness/config/yaml_util.h"

namespace tgnav::harness {

struct SweepPlanner {
  std::string name;                    // proposed | agnostic | rrtstar, or the external planner's name
  std::string external_command;        // "" for a built-in planner
  std::filesystem::path external_dir;  // the sweep file's folder (external only)
  // planner.external.timeout_s and .classes when the entry gives them (--set for each trial).
  std::vector<std::pair<std::string, std::string>> set;
  bool external() const { return !external_command.empty(); }
};

// run[planner] of the sweep file `doc` (`source`), `context` its dotted path ("runs[2]"). Fails
// (doc.fail, naming file:line) on an unknown planner, a bad entry or key, or a name that is not a
// valid planner label.
std::vector<SweepPlanner> readSweepPlanners(const YamlDoc& doc, const YAML::Node& run, const std::string& context,
                                            const std::filesystem::path& source);

}  // namespace tgnav::harness
