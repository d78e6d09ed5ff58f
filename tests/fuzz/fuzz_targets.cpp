#include "tests/fuzz/fuzz_targets.h"

#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <functional>
#include <regex>
#include <sstream>
#include <stdexcept>

#include "harness/base/errors.h"
#include "harness/config/scenario.h"
#include "harness/config/scene_config.h"
#include "harness/config/track_model_file.h"
#include "harness/config/vehicle_config.h"
#include "harness/config/yaml_util.h"
#include "harness/experiments/sweep.h"
#include "harness/io/grid_io.h"
#include "harness/io/movingai_scen.h"
#include "harness/io/planner_protocol.h"
#include "harness/io/trajectory_csv.h"
#include "harness/io/tum_sequence.h"
#include "harness/sim/vehicle_model.h"
#include "vo/trajectory_formats.h"
#include "vo/tum.h"

namespace tgnav::fuzz {

namespace fs = std::filesystem;

namespace {

// The process's scratch folder, removed at exit. Each input starts from an empty run/ inside it.
class Scratch {
 public:
  Scratch() : root_(fs::temp_directory_path() / ("tgnav-fuzz-" + std::to_string(::getpid()))) {}
  ~Scratch() {
    std::error_code ec;
    fs::remove_all(root_, ec);
  }
  Scratch(const Scratch&) = delete;
  Scratch& operator=(const Scratch&) = delete;
  Scratch(Scratch&&) = delete;
  Scratch& operator=(Scratch&&) = delete;

  // A fresh, empty run folder.
  fs::path fresh() const {
    const fs::path run = root_ / "run";
    fs::remove_all(run);
    fs::create_directories(run);
    return run;
  }

 private:
  fs::path root_;
};

const Scratch& scratch() {
  static const Scratch s;
  return s;
}

void write(const fs::path& file, const std::string& text) {
  fs::create_directories(file.parent_path());
  std::ofstream out(file, std::ios::binary);
  out << text;
  if (!out) throw std::runtime_error("fuzz: cannot write " + file.string());
}

// Writes section i of `parts` to `file` when the input has it (a missing section: no file).
void writeSection(const std::vector<std::string>& parts, std::size_t i, const fs::path& file) {
  if (i < parts.size()) write(file, parts[i]);
}

// The MJCF a scene names: its content is MuJoCo's to parse (not fuzzed here); it must exist. It
// includes the vehicle vehicle.xml, described by vehicle.yaml beside it, as the shipped scenes do.
constexpr const char* kMjcf = "fuzz.xml";
constexpr const char* kVehicleYaml =
    "mjcf: vehicle.xml\nbody: b\nrotors: [m0, m1, m2, m3]\ngyro: g\naccelerometer: a\ncamera: c\n";

// Scratch layout of the configuration targets: run/fuzz.xml, run/vehicle.{xml,yaml},
// run/scenes/fuzz.yaml, run/scenarios/fuzz.yaml, run/sweeps/fuzz.yaml.
fs::path configLayout(const std::vector<std::string>& parts, const std::vector<std::string>& order) {
  const fs::path run = scratch().fresh();
  write(run / kMjcf, "<mujoco>\n  <include file=\"vehicle.xml\"/>\n</mujoco>\n");
  write(run / "vehicle.xml", "<mujoco/>\n");
  write(run / "vehicle.yaml", kVehicleYaml);
  for (std::size_t i = 0; i < order.size(); ++i) writeSection(parts, i, run / order[i] / "fuzz.yaml");
  return run;
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

using Body = std::function<void(const std::string&)>;

// The rejection message of the current input (run() hands it out).
std::string& lastError() {
  static std::string message;
  return message;
}

// A target whose parser documents InputError for bad input.
Outcome harnessParser(const Body& body, const std::string& input) {
  try {
    body(input);
    return Outcome::kAccepted;
  } catch (const InputError& e) {
    lastError() = e.what();
    return Outcome::kRejected;
  }
}

// A pure library's text parser, documented to throw std::invalid_argument.
Outcome textParser(const Body& body, const std::string& input) {
  try {
    body(input);
    return Outcome::kAccepted;
  } catch (const std::invalid_argument& e) {
    lastError() = e.what();
    return Outcome::kRejected;
  }
}

// The external planner protocol's response parser, documented to throw ProtocolError.
Outcome protocolParser(const Body& body, const std::string& input) {
  try {
    body(input);
    return Outcome::kAccepted;
  } catch (const harness::ProtocolError& e) {
    lastError() = e.what();
    return Outcome::kRejected;
  }
}

struct Entry {
  Target target;
  Outcome (*contract)(const Body&, const std::string&);  // harnessParser or textParser
  Body parse;                                            // writes the input where it goes and parses it
};

const std::vector<Entry>& entries() {
  static const std::vector<Entry> all = {
      {{"tum", "a TUM trajectory (vo::parseTum)"}, textParser, [](const std::string& t) { vo::parseTum(t); }},
      {{"kitti", "a KITTI trajectory (vo::parseKitti)"}, textParser, [](const std::string& t) { vo::parseKitti(t); }},
      {{"euroc", "a EuRoC trajectory (vo::parseEuroc)"}, textParser, [](const std::string& t) { vo::parseEuroc(t); }},
      {{"trajectory_csv", "a setpoint trajectory CSV (tgnav fly --trajectory)"},
       harnessParser,
       [](const std::string& t) {
         const fs::path file = scratch().fresh() / "trajectory.csv";
         write(file, t);
         harness::readTrajectoryCsv(file);
       }},
      {{"path_csv", "a 4-DoF path CSV (tgnav trial --path)"},
       harnessParser,
       [](const std::string& t) {
         const fs::path file = scratch().fresh() / "path.csv";
         write(file, t);
         harness::readPathCsv(file);
       }},
      {{"planner_response", "an external planner's response line to request 1 (docs/PLANNER_PROTOCOL.md)"},
       protocolParser,
       [](const std::string& t) { harness::parsePlanResponse(t, 1); }},
      {{"movingai_map", "a MovingAI .map"},
       harnessParser,
       [](const std::string& t) {
         const fs::path file = scratch().fresh() / "grid.map";
         write(file, t);
         harness::loadMovingAiMap(file, 0.5);
       }},
      {{"movingai_scen", "a MovingAI .scen, checked against a 64x64 map"},
       harnessParser,
       [](const std::string& t) {
         const fs::path file = scratch().fresh() / "grid.map.scen";
         write(file, t);
         const auto rows = harness::loadMovingAiScen(file);
         harness::checkScenAgainstMap(file, rows, 64, 64);
       }},
      {{"ros_map", "sections: map_server YAML, then the PGM it may name as map.pgm"},
       harnessParser,
       [](const std::string& t) {
         const auto parts = sections(t, 2);
         const fs::path run = scratch().fresh();
         writeSection(parts, 0, run / "map.yaml");
         writeSection(parts, 1, run / "map.pgm");
         harness::loadRosMap(run / "map.yaml");
       }},
      {{"tum_rgbd", "sections: rgb.txt, depth.txt, groundtruth.txt, intrinsics.yaml (images rgb|depth/0..2.png exist)"},
       harnessParser,
       [](const std::string& t) {
         const auto parts = sections(t, 4);
         const fs::path seq = scratch().fresh() / "seq";
         for (const char* sub : {"rgb", "depth"}) {
           for (int i = 0; i < 3; ++i) write(seq / sub / (std::to_string(i) + ".png"), "");
         }
         writeSection(parts, 0, seq / "rgb.txt");
         writeSection(parts, 1, seq / "depth.txt");
         writeSection(parts, 2, seq / "groundtruth.txt");
         writeSection(parts, 3, seq / "intrinsics.yaml");
         harness::loadSequence(seq);
       }},
      {{"intrinsics", "a TUM RGB-D sequence's intrinsics.yaml (with valid image lists)"},
       harnessParser,
       [](const std::string& t) {
         const fs::path seq = scratch().fresh() / "seq";
         write(seq / "rgb" / "0.png", "");
         write(seq / "depth" / "0.png", "");
         write(seq / "rgb.txt", "# rgb\n0.000000 rgb/0.png\n");
         write(seq / "depth.txt", "# depth\n0.000000 depth/0.png\n");
         write(seq / "intrinsics.yaml", t);
         harness::loadSequence(seq);
       }},
      {{"scene", "a scene YAML (its mjcf may name ../fuzz.xml)"},
       harnessParser,
       [](const std::string& t) {
         const fs::path run = configLayout({t}, {"scenes"});
         harness::loadSceneConfig(run / "scenes" / "fuzz.yaml");
       }},
      {{"scenario", "sections: scenario YAML, scene YAML (../scenes/fuzz.yaml), --set assignments one per line"},
       harnessParser,
       [](const std::string& t) {
         const auto parts = sections(t, 3);
         const fs::path run = configLayout(parts, {"scenarios", "scenes"});
         if (parts.size() > 2) {
           const harness::YamlDoc overrides = harness::YamlDoc::fromOverrides(lines(parts[2]));
           harness::loadScenario(run / "scenarios" / "fuzz.yaml", &overrides);
         } else {
           harness::loadScenario(run / "scenarios" / "fuzz.yaml");
         }
       }},
      {{"vehicle", "sections: vehicle description (mjcf may name ../fuzz.xml), scene MJCF scanned for its vehicle"},
       harnessParser,
       [](const std::string& t) {
         const auto parts = sections(t, 2);
         const fs::path run = configLayout({}, {});
         if (!parts[0].empty() || parts.size() == 1) {
           write(run / "vehicles" / "fuzz.yaml", parts[0]);
           harness::loadVehicleDescription(run / "vehicles" / "fuzz.yaml");
         }
         if (parts.size() > 1) {
           write(run / "scene.xml", parts[1]);
           if (!harness::includedVehicle(run / "scene.xml").empty()) {
             harness::composeVehicleScene(run / "scene.xml", harness::loadVehicleDescription(run / "vehicle.yaml"));
           }
         }
       }},
      {{"track_model", "a learned perception model's JSON (planner.information.track_model)"},
       harnessParser,
       [](const std::string& t) {
         const fs::path file = scratch().fresh() / "model.json";
         write(file, t);
         harness::loadTrackModel(file);
       }},
      {{"sweep", "sections: sweep YAML, scenario YAML (../scenarios/fuzz.yaml), scene YAML"},
       harnessParser,
       [](const std::string& t) {
         const fs::path run = configLayout(sections(t, 3), {"sweeps", "scenarios", "scenes"});
         harness::loadSweep(run / "sweeps" / "fuzz.yaml", run / "generated");
       }},
  };
  return all;
}

std::string readText(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<fs::path> yamlFiles(const fs::path& dir) {
  std::vector<fs::path> files;
  if (!fs::is_directory(dir)) return files;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().extension() == ".yaml") files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::string join(const std::vector<std::string>& parts) {
  std::string out;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (i > 0) out += std::string(kSectionMark) + "\n";
    out += parts[i];
    if (!out.empty() && out.back() != '\n') out += '\n';
  }
  return out;
}

// `text` with every line starting with `key:` replaced by `key: value`.
std::string replaceKey(const std::string& text, const std::string& key, const std::string& value) {
  std::string out;
  for (const std::string& line : lines(text)) {
    out += line.rfind(key + ":", 0) == 0 ? key + ": " + value : line;
    out += '\n';
  }
  return out;
}

// A scene file pointed at the scratch MJCF.
std::string sceneSeed(const fs::path& scene) { return replaceKey(readText(scene), "mjcf", std::string("../") + kMjcf); }

// A scenario's `*_config: FILE` keys made absolute (they name files of the repository), its scene
// pointed at the scratch scene.
std::string scenarioSeed(const fs::path& scenario) {
  const std::regex config_key(R"(^(\w+_config):\s*(\S+)\s*$)");
  std::string out;
  for (const std::string& line : lines(replaceKey(readText(scenario), "scene", "../scenes/fuzz.yaml"))) {
    std::smatch m;
    if (std::regex_match(line, m, config_key)) {
      out += m[1].str() + ": " + (scenario.parent_path() / m[2].str()).lexically_normal().string() + "\n";
    } else {
      out += line + "\n";
    }
  }
  return out;
}

// The scene file a scenario names, if it names one that exists.
fs::path sceneOf(const fs::path& scenario) {
  std::smatch m;
  const std::string text = readText(scenario);
  if (!std::regex_search(text, m, std::regex(R"((^|\n)scene:\s*(\S+))"))) return {};
  const fs::path scene = (scenario.parent_path() / m[2].str()).lexically_normal();
  return fs::is_regular_file(scene) ? scene : fs::path();
}

}  // namespace

const std::vector<Target>& targets() {
  static const std::vector<Target> all = [] {
    std::vector<Target> t;
    for (const Entry& e : entries()) t.push_back(e.target);
    return t;
  }();
  return all;
}

Outcome run(const std::string& name, const std::uint8_t* data, std::size_t size, std::string* why) {
  for (const Entry& e : entries()) {
    if (e.target.name != name) continue;
    lastError().clear();
    const Outcome outcome = e.contract(e.parse, std::string(reinterpret_cast<const char*>(data), size));
    if (why != nullptr) *why = lastError();
    return outcome;
  }
  throw std::out_of_range("no fuzz target '" + name + "'");
}

std::vector<std::string> sections(const std::string& input, std::size_t count) {
  std::vector<std::string> parts(1);
  std::size_t pos = 0;
  while (pos <= input.size()) {
    const std::size_t end = input.find('\n', pos);
    const std::string line = input.substr(pos, end == std::string::npos ? std::string::npos : end - pos);
    const bool last_line = end == std::string::npos;
    if (line == kSectionMark && parts.size() < count) {
      parts.emplace_back();
    } else {
      parts.back() += line;
      if (!last_line) parts.back() += '\n';
    }
    if (last_line) break;
    pos = end + 1;
  }
  return parts;
}

std::vector<std::string> repositorySeeds(const std::string& name, const fs::path& source_dir) {
  const fs::path configs = source_dir / "configs";
  std::vector<std::string> seeds;
  if (name == "scene") {
    for (const fs::path& f : yamlFiles(configs / "scenes")) seeds.push_back(sceneSeed(f));
  } else if (name == "scenario" || name == "sweep") {
    // Each scenario once with its scene; under each sweep file (without generated scenes: each
    // input would write scenes), the first scenario's sections.
    for (const fs::path& f : yamlFiles(configs / "scenarios")) {
      const fs::path scene = sceneOf(f);
      if (scene.empty()) continue;
      if (name == "scenario") {
        seeds.push_back(join({scenarioSeed(f), sceneSeed(scene)}));
        seeds.push_back(join({scenarioSeed(f), sceneSeed(scene), "camera.width_px=320\nvo.min_inliers=25\n"}));
        continue;
      }
      for (const fs::path& s : yamlFiles(configs / "sweeps")) {
        const std::string sweep = readText(s);
        if (sweep.find("generated:") != std::string::npos) continue;  // each input would write scenes
        // The sweep's scenarios are the repository's (absolute paths: a sweep may list several);
        // the scratch scenario and scene sections are there for the fuzzer to point it at.
        // (and its files of the repository, e.g. vehicles, by absolute path too).
        const std::string pointed = std::regex_replace(
            std::regex_replace(sweep, std::regex(R"(\.\./scenarios/)"), (configs / "scenarios").string() + "/"),
            std::regex(R"(\.\./\.\./)"), source_dir.string() + "/");
        seeds.push_back(join({pointed, scenarioSeed(f), sceneSeed(scene)}));
      }
      break;  // one scenario suffices under every sweep file
    }
  } else if (name == "vehicle") {
    // The repository's vehicle descriptions pointed at the scratch MJCF (their gains files by
    // absolute path), each with a shipped scene whose vehicle include names the scratch vehicle.
    std::vector<fs::path> descriptions = {source_dir / "models" / "quadrotor.yaml",
                                          source_dir / "tests" / "data" / "x2_like" / "x2_like.yaml"};
    for (const fs::path& f : yamlFiles(source_dir / "models" / "vehicles")) {
      if (fs::is_regular_file(fs::path(f).replace_extension(".xml"))) descriptions.push_back(f);  // not a gains file
    }
    const std::vector<fs::path> scenes = {source_dir / "models" / "scenes" / "smoke.xml",
                                          source_dir / "models" / "scenes" / "storage.xml"};
    for (std::size_t i = 0; i < descriptions.size(); ++i) {
      std::string d = replaceKey(readText(descriptions[i]), "mjcf", std::string("../") + kMjcf);
      const std::regex gains(R"((^|\n)controller_config:\s*(\S+))");
      std::smatch m;
      if (std::regex_search(d, m, gains)) {
        d = replaceKey(d, "controller_config",
                       (descriptions[i].parent_path() / m[2].str()).lexically_normal().string());
      }
      const std::string scene =
          std::regex_replace(readText(scenes[i % scenes.size()]), std::regex(R"(\.\./quadrotor\.xml)"), "vehicle.xml");
      seeds.push_back(join({d, scene}));
    }
  } else if (name == "track_model") {
    for (const auto& e : fs::directory_iterator(configs)) {
      if (e.path().extension() == ".json") seeds.push_back(readText(e.path()));
    }
    std::sort(seeds.begin(), seeds.end());
  } else if (name == "trajectory_csv") {
    for (const auto& e : fs::directory_iterator(configs / "trajectories")) {
      if (e.path().extension() == ".csv") seeds.push_back(readText(e.path()));
    }
    std::sort(seeds.begin(), seeds.end());
  }
  return seeds;
}

}  // namespace tgnav::fuzz
