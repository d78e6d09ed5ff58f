#pragma once
// A planner the harness does not ship, run as a child process that speaks the protocol of
// docs/PLANNER_PROTOCOL.md (harness/run/external_plan.h): a scenario's `planner.external` section.
#include <string>

namespace tgnav::harness {

struct ExternalPlannerConfig {
  std::string command = "none";   // run with /bin/sh -c; "none": no external planner
  std::string name = "external";  // its label in plan.json, metrics, sweeps and reports
  // Its working directory: relative to the file that sets it (the current directory for --set and
  // the command line); "." by default, so a scenario's command runs beside the scenario.
  // loadScenario() makes it absolute when a command is configured.
  std::string dir = ".";
  double timeout_s = 10.0;  // one plan request's budget, start-up included (wall time)
  bool classes = false;     // the request names a classes.json with the topological classes

  bool configured() const { return command != "none"; }

  template <typename Archive>
  void visit(Archive& a) {
    a("command", command);
    a("name", name);
    a("dir", dir);
    a("timeout_s", timeout_s);
    a("classes", classes);
  }
  void validate() const;  // std::invalid_argument naming the key
};

// A planner label a user may give (`name`): 1-40 of [A-Za-z0-9_-], not a built-in planner's name
// (proposed, agnostic, rrtstar) nor "trajectory" or "path" (the labels of given routes).
bool isExternalPlannerName(const std::string& name);

}  // namespace tgnav::harness
