#include "harness/experiments/report_scenes.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <sstream>

#include "harness/experiments/statistics.h"

namespace tgnav::harness {
namespace {

bool isOracle(const IndexRow& r) { return r.oracle_class.has_value(); }

std::optional<double> median(std::vector<double> v) {
  if (v.empty()) return std::nullopt;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

bool predictedFlyable(const IndexRow& r) {
  return r.chosen_c_p_min && r.c_p_threshold && *r.chosen_c_p_min >= *r.c_p_threshold;
}

bool choseFlyable(const IndexRow& r, const std::vector<int>& flyable) {
  return r.chosen_class && std::count(flyable.begin(), flyable.end(), *r.chosen_class) > 0;
}

SceneReport& sceneOf(std::vector<SceneReport>& scenes, const std::string& name) {
  auto it = std::find_if(scenes.begin(), scenes.end(), [&](const SceneReport& s) { return s.scene == name; });
  if (it != scenes.end()) return *it;
  scenes.push_back(SceneReport{name, std::nullopt, {}, {}});
  return scenes.back();
}

void addOracleTrial(SceneReport& scene, const IndexRow& r) {
  auto it = std::find_if(scene.oracle.begin(), scene.oracle.end(),
                         [&](const OracleClass& c) { return c.index == *r.oracle_class; });
  if (it == scene.oracle.end()) {
    OracleClass c;
    c.index = *r.oracle_class;
    scene.oracle.push_back(c);
    it = std::prev(scene.oracle.end());
  }
  if (!it->c_p_min && r.chosen_c_p_min && r.c_p_threshold) {  // the first trial that scored it (AP does not)
    it->c_p_min = r.chosen_c_p_min;
    it->c_p_threshold = r.c_p_threshold;
  }
  ++it->trials;
  if (r.status == "success") ++it->successes;
  it->flyable = isFlyable(it->successes, it->trials);
}

// The planner rows of one scene, with the flyable classes known.
void addPlanners(SceneReport& scene, const std::vector<IndexRow>& rows) {
  const std::vector<int> flyable = scene.flyableClasses();
  std::vector<std::vector<double>> goals;
  for (const IndexRow& r : rows) {
    if (r.scene != scene.scene || isOracle(r)) continue;
    auto it = std::find_if(scene.planners.begin(), scene.planners.end(), [&](const ScenePlanner& p) {
      return p.planner == r.planner && p.samples == r.samples && p.params == r.params;
    });
    if (it == scene.planners.end()) {
      scene.planners.push_back(
          {plannerLabel(r.planner, r.samples, r.params), r.planner, r.samples, r.params, 0, 0, std::nullopt, 0});
      goals.emplace_back();
      it = std::prev(scene.planners.end());
    }
    ++it->trials;
    if (r.status == "success") {
      ++it->successes;
      if (r.goal_error_m) goals[static_cast<std::size_t>(it - scene.planners.begin())].push_back(*r.goal_error_m);
    }
    if (choseFlyable(r, flyable)) ++it->chose_flyable;
  }
  for (std::size_t i = 0; i < goals.size(); ++i) scene.planners[i].goal_error_median_m = median(goals[i]);
}

// 0 <= k <= n and n > 0 (formatShare), so the share is in [0, 100]: lround is the old (int)(x + 0.5).
std::string percent(int k, int n) { return std::to_string(static_cast<int>(std::lround(100.0 * k / n))) + "%"; }

std::string classList(const std::vector<int>& classes) {
  std::string out;
  for (const int k : classes) out += (out.empty() ? "" : ";") + std::to_string(k);
  return out;
}

std::string optionalCsv(const std::optional<double>& v) { return v ? csvNumber(*v) : ""; }

std::string optionalSig3(const std::optional<double>& v) { return v ? formatSig3(*v) : "–"; }

std::string sceneCell(const std::vector<SceneReport>& scenes, std::size_t i, bool first) {
  return first ? "*" + markdownCell(scenes[i].scene) + "*" : "";
}

// The scenes' flyable classes, then each oracle class's VO success.
std::string oracleMarkdown(const std::vector<SceneReport>& scenes) {
  std::vector<std::vector<std::string>> summary, classes;
  for (std::size_t i = 0; i < scenes.size(); ++i) {
    const SceneReport& s = scenes[i];
    int trials = 0;
    for (const OracleClass& c : s.oracle) trials += c.trials;
    std::string flyable = s.oracle.empty() ? "n/a" : "none";
    if (s.hasFlyable()) {
      flyable.clear();
      for (const int k : s.flyableClasses()) flyable += (flyable.empty() ? "" : ", ") + std::to_string(k);
    }
    summary.push_back({sceneCell(scenes, i, true), s.classes ? std::to_string(*s.classes) : "–",
                       std::to_string(s.oracle.size()), std::to_string(trials), flyable});
    for (std::size_t k = 0; k < s.oracle.size(); ++k) {
      const OracleClass& c = s.oracle[k];
      std::string predicted = "–";
      if (c.c_p_min && c.c_p_threshold) predicted = *c.c_p_min >= *c.c_p_threshold ? "yes" : "no";
      classes.push_back({sceneCell(scenes, i, k == 0), std::to_string(c.index),
                         std::to_string(c.successes) + "/" + std::to_string(c.trials), optionalSig3(c.c_p_min),
                         predicted, c.flyable ? "yes" : "no"});
    }
  }
  std::string out = markdownTable({"Scene", "Classes", "Classes flown by the oracle", "Oracle trials", "Flyable"},
                                  {false, true, true, true, false}, summary);
  if (classes.empty()) return out + "\nNo oracle trials: which classes are flyable is unknown (n/a).\n";
  out += "\n" + markdownTable({"Scene", "Class", "VO success", "c_p_min", "Predicted flyable", "Flyable"},
                              {false, true, true, true, false, false}, classes);
  return out +
         "\nFlyable: the VO tracked to the goal in at least 2/3 of the class's oracle trials (trials that flew it "
         "on request, any planner). Predicted flyable: its weakest segment's score c_p_min (plan.json) is at least "
         "c_p_threshold.\n";
}

std::string plannerMarkdown(const std::vector<SceneReport>& scenes) {
  std::vector<std::vector<std::string>> cells;
  for (std::size_t i = 0; i < scenes.size(); ++i) {
    const SceneReport& s = scenes[i];
    for (std::size_t k = 0; k < s.planners.size(); ++k) {
      const ScenePlanner& p = s.planners[k];
      cells.push_back({sceneCell(scenes, i, k == 0), markdownCell(p.label), std::to_string(p.trials),
                       std::to_string(p.successes) + "/" + std::to_string(p.trials),
                       optionalSig3(p.goal_error_median_m),
                       s.hasFlyable() ? std::to_string(p.chose_flyable) + "/" + std::to_string(p.trials) : "n/a"});
    }
  }
  return markdownTable({"Scene", "Planner", "Trials", "VO success", "Goal error median (m)*", "Chose a flyable class"},
                       {false, false, true, true, true, true}, cells) +
         "\n*Over successful trials. Oracle trials are not counted here.\n";
}

}  // namespace

bool isFlyable(int successes, int trials) { return trials > 0 && 3 * successes >= 2 * trials; }

std::vector<int> SceneReport::flyableClasses() const {
  std::vector<int> out;
  for (const OracleClass& c : oracle) {
    if (c.flyable) out.push_back(c.index);
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<SceneReport> sceneReports(const std::vector<IndexRow>& rows) {
  std::vector<SceneReport> scenes;
  for (const IndexRow& r : rows) {
    SceneReport& scene = sceneOf(scenes, r.scene);
    if (r.classes) scene.classes = std::max(scene.classes.value_or(0), *r.classes);
    if (isOracle(r)) addOracleTrial(scene, r);
  }
  for (SceneReport& scene : scenes) {
    std::sort(scene.oracle.begin(), scene.oracle.end(),
              [](const OracleClass& a, const OracleClass& b) { return a.index < b.index; });
    addPlanners(scene, rows);
  }
  return scenes;
}

bool wantsSceneTable(const std::vector<IndexRow>& rows) {
  std::set<std::string> scenes;
  for (const IndexRow& r : rows) {
    if (isOracle(r)) return true;
    scenes.insert(r.scene);
  }
  return scenes.size() > 1;
}

std::vector<AggregateRow> aggregateRows(const std::vector<IndexRow>& rows, const std::vector<SceneReport>& scenes) {
  std::map<std::string, std::vector<int>> flyable;  // scene -> its flyable classes
  for (const SceneReport& s : scenes) flyable[s.scene] = s.flyableClasses();
  std::vector<AggregateRow> out;
  std::vector<std::set<std::string>> seen, covered;  // per row: its scenes, those with a flyable class
  AggregateRow oracle;
  oracle.label = "Oracle";
  oracle.planner = "oracle";
  oracle.oracle = true;
  for (const IndexRow& r : rows) {
    AggregateRow* a = &oracle;
    if (!isOracle(r)) {
      auto it = std::find_if(out.begin(), out.end(), [&](const AggregateRow& x) {
        return x.planner == r.planner && x.samples == r.samples && x.params == r.params;
      });
      if (it == out.end()) {
        out.push_back({plannerLabel(r.planner, r.samples, r.params), r.planner, r.samples, r.params});
        seen.emplace_back();
        covered.emplace_back();
        it = std::prev(out.end());
      }
      a = &*it;
      const auto k = static_cast<std::size_t>(it - out.begin());
      seen[k].insert(r.scene);
      if (!flyable[r.scene].empty()) {
        covered[k].insert(r.scene);
        ++a->covered_trials;
        if (r.status == "success") ++a->covered_successes;
        if (choseFlyable(r, flyable[r.scene])) ++a->chose_flyable;
      }
    }
    ++a->trials;
    if (predictedFlyable(r)) {
      ++a->predicted_flyable;
      if (r.status == "success") ++a->predicted_successes;
    }
  }
  for (std::size_t k = 0; k < out.size(); ++k) {
    out[k].scenes = static_cast<int>(seen[k].size());
    out[k].covered_scenes = static_cast<int>(covered[k].size());
  }
  if (oracle.trials > 0) out.push_back(oracle);
  return out;
}

std::string formatShare(int k, int n) {
  if (n == 0) return "n/a";
  const Interval w = wilsonInterval(k, n);
  return std::to_string(k) + "/" + std::to_string(n) + " (" + percent(k, n) + "; " +
         std::to_string(std::lround(100.0 * w.lo)) + "–" + std::to_string(std::lround(100.0 * w.hi)) + "%)";
}

std::string scenesCsv(const std::vector<SceneReport>& scenes) {
  std::ostringstream out;
  out << "scene,kind,label,planner,samples,params,class,trials,successes,vo_success_rate,goal_error_median_m,"
         "chose_flyable,flyable,c_p_min,c_p_threshold,scene_classes,oracle_classes,flyable_classes\n";
  for (const SceneReport& s : scenes) {
    const std::string tail = "," + (s.classes ? std::to_string(*s.classes) : "") + "," +
                             std::to_string(s.oracle.size()) + "," + classList(s.flyableClasses()) + "\n";
    for (const OracleClass& c : s.oracle) {
      out << s.scene << ",oracle,Oracle " << c.index << ",,0,," << c.index << ',' << c.trials << ',' << c.successes
          << ',' << csvNumber(static_cast<double>(c.successes) / c.trials) << ",,," << (c.flyable ? 1 : 0) << ','
          << optionalCsv(c.c_p_min) << ',' << optionalCsv(c.c_p_threshold) << tail;
    }
    for (const ScenePlanner& p : s.planners) {
      out << s.scene << ",planner," << p.label << ',' << p.planner << ',' << p.samples << ',' << p.params << ",,"
          << p.trials << ',' << p.successes << ',' << csvNumber(static_cast<double>(p.successes) / p.trials) << ','
          << optionalCsv(p.goal_error_median_m) << ',' << (s.oracle.empty() ? "" : std::to_string(p.chose_flyable))
          << ",,," << tail;
    }
  }
  return out.str();
}

std::string aggregateCsv(const std::vector<AggregateRow>& rows) {
  std::ostringstream out;
  out << "label,planner,samples,params,trials,scenes,covered_scenes,covered_trials,covered_successes,"
         "covered_vo_success_rate,chose_flyable,selection_accuracy,predicted_flyable,predicted_successes,"
         "predicted_success_rate\n";
  auto rate = [](int k, int n) { return n > 0 ? csvNumber(static_cast<double>(k) / n) : std::string(); };
  for (const AggregateRow& a : rows) {
    out << a.label << ',' << a.planner << ',' << a.samples << ',' << a.params << ',' << a.trials << ',';
    if (a.oracle) {
      out << ",,,,,,,";
    } else {
      out << a.scenes << ',' << a.covered_scenes << ',' << a.covered_trials << ',' << a.covered_successes << ','
          << rate(a.covered_successes, a.covered_trials) << ',' << a.chose_flyable << ','
          << rate(a.chose_flyable, a.covered_trials) << ',';
    }
    out << a.predicted_flyable << ',' << a.predicted_successes << ','
        << rate(a.predicted_successes, a.predicted_flyable) << '\n';
  }
  return out.str();
}

std::string generalisationMarkdown(const std::vector<SceneReport>& scenes, const std::vector<AggregateRow>& rows,
                                   bool per_scene) {
  std::ostringstream out;
  if (per_scene) out << "\n## Per scene\n\n" << oracleMarkdown(scenes) << "\n" << plannerMarkdown(scenes);
  int with_flyable = 0;
  for (const SceneReport& s : scenes) with_flyable += s.hasFlyable();
  std::vector<std::vector<std::string>> cells;
  for (const AggregateRow& a : rows) {
    const bool covered = !a.oracle && a.covered_trials > 0;
    cells.push_back({markdownCell(a.oracle ? "Oracle (all classes)" : a.label), std::to_string(a.trials),
                     a.oracle ? "–" : std::to_string(a.covered_scenes) + " of " + std::to_string(a.scenes),
                     covered ? formatShare(a.covered_successes, a.covered_trials) : "n/a",
                     covered ? formatShare(a.chose_flyable, a.covered_trials) : "n/a",
                     formatShare(a.predicted_successes, a.predicted_flyable)});
  }
  out << "\n## Aggregate\n\n"
      << markdownTable({"Planner", "Trials", "Scenes with a flyable class", "VO success there", "Selection accuracy",
                        "Predicted flyable: VO success"},
                       {false, true, true, true, true, true}, cells)
      << "\n"
      << with_flyable << " of " << scenes.size()
      << " scene(s) have a flyable class (from oracle trials). VO success there and selection accuracy (the share "
         "of a planner's trials whose chosen class is flyable) count its trials in those scenes only; n/a without "
         "them. Predicted flyable: over all its trials whose chosen class had c_p_min >= c_p_threshold (plan.json), "
         "the share whose VO tracked to the goal.\n";
  return out.str();
}

}  // namespace tgnav::harness
