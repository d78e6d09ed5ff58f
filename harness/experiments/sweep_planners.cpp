#include "harness/experiments/sweep_planners.h"

#include "harness/base/errors.h"
#include "harness/config/external_planner_config.h"
#include "harness/run/plan_run.h"

namespace tgnav::harness {

namespace {

SweepPlanner externalEntry(const YamlDoc& doc, const YAML::Node& entry, const std::string& where,
                           const std::filesystem::path& source) {
  doc.requireKeys(entry, {"external", "name", "timeout_s", "classes"}, where);
  SweepPlanner p;
  const YAML::Node command = entry["external"];
  if (!command || !command.IsScalar() || command.Scalar().empty()) {
    doc.fail(entry, where + ": an external planner needs 'external': its command");
  }
  const YAML::Node name = entry["name"];
  if (!name || !name.IsScalar()) doc.fail(entry, where + ": an external planner needs 'name': its label in results");
  if (!isExternalPlannerName(name.Scalar())) {
    doc.fail(name, joinKey(where, "name") + ": '" + name.Scalar() +
                       "': 1-40 letters, digits, '_' or '-', and not proposed, agnostic, rrtstar, trajectory or path");
  }
  p.name = name.Scalar();
  p.external_command = command.Scalar();
  p.external_dir = std::filesystem::absolute(source.parent_path()).lexically_normal();
  for (const char* key : {"timeout_s", "classes"}) {
    const YAML::Node v = entry[key];
    if (!v) continue;
    if (!v.IsScalar()) doc.fail(v, joinKey(where, key) + ": expected a value");
    p.set.emplace_back(std::string("planner.external.") + key, v.Scalar());
  }
  return p;
}

}  // namespace

std::vector<SweepPlanner> readSweepPlanners(const YamlDoc& doc, const YAML::Node& run, const std::string& context,
                                            const std::filesystem::path& source) {
  const std::string key = joinKey(context, "planner");
  const YAML::Node node = run["planner"];
  std::vector<YAML::Node> entries;
  if (node.IsSequence()) {
    if (node.size() == 0) doc.fail(node, key + ": empty list (an axis needs at least one value)");
    for (const YAML::Node& e : node) entries.push_back(e);
  } else {
    entries.push_back(node);
  }
  std::vector<SweepPlanner> planners;
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const YAML::Node& e = entries[i];
    const std::string where = node.IsSequence() ? key + "[" + std::to_string(i) + "]" : key;
    if (e.IsMap()) {
      planners.push_back(externalEntry(doc, e, where, source));
      continue;
    }
    if (!e.IsScalar() || e.Scalar().empty()) {
      doc.fail(e, where + ": expected a planner's name or an external planner {external: COMMAND, name: NAME}");
    }
    try {
      SweepPlanner p;
      p.name = planner::toString(parsePlannerName(e.Scalar(), where));
      planners.push_back(p);
    } catch (const InputError& err) {
      doc.fail(e, err.what());
    }
  }
  return planners;
}

}  // namespace tgnav::harness
