#include "harness/experiments/sweep.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <set>
#include <sstream>
#include <utility>

#include "harness/base/errors.h"
#include "harness/base/files.h"
#include "harness/base/shell.h"
#include "harness/config/scenario.h"
#include "harness/config/yaml_util.h"
#include "harness/experiments/sweep_planners.h"
#include "harness/experiments/sweep_scenes.h"
#include "harness/run/plan_run.h"

namespace tgnav::harness {

namespace fs = std::filesystem;

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
  const std::string& key = key_node.Scalar();
  if (key == "seed") doc.fail(key_node, context + ": key 'seed': give seeds with the sweep's 'seeds'");
  if (key.empty() || key.find('=') != std::string::npos || key.find(' ') != std::string::npos) {
    doc.fail(key_node, context + ": '" + key + "' is not a dotted config key");
  }
}

// A value as `--set` takes it; a file (a `vehicle`, a `planner.information.track_model` other than
// none) made absolute from the sweep file's folder, as the runs' scenarios are, so that it means
// the same wherever the trials run.
std::string settingValue(const YamlDoc& doc, const std::string& key, const YAML::Node& value) {
  std::string text = valueText(value);
  const bool file = key == "vehicle" || (key == "planner.information.track_model" && text != "none");
  if (!file) return text;
  const fs::path p = fs::absolute(doc.file().parent_path() / text).lexically_normal();
  if (!isRegularFile(p)) doc.fail(value, key + ": file " + p.string() + " not found");
  return p.string();
}

void readAssignments(const YamlDoc& doc, const YAML::Node& map, const std::string& context, Assignments* out) {
  if (const YAML::Node set = map["set"]) {
    if (!set.IsMap()) doc.fail(set, joinKey(context, "set") + ": expected a mapping of config keys to values");
    for (const auto& kv : set) {
      checkSettingKey(doc, kv.first, joinKey(context, "set"));
      if (kv.second.IsNull()) doc.fail(kv.first, joinKey(context, "set." + kv.first.Scalar()) + ": no value");
      out->fixed.emplace_back(kv.first.Scalar(), settingValue(doc, kv.first.Scalar(), kv.second));
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
      for (const YAML::Node& v : kv.second) values.push_back(settingValue(doc, key, v));
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

}  // namespace

std::string paramsLabel(const std::string& params) {
  std::string out;
  std::stringstream in(params);
  std::string item;
  while (std::getline(in, item, ';')) {
    if (item.rfind("vehicle=", 0) == 0) item = "vehicle=" + fs::path(item.substr(8)).stem().string();
    out += (out.empty() ? "" : ";") + item;
  }
  return out;
}

namespace {

std::string trialId(const SweepTrial& t, std::size_t seed_width) {
  std::string id = fs::path(t.scenario).stem().string() + "__" + t.planner;
  if (t.planner == "rrtstar") id += "-" + std::to_string(t.samples);
  std::stringstream params(paramsLabel(t.params));
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
  assignments.reserve(set.size());
  for (const auto& [key, value] : set) assignments.push_back(key + "=" + value);
  try {
    const YamlDoc overrides = YamlDoc::fromOverrides(assignments);
    const Scenario s = loadScenario(scenario, &overrides);
    return Checked{s.scene.source.stem().string(), s.planner.rrt_star.samples};
  } catch (const InputError& e) {
    doc.fail(where, context + ": " + e.what());
  }
}

// A run of the sweep file as read: what it expands into, before the configurations are checked.
struct Run {
  std::string context;  // "runs[2]"
  std::vector<fs::path> scenarios;
  std::vector<SweepPlanner> planners;
  std::vector<int> samples{0};  // 0: the configured budget (and not rrtstar)
  std::vector<std::uint64_t> seeds;
  Assignments own;
};

std::vector<fs::path> readScenarios(const YamlDoc& doc, const YAML::Node& run, const std::string& context,
                                    const fs::path& source) {
  std::vector<fs::path> scenarios;
  for (const YAML::Node& s : oneOrList(doc, run, "scenario", context)) {
    const fs::path p = fs::absolute(source.parent_path() / s.Scalar()).lexically_normal();
    if (!isRegularFile(p)) {
      doc.fail(s, joinKey(context, "scenario") + ": '" + s.Scalar() + "': file " + p.string() + " not found");
    }
    scenarios.push_back(p);
  }
  return scenarios;
}

std::vector<int> readSamples(const YamlDoc& doc, const YAML::Node& run, const std::string& context,
                             const std::vector<SweepPlanner>& planners) {
  if (!run["samples"]) return {0};
  if (std::any_of(planners.begin(), planners.end(), [](const SweepPlanner& p) { return p.name != "rrtstar"; })) {
    doc.fail(run["samples"], joinKey(context, "samples") + ": only the rrtstar planner takes a sample budget");
  }
  std::vector<int> samples;
  for (const YAML::Node& n : oneOrList(doc, run, "samples", context)) {
    samples.push_back(static_cast<int>(integer(doc, n, joinKey(context, "samples"), 1)));
  }
  return samples;
}

// runs[r]; `seeds` are the sweep's, for a run that gives none.
Run readRun(const YamlDoc& doc, const YAML::Node& run, std::size_t r, const fs::path& source,
            const std::vector<std::uint64_t>& seeds, GeneratedScenes* scenes) {
  Run out;
  out.context = "runs[" + std::to_string(r) + "]";
  const std::string& context = out.context;
  if (!run.IsMap()) doc.fail(run, context + ": expected a mapping (scenario, planner, ...)");
  doc.requireKeys(run, {"scenario", "generated", "planner", "samples", "seeds", "set", "axes"}, context);
  if (!run["planner"]) doc.fail(run, context + ": key 'planner' is missing");
  if (static_cast<bool>(run["scenario"]) == static_cast<bool>(run["generated"])) {
    doc.fail(run, context + ": give either 'scenario' (files) or 'generated' (generated scenes)");
  }
  out.scenarios =
      run["scenario"] ? readScenarios(doc, run, context, source) : readGeneratedScenes(doc, run, context, scenes);
  out.planners = readSweepPlanners(doc, run, context, source);
  out.samples = readSamples(doc, run, context, out.planners);
  out.seeds = run["seeds"] ? readSeeds(doc, run["seeds"], joinKey(context, "seeds")) : seeds;
  if (out.seeds.empty()) doc.fail(run, context + ": no seeds (give 'seeds' in the sweep or the run)");
  readAssignments(doc, run, context, &out.own);
  return out;
}

using Settings = std::vector<std::pair<std::string, std::string>>;

// The cartesian product of the axes' values, first axis slowest.
std::vector<Settings> axisCombinations(const std::vector<std::pair<std::string, std::vector<std::string>>>& axes) {
  std::vector<Settings> combos{{}};
  for (const auto& [key, values] : axes) {
    std::vector<Settings> next;
    for (const Settings& combo : combos) {
      for (const std::string& v : values) {
        next.push_back(combo);
        next.back().emplace_back(key, v);
      }
    }
    combos = std::move(next);
  }
  return combos;
}

// A trial's settings: the sweep's `set`, then the run's (`own`, then `combo`), which are also its params.
void assign(SweepTrial* t, const Settings& common, const Settings& own, const Settings& combo) {
  t->set = common;
  std::string params;
  for (const Settings* part : {&own, &combo}) {
    for (const auto& kv : *part) {
      t->set.push_back(kv);
      params += (params.empty() ? "" : ";") + kv.first + "=" + kv.second;
    }
  }
  t->params = params;
}

// checkConfig() of the trial's scenario and settings, once for each (`cache`).
const Checked& checkOnce(const YamlDoc& doc, const YAML::Node& node, const std::string& context, const SweepTrial& t,
                         std::map<std::string, Checked>* cache) {
  std::string key = t.scenario.string();
  for (const auto& kv : t.set) key += "\n" + kv.first + "=" + kv.second;
  auto it = cache->find(key);
  if (it == cache->end()) it = cache->emplace(key, checkConfig(doc, node, context, t.scenario, t.set)).first;
  return it->second;
}

// Expands one run into `sweep`'s trials (without ids), each configuration checked once
// (`checked`: by scenario and settings).
void expandRun(const YamlDoc& doc, const YAML::Node& node, const Run& run, const Settings& common,
               std::map<std::string, Checked>* checked, Sweep* sweep) {
  const std::vector<Settings> combos = axisCombinations(run.own.axes);
  for (const fs::path& scenario : run.scenarios) {
    for (const SweepPlanner& planner : run.planners) {
      for (int n : run.samples) {
        for (const Settings& combo : combos) {
          SweepTrial t;
          t.scenario = scenario;
          t.planner = planner.name;
          t.external_command = planner.external_command;
          t.external_dir = planner.external_dir;
          t.samples = n;
          assign(&t, common, run.own.fixed, combo);
          t.set.insert(t.set.end(), planner.set.begin(), planner.set.end());  // not params: not in the id
          const Checked& config = checkOnce(doc, node, run.context, t, checked);
          t.scene = config.scene;
          if (planner.name == "rrtstar" && t.samples == 0) t.samples = config.default_samples;
          for (std::uint64_t seed : run.seeds) {
            t.seed = seed;
            sweep->trials.push_back(t);
          }
        }
      }
    }
  }
}

// Names every trial (seeds zero-padded alike); InputError when two trials are the same.
void assignIds(const YamlDoc& doc, const YAML::Node& runs, std::vector<SweepTrial>* trials) {
  std::uint64_t max_seed = 0;
  for (const SweepTrial& t : *trials) max_seed = std::max(max_seed, t.seed);
  const std::size_t width = std::max<std::size_t>(2, std::to_string(max_seed).size());
  std::set<std::string> ids;
  for (SweepTrial& t : *trials) {
    t.id = trialId(t, width);
    if (!ids.insert(t.id).second) {
      doc.fail(runs,
               "runs: trial " + t.id + " is listed twice (the same scenario, planner, samples, settings and seed)");
    }
  }
}

}  // namespace

Sweep loadSweep(const fs::path& yaml, const fs::path& scenes_dir) {
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
  std::map<std::string, Checked> checked;  // by scenario and settings
  GeneratedScenes scenes{scenes_dir, {}};
  for (std::size_t r = 0; r < runs.size(); ++r) {
    const Run run = readRun(doc, runs[r], r, sweep.source, seeds, &scenes);
    expandRun(doc, runs[r], run, common.fixed, &checked, &sweep);
  }
  assignIds(doc, runs, &sweep.trials);
  return sweep;
}

std::vector<std::string> trialArguments(const SweepTrial& t, const fs::path& out) {
  std::vector<std::string> args{"trial", "--scenario", t.scenario.string()};
  if (t.external_command.empty()) {
    args.insert(args.end(), {"--planner", t.planner});
  } else {
    args.insert(args.end(), {"--planner-command", t.external_command, "--planner-name", t.planner, "--planner-dir",
                             t.external_dir.string()});
  }
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

}  // namespace tgnav::harness
