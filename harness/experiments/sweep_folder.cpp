#include "harness/experiments/sweep_folder.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <thread>

#include "harness/base/errors.h"
#include "harness/base/files.h"
#include "harness/experiments/report.h"
#include "harness/io/staged_output.h"

namespace tgnav::harness {

namespace fs = std::filesystem;
using nlohmann::json;

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

// Why metrics.json `j` cannot go into the index ("" when it can).
std::string metricsProblem(const json& j) {
  if (!j.is_object()) return "metrics.json is not an object";
  for (const IndexColumn& c : kIndexMetrics) {
    if (!j.contains(c.key)) return std::string("metrics.json has no '") + c.key + "'";
    const json& v = j[c.key];
    const bool ok = std::string(c.key) == "status" ? v.is_string() && isStatusName(v.get<std::string>())
                                                   : v.is_number() || (c.nullable && v.is_null());
    if (!ok) return std::string("metrics.json: '") + c.key + "' is " + v.dump();
  }
  return "";
}

// Why metrics.json `j` is not `trial`'s ("" when it is).
std::string otherTrialProblem(const json& j, const SweepTrial& trial) {
  const auto str = [&](const char* key) {
    return j.contains(key) && j[key].is_string() ? j[key].get<std::string>() : "";
  };
  const int samples = j.contains("samples") && j["samples"].is_number_integer() ? j["samples"].get<int>() : 0;
  const bool same = str("scene") == trial.scene && str("planner") == trial.planner &&
                    (trial.planner != "rrtstar" || samples == trial.samples) && j.contains("seed") &&
                    j["seed"].is_number_unsigned() && j["seed"].get<std::uint64_t>() == trial.seed;
  if (same) return "";
  return "metrics.json is of another trial (" + str("scene") + " " + str("planner") + " seed " +
         (j.contains("seed") ? j["seed"].dump() : "?") + ")";
}

TrialFolder folderIn(TrialState state, std::string problem) {
  TrialFolder f;
  f.state = state;
  f.problem = std::move(problem);
  return f;
}

}  // namespace

const char* const kIndexHeader =
    "id,scene,planner,samples,seed,params,status,path_length_m,planned_length_m,goal_error_m,"
    "final_distance_to_goal_m,ate_rmse_m,plan_time_s,wall_time_s,sim_time_s,vo_lost_at_s,distance_tracked_m,folder";

TrialFolder inspectTrialFolder(const SweepTrial& trial, const fs::path& folder) {
  std::error_code ec;
  if (!fs::exists(folder, ec)) return TrialFolder{};
  if (!fs::is_directory(folder, ec)) return folderIn(TrialState::kCorrupt, "is not a folder");
  const fs::path metrics = folder / "metrics.json";
  if (!fs::exists(metrics, ec)) {
    return folderIn(TrialState::kIncomplete,
                    fs::exists(folder / "INCOMPLETE", ec) ? "interrupted (INCOMPLETE)" : "no metrics.json");
  }
  json j;
  try {
    j = json::parse(readTextFile(metrics));
  } catch (const InputError& e) {
    return folderIn(TrialState::kCorrupt, "metrics.json cannot be read");
  } catch (const json::exception& e) {
    return folderIn(TrialState::kCorrupt, "metrics.json does not parse (" + std::string(e.what()) + ")");
  }
  std::string problem = metricsProblem(j);
  if (problem.empty()) problem = otherTrialProblem(j, trial);
  if (!problem.empty()) return folderIn(TrialState::kCorrupt, problem);
  TrialFolder f = folderIn(TrialState::kDone, "");
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

bool isTrialStaging(const std::string& name) {
  return name.size() > 1 && name[0] == '.' && name.find(".tmp-") != std::string::npos;
}

bool isTrialLeftover(const std::string& name) {
  return isTrialStaging(name) || (name.size() > 1 && name[0] == '.' && name.find(".old-") != std::string::npos);
}

TrialCounts countTrials(const std::vector<TrialFolder>& folders) {
  TrialCounts c;
  for (const TrialFolder& f : folders) {
    switch (f.state) {
      case TrialState::kDone:
        ++c.done;
        ++c.statuses[f.metrics["status"].get<std::string>()];
        break;
      case TrialState::kIncomplete:
        ++c.incomplete;
        break;
      case TrialState::kCorrupt:
        ++c.corrupt;
        break;
      case TrialState::kAbsent:
        ++c.absent;
        break;
    }
  }
  return c;
}

std::string statusList(const TrialCounts& c) {
  std::string out;
  for (const auto& [status, n] : c.statuses) out += (out.empty() ? "" : ", ") + std::to_string(n) + " " + status;
  return out.empty() ? "none" : out;
}

// ---- FolderLock ----------------------------------------------------------------------------

FolderLock::FolderLock(const fs::path& file, bool inherit, double wait_s, const std::string& waiting_message) {
  fd_ = ::open(file.c_str(), O_RDWR | O_CREAT | (inherit ? 0 : O_CLOEXEC), 0644);
  if (fd_ < 0) throw InputError("--out: cannot create " + file.string() + ": " + std::strerror(errno));
  const auto t0 = std::chrono::steady_clock::now();
  bool told = false;
  while (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (waited >= wait_s) {
      ::close(fd_);
      throw InputError("--out: " + file.parent_path().string() +
                       " is in use by another tgnav sweep (or its trials are still stopping): " + file.string() +
                       " is locked");
    }
    if (!told && !waiting_message.empty()) {
      std::fprintf(stderr, "%s\n", waiting_message.c_str());
      told = true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
}

FolderLock::~FolderLock() { ::close(fd_); }

// ---- SweepDir ------------------------------------------------------------------------------

SweepDir::SweepDir(const fs::path& dir) : dir_(fs::weakly_canonical(fs::absolute(dir))) {
  if (!dir_.has_filename()) dir_ = dir_.parent_path();
}

std::vector<SweepTrial> SweepDir::manifest() const {
  const fs::path file = dir_ / "trials.csv";
  if (!fs::is_regular_file(file)) {
    throw InputError("--out: " + dir_.string() + " is not a sweep folder (no trials.csv)");
  }
  return parseManifest(readTextFile(file), file.string());
}

std::vector<TrialFolder> SweepDir::inspect(const std::vector<SweepTrial>& trials) const {
  std::vector<TrialFolder> folders;
  folders.reserve(trials.size());
  for (const SweepTrial& t : trials) folders.push_back(inspectTrialFolder(t, trialDir(t)));
  return folders;
}

std::vector<TrialFolder> SweepDir::writeIndex(const std::vector<SweepTrial>& trials) const {
  const FolderLock lock(dir_ / ".index.lock", false, 60.0, "");
  std::vector<TrialFolder> folders = inspect(trials);
  writeFileAtomic(dir_ / "index.csv", indexCsv(trials, folders));
  return folders;
}

std::size_t SweepDir::staging() const {
  std::size_t n = 0;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir_ / "trials", ec)) n += isTrialStaging(e.path().filename().string());
  return n;
}

void SweepDir::prepare(const Sweep& sweep) const {
  const fs::path commands = dir_ / "commands.txt";
  const std::string text = commandsText(sweep.trials);
  if (fs::exists(commands)) {
    const std::string held = readTextFile(commands);
    if (held != text) {
      std::istringstream a(held), b(text);
      std::string la, lb;
      int line = 1;
      while (std::getline(a, la) && std::getline(b, lb) && la == lb) ++line;
      const std::string what = la.substr(0, la.find(' '));
      throw InputError("--out: " + dir_.string() + " holds another sweep: its commands.txt differs from " +
                       sweep.source.string() + "'s at line " + std::to_string(line) + " (trial " + what +
                       "); use a new --out, or the sweep file it was made from");
    }
  }
  makeOutputDir(dir_ / "trials");
  makeOutputDir(dir_ / "logs");
  if (!fs::exists(dir_ / "sweep.yaml")) writeFileAtomic(dir_ / "sweep.yaml", readTextFile(sweep.source));
  writeFileAtomic(dir_ / "trials.csv", manifestCsv(sweep.trials));
  writeFileAtomic(commands, text);
}

void SweepDir::tidy(const std::vector<SweepTrial>& trials, const std::vector<TrialFolder>& folders) const {
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir_ / "trials", ec)) {
    if (isTrialLeftover(e.path().filename().string())) fs::remove_all(e.path(), ec);
  }
  for (std::size_t i = 0; i < trials.size(); ++i) {
    if (folders[i].state != TrialState::kCorrupt) continue;
    makeOutputDir(dir_ / "corrupt");
    fs::path to;
    for (int n = 1; to.empty() || fs::exists(to); ++n) to = dir_ / "corrupt" / (trials[i].id + "." + std::to_string(n));
    fs::rename(trialDir(trials[i]), to);
    std::fprintf(stderr, "tgnav sweep: trials/%s is corrupted (%s); moved to %s, the trial runs again\n",
                 trials[i].id.c_str(), folders[i].problem.c_str(), fs::relative(to, dir_).string().c_str());
  }
}

}  // namespace tgnav::harness
