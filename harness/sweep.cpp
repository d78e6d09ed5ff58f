#include "harness/sweep.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "harness/errors.h"
#include "harness/plan_run.h"
#include "harness/report.h"
#include "harness/scenario.h"
#include "harness/shell.h"
#include "harness/yaml_util.h"

namespace tgnav::harness {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// A scalar as written, anything else as flow-style YAML ("[1, 2, 1, 0]").
std::string valueText(const YAML::Node& node) {
  if (node.IsScalar()) return node.Scalar();
  YAML::Emitter out;
  out.SetSeqFormat(YAML::Flow);
  out.SetMapFormat(YAML::Flow);
  out << node;
  return out.c_str();
}

// The elements of a key that takes one value or a non-empty list of them.
std::vector<YAML::Node> oneOrList(const YamlDoc& doc, const YAML::Node& map, const std::string& key,
                                  const std::string& context) {
  const YAML::Node node = map[key];
  std::vector<YAML::Node> items;
  if (node.IsSequence()) {
    if (node.size() == 0) doc.fail(node, joinKey(context, key) + ": empty list (an axis needs at least one value)");
    for (const YAML::Node& item : node) items.push_back(item);
  } else if (node.IsScalar()) {
    items.push_back(node);
  } else {
    doc.fail(node, joinKey(context, key) + ": expected a value or a list of values");
  }
  for (const YAML::Node& item : items) {
    if (!item.IsScalar() || item.Scalar().empty()) {
      doc.fail(item, joinKey(context, key) + ": expected a value, got '" + valueText(item) + "'");
    }
  }
  return items;
}

long long integer(const YamlDoc& doc, const YAML::Node& node, const std::string& key, long long min) {
  double v = 0.0;
  bool ok = node.IsScalar();
  try {
    if (ok) v = node.as<double>();
  } catch (const YAML::Exception&) {
    ok = false;
  }
  if (!ok || v != std::floor(v) || v < static_cast<double>(min) || v > 9.0e15) {
    doc.fail(node, key + ": '" + valueText(node) + "' is not an integer >= " + std::to_string(min));
  }
  return static_cast<long long>(v);
}

std::vector<std::uint64_t> readSeeds(const YamlDoc& doc, const YAML::Node& node, const std::string& key) {
  std::vector<std::uint64_t> seeds;
  if (node.IsScalar()) {  // a count: 1..N
    const long long n = integer(doc, node, key, 1);
    if (n > 100000) doc.fail(node, key + ": " + node.Scalar() + " seeds is too many (at most 100000)");
    for (long long s = 1; s <= n; ++s) seeds.push_back(static_cast<std::uint64_t>(s));
    return seeds;
  }
  if (!node.IsSequence() || node.size() == 0) {
    doc.fail(node, key + ": expected a count (1..N) or a non-empty list of seeds");
  }
  for (const YAML::Node& item : node) {
    const auto s = static_cast<std::uint64_t>(integer(doc, item, key, 0));
    if (std::find(seeds.begin(), seeds.end(), s) != seeds.end()) {
      doc.fail(item, key + ": seed " + item.Scalar() + " is listed twice");
    }
    seeds.push_back(s);
  }
  return seeds;
}

// `set:` (fixed values) or `axes:` (lists of values): dotted config keys, as `--set` takes them.
struct Assignments {
  std::vector<std::pair<std::string, std::string>> fixed;
  std::vector<std::pair<std::string, std::vector<std::string>>> axes;
};

void checkSettingKey(const YamlDoc& doc, const YAML::Node& key_node, const std::string& context) {
  const std::string key = key_node.Scalar();
  if (key == "seed") doc.fail(key_node, context + ": key 'seed': give seeds with the sweep's 'seeds'");
  if (key.empty() || key.find('=') != std::string::npos || key.find(' ') != std::string::npos) {
    doc.fail(key_node, context + ": '" + key + "' is not a dotted config key");
  }
}

void readAssignments(const YamlDoc& doc, const YAML::Node& map, const std::string& context, Assignments* out) {
  if (const YAML::Node set = map["set"]) {
    if (!set.IsMap()) doc.fail(set, joinKey(context, "set") + ": expected a mapping of config keys to values");
    for (const auto& kv : set) {
      checkSettingKey(doc, kv.first, joinKey(context, "set"));
      if (kv.second.IsNull()) doc.fail(kv.first, joinKey(context, "set." + kv.first.Scalar()) + ": no value");
      out->fixed.emplace_back(kv.first.Scalar(), valueText(kv.second));
    }
  }
  if (const YAML::Node axes = map["axes"]) {
    if (!axes.IsMap()) doc.fail(axes, joinKey(context, "axes") + ": expected a mapping of config keys to lists");
    for (const auto& kv : axes) {
      const std::string key = kv.first.Scalar();
      checkSettingKey(doc, kv.first, joinKey(context, "axes"));
      if (!kv.second.IsSequence() || kv.second.size() == 0) {
        doc.fail(kv.first, joinKey(context, "axes." + key) + ": expected a non-empty list of values");
      }
      std::vector<std::string> values;
      for (const YAML::Node& v : kv.second) values.push_back(valueText(v));
      out->axes.emplace_back(key, values);
    }
  }
}

std::string sanitise(const std::string& text) {
  std::string out;
  for (char c : text) {
    const bool keep = std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '=' || c == '-';
    out += keep ? c : '_';
  }
  return out;
}

std::string trialId(const SweepTrial& t, std::size_t seed_width) {
  std::string id = fs::path(t.scenario).stem().string() + "__" + t.planner;
  if (t.planner == "rrtstar") id += "-" + std::to_string(t.samples);
  std::stringstream params(t.params);
  std::string item;
  while (std::getline(params, item, ';')) id += "__" + sanitise(item);
  std::string seed = std::to_string(t.seed);
  if (seed.size() < seed_width) seed.insert(0, seed_width - seed.size(), '0');
  return id + "__s" + seed;
}

// Loads the trial's configuration as `tgnav trial` will, so bad keys and values fail now.
struct Checked {
  std::string scene;
  int default_samples = 0;
};
Checked checkConfig(const YamlDoc& doc, const YAML::Node& where, const std::string& context, const fs::path& scenario,
                    const std::vector<std::pair<std::string, std::string>>& set) {
  std::vector<std::string> assignments;
  for (const auto& [key, value] : set) assignments.push_back(key + "=" + value);
  try {
    const YamlDoc overrides = YamlDoc::fromOverrides(assignments);
    const Scenario s = loadScenario(scenario, &overrides);
    return Checked{s.scene.source.stem().string(), s.planner.rrt_star.samples};
  } catch (const InputError& e) {
    doc.fail(where, context + ": " + e.what());
  }
}

}  // namespace

Sweep loadSweep(const fs::path& yaml) {
  const YamlDoc doc = YamlDoc::load(yaml);
  const YAML::Node& root = doc.root();
  if (!root.IsMap()) doc.fail(root, "a sweep file is a mapping with 'runs'");
  doc.requireKeys(root, {"seeds", "set", "runs"}, "");
  std::vector<std::uint64_t> seeds;
  if (root["seeds"]) seeds = readSeeds(doc, root["seeds"], "seeds");
  Assignments common;
  readAssignments(doc, root, "", &common);
  if (!common.axes.empty()) doc.fail(root, "axes belong to a run");
  const YAML::Node runs = root["runs"];
  if (!runs) doc.fail(root, "key 'runs' is missing: the list of runs (scenario, planner, ...)");
  if (!runs.IsSequence() || runs.size() == 0) doc.fail(runs, "runs: expected a non-empty list of runs");

  Sweep sweep;
  sweep.source = fs::absolute(yaml).lexically_normal();
  std::map<std::string, Checked> checked;    // by scenario and overrides
  std::map<std::string, std::string> where;  // trial id -> the run that made it
  std::uint64_t max_seed = 0;
  for (std::size_t r = 0; r < runs.size(); ++r) {
    const YAML::Node run = runs[r];
    const std::string context = "runs[" + std::to_string(r) + "]";
    if (!run.IsMap()) doc.fail(run, context + ": expected a mapping (scenario, planner, ...)");
    doc.requireKeys(run, {"scenario", "planner", "samples", "seeds", "set", "axes"}, context);
    for (const char* key : {"scenario", "planner"}) {
      if (!run[key]) doc.fail(run, context + ": key '" + key + "' is missing");
    }
    std::vector<fs::path> scenarios;
    for (const YAML::Node& s : oneOrList(doc, run, "scenario", context)) {
      const fs::path p = fs::absolute(sweep.source.parent_path() / s.Scalar()).lexically_normal();
      if (!fs::is_regular_file(p)) {
        doc.fail(s, joinKey(context, "scenario") + ": '" + s.Scalar() + "': file " + p.string() + " not found");
      }
      scenarios.push_back(p);
    }
    std::vector<std::string> planners;
    for (const YAML::Node& p : oneOrList(doc, run, "planner", context)) {
      try {
        planners.push_back(toString(parsePlannerName(p.Scalar(), joinKey(context, "planner"))));
      } catch (const InputError& e) {
        doc.fail(p, e.what());
      }
    }
    std::vector<int> samples{0};
    if (run["samples"]) {
      if (std::any_of(planners.begin(), planners.end(), [](const std::string& p) { return p != "rrtstar"; })) {
        doc.fail(run["samples"], joinKey(context, "samples") + ": only the rrtstar planner takes a sample budget");
      }
      samples.clear();
      for (const YAML::Node& n : oneOrList(doc, run, "samples", context)) {
        samples.push_back(static_cast<int>(integer(doc, n, joinKey(context, "samples"), 1)));
      }
    }
    const std::vector<std::uint64_t> run_seeds =
        run["seeds"] ? readSeeds(doc, run["seeds"], joinKey(context, "seeds")) : seeds;
    if (run_seeds.empty()) doc.fail(run, context + ": no seeds (give 'seeds' in the sweep or the run)");
    Assignments own;
    readAssignments(doc, run, context, &own);

    // The cartesian product of the axes' values, first axis slowest.
    std::vector<std::vector<std::pair<std::string, std::string>>> combos{{}};
    for (const auto& [key, values] : own.axes) {
      std::vector<std::vector<std::pair<std::string, std::string>>> next;
      for (const auto& combo : combos) {
        for (const std::string& v : values) {
          next.push_back(combo);
          next.back().emplace_back(key, v);
        }
      }
      combos = std::move(next);
    }
    for (const fs::path& scenario : scenarios) {
      for (const std::string& planner : planners) {
        for (int n : samples) {
          for (const auto& combo : combos) {
            SweepTrial t;
            t.scenario = scenario;
            t.planner = planner;
            t.samples = n;
            t.set = common.fixed;
            std::string params;
            for (const auto& kv : own.fixed) {
              t.set.push_back(kv);
              params += (params.empty() ? "" : ";") + kv.first + "=" + kv.second;
            }
            for (const auto& kv : combo) {
              t.set.push_back(kv);
              params += (params.empty() ? "" : ";") + kv.first + "=" + kv.second;
            }
            t.params = params;
            std::string key = scenario.string();
            for (const auto& kv : t.set) key += "\n" + kv.first + "=" + kv.second;
            auto it = checked.find(key);
            if (it == checked.end()) {
              it = checked.emplace(key, checkConfig(doc, run, context, scenario, t.set)).first;
            }
            t.scene = it->second.scene;
            if (planner == "rrtstar" && t.samples == 0) t.samples = it->second.default_samples;
            for (std::uint64_t seed : run_seeds) {
              t.seed = seed;
              max_seed = std::max(max_seed, seed);
              sweep.trials.push_back(t);
            }
          }
        }
      }
    }
  }
  const std::size_t width = std::max<std::size_t>(2, std::to_string(max_seed).size());
  for (std::size_t i = 0; i < sweep.trials.size(); ++i) {
    SweepTrial& t = sweep.trials[i];
    t.id = trialId(t, width);
    if (!where.emplace(t.id, "").second) {
      doc.fail(runs,
               "runs: trial " + t.id + " is listed twice (the same scenario, planner, samples, settings and seed)");
    }
  }
  return sweep;
}

std::vector<std::string> trialArguments(const SweepTrial& t, const fs::path& out) {
  std::vector<std::string> args{"trial", "--scenario", t.scenario.string(), "--planner", t.planner};
  if (t.planner == "rrtstar") {
    args.push_back("--samples");
    args.push_back(std::to_string(t.samples));
  }
  args.push_back("--seed");
  args.push_back(std::to_string(t.seed));
  for (const auto& [key, value] : t.set) {
    args.push_back("--set");
    args.push_back(key + "=" + value);
  }
  args.push_back("--out");
  args.push_back(out.string());
  return args;
}

namespace {
constexpr const char* kManifestHeader = "id,scenario,scene,planner,samples,seed,params";

// CSV fields here are plain: a comma (in a list value) is shown as a space.
std::string plain(std::string s) {
  std::replace(s.begin(), s.end(), ',', ' ');
  std::replace(s.begin(), s.end(), '\n', ' ');
  return s;
}

}  // namespace

std::string manifestCsv(const std::vector<SweepTrial>& trials) {
  std::ostringstream out;
  out << kManifestHeader << '\n';
  for (const SweepTrial& t : trials) {
    out << t.id << ',' << plain(t.scenario.string()) << ',' << t.scene << ',' << t.planner << ',' << t.samples << ','
        << t.seed << ',' << plain(t.params) << '\n';
  }
  return out.str();
}

std::vector<SweepTrial> parseManifest(const std::string& text, const std::string& file) {
  std::istringstream in(text);
  std::string line;
  if (!std::getline(in, line) || line != kManifestHeader) {
    throw InputError(file + ":1: not a sweep manifest (expected the header '" + kManifestHeader + "')");
  }
  std::vector<SweepTrial> trials;
  for (int n = 2; std::getline(in, line); ++n) {
    std::vector<std::string> f(1);
    for (char c : line) {
      if (c == ',') {
        f.emplace_back();
      } else {
        f.back() += c;
      }
    }
    const std::string at = file + ":" + std::to_string(n) + ": ";
    if (f.size() != 7) throw InputError(at + "expected 7 fields, found " + std::to_string(f.size()));
    SweepTrial t;
    t.id = f[0];
    t.scenario = f[1];
    t.scene = f[2];
    t.planner = f[3];
    try {
      std::size_t used = 0;
      t.samples = std::stoi(f[4], &used);
      if (used != f[4].size()) throw std::invalid_argument("samples");
      t.seed = std::stoull(f[5], &used);
      if (used != f[5].size() || f[5][0] == '-') throw std::invalid_argument("seed");
    } catch (const std::exception&) {
      throw InputError(at + "samples '" + f[4] + "' or seed '" + f[5] + "' is not an integer >= 0");
    }
    if (t.id.empty() || t.id.find('/') != std::string::npos || t.id[0] == '.') {
      throw InputError(at + "id '" + t.id + "' is not a trial id");
    }
    t.params = f[6];
    trials.push_back(std::move(t));
  }
  return trials;
}

std::string commandsText(const std::vector<SweepTrial>& trials) {
  std::ostringstream out;
  for (const SweepTrial& t : trials) {
    out << t.id;
    for (const std::string& arg : trialArguments(t, fs::path("trials") / t.id)) out << ' ' << shellWord(arg);
    out << '\n';
  }
  return out.str();
}

namespace {
// The metrics index.csv takes (besides the trial's own fields), with whether they may be null.
struct IndexColumn {
  const char* key;
  bool nullable;
};
constexpr IndexColumn kIndexMetrics[] = {{"status", false},
                                         {"path_length_m", false},
                                         {"planned_length_m", false},
                                         {"goal_error_m", true},
                                         {"final_distance_to_goal_m", false},
                                         {"ate_rmse_m", false},
                                         {"plan_time_s", false},
                                         {"wall_time_s", false},
                                         {"sim_time_s", false},
                                         {"vo_lost_at_s", true},
                                         {"distance_tracked_m", false}};

bool isStatusName(const std::string& s) {
  const std::vector<std::string>& names = trialStatusNames();
  return std::find(names.begin(), names.end(), s) != names.end();
}

std::string readAll(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}
}  // namespace

const char* const kIndexHeader =
    "id,scene,planner,samples,seed,params,status,path_length_m,planned_length_m,goal_error_m,"
    "final_distance_to_goal_m,ate_rmse_m,plan_time_s,wall_time_s,sim_time_s,vo_lost_at_s,distance_tracked_m,folder";

TrialFolder inspectTrialFolder(const SweepTrial& trial, const fs::path& folder) {
  TrialFolder f;
  std::error_code ec;
  if (!fs::exists(folder, ec)) return f;
  if (!fs::is_directory(folder, ec)) {
    f.state = TrialState::kCorrupt;
    f.problem = "is not a folder";
    return f;
  }
  const fs::path metrics = folder / "metrics.json";
  if (!fs::exists(metrics, ec)) {
    f.state = TrialState::kIncomplete;
    f.problem = fs::exists(folder / "INCOMPLETE", ec) ? "interrupted (INCOMPLETE)" : "no metrics.json";
    return f;
  }
  f.state = TrialState::kCorrupt;
  json j;
  try {
    j = json::parse(readAll(metrics));
  } catch (const json::exception& e) {
    f.problem = "metrics.json does not parse (" + std::string(e.what()) + ")";
    return f;
  }
  if (!j.is_object()) {
    f.problem = "metrics.json is not an object";
    return f;
  }
  for (const IndexColumn& c : kIndexMetrics) {
    if (!j.contains(c.key)) {
      f.problem = std::string("metrics.json has no '") + c.key + "'";
      return f;
    }
    const json& v = j[c.key];
    const bool ok = std::string(c.key) == "status" ? v.is_string() && isStatusName(v.get<std::string>())
                                                   : v.is_number() || (c.nullable && v.is_null());
    if (!ok) {
      f.problem = std::string("metrics.json: '") + c.key + "' is " + v.dump();
      return f;
    }
  }
  const auto str = [&](const char* key) {
    return j.contains(key) && j[key].is_string() ? j[key].get<std::string>() : "";
  };
  const int samples = j.contains("samples") && j["samples"].is_number_integer() ? j["samples"].get<int>() : 0;
  const bool same = str("scene") == trial.scene && str("planner") == trial.planner &&
                    (trial.planner != "rrtstar" || samples == trial.samples) && j.contains("seed") &&
                    j["seed"].is_number_unsigned() && j["seed"].get<std::uint64_t>() == trial.seed;
  if (!same) {
    f.problem = "metrics.json is of another trial (" + str("scene") + " " + str("planner") + " seed " +
                (j.contains("seed") ? j["seed"].dump() : "?") + ")";
    return f;
  }
  f.state = TrialState::kDone;
  f.metrics = std::move(j);
  return f;
}

std::string indexCsv(const std::vector<SweepTrial>& trials, const std::vector<TrialFolder>& folders) {
  std::ostringstream out;
  out << kIndexHeader << '\n';
  for (std::size_t i = 0; i < trials.size() && i < folders.size(); ++i) {
    if (folders[i].state != TrialState::kDone) continue;
    const SweepTrial& t = trials[i];
    const json& m = folders[i].metrics;
    out << t.id << ',' << t.scene << ',' << t.planner << ',' << t.samples << ',' << t.seed << ',';
    for (char c : t.params) out << (c == ',' ? ' ' : c);  // a list value: the index is plain CSV
    for (const IndexColumn& c : kIndexMetrics) {
      const json& v = m[c.key];
      out << ',';
      if (v.is_string()) {
        out << v.get<std::string>();
      } else if (!v.is_null()) {
        out << v.dump();
      }
    }
    out << ",trials/" << t.id << '\n';
  }
  return out.str();
}

}  // namespace tgnav::harness
