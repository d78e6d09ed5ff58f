#include "harness/experiments/report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include "harness/base/errors.h"
#include "harness/base/files.h"
#include "harness/config/external_planner_config.h"
#include "harness/experiments/report_trial.h"
#include "harness/experiments/statistics.h"
#include "harness/experiments/sweep.h"
#include "harness/io/staged_output.h"

namespace tgnav::harness {
namespace {

namespace fs = std::filesystem;

const std::vector<std::string> kIndexColumns = {"id",
                                                "scene",
                                                "planner",
                                                "samples",
                                                "seed",
                                                "params",
                                                "status",
                                                "path_length_m",
                                                "planned_length_m",
                                                "goal_error_m",
                                                "final_distance_to_goal_m",
                                                "ate_rmse_m",
                                                "plan_time_s",
                                                "wall_time_s",
                                                "sim_time_s",
                                                "vo_lost_at_s",
                                                "distance_tracked_m",
                                                "folder"};
const std::vector<std::string> kManifestColumns = {"id", "scenario", "scene", "planner", "samples", "seed", "params"};

std::vector<std::string> splitFields(const std::string& line, char sep) {
  std::vector<std::string> out;
  std::string::size_type start = 0;
  while (true) {
    const auto end = line.find(sep, start);
    out.push_back(line.substr(start, end == std::string::npos ? std::string::npos : end - start));
    if (end == std::string::npos) return out;
    start = end + 1;
  }
}

// Non-empty lines with their 1-based line numbers; "\r\n" endings accepted.
std::vector<std::pair<int, std::string>> csvLines(const std::string& text) {
  std::vector<std::pair<int, std::string>> lines;
  std::istringstream in(text);
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (!line.empty()) lines.emplace_back(n, line);
  }
  return lines;
}

std::string joined(const std::vector<std::string>& items, const std::string& sep) {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i) out += (i ? sep : "") + items[i];
  return out;
}

// InputError "<file>:1: ..." naming the first column that differs from `expected`.
void checkHeader(const std::vector<std::pair<int, std::string>>& lines, const fs::path& file,
                 const std::vector<std::string>& expected) {
  if (lines.empty() || lines.front().first != 1) throw InputError(file.string() + ":1: missing header line");
  const std::vector<std::string> got = splitFields(lines.front().second, ',');
  for (std::size_t i = 0; i < std::max(got.size(), expected.size()); ++i) {
    const std::string g = i < got.size() ? got[i] : "(nothing)";
    const std::string e = i < expected.size() ? expected[i] : "(nothing)";
    if (g != e) {
      throw InputError(file.string() + ":1: header column " + std::to_string(i + 1) + " is '" + g + "', expected '" +
                       e + "' (the header must be " + joined(expected, ",") + ")");
    }
  }
}

// Parses the cells of one index.csv row, naming file:line and the column in errors.
class RowReader {
 public:
  RowReader(const fs::path& file, int line, const std::vector<std::string>& fields)
      : file_(file), line_(line), fields_(fields) {}

  const std::string& text(std::size_t col) const { return fields_[col]; }

  std::string required(std::size_t col) const {
    if (fields_[col].empty()) fail(col, "is empty");
    return fields_[col];
  }

  std::optional<double> number(std::size_t col) const {
    const std::string& s = fields_[col];
    if (s.empty()) return std::nullopt;
    std::size_t used = 0;
    double v = 0.0;
    try {
      v = std::stod(s, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != s.size() || !std::isfinite(v)) fail(col, "'" + s + "' is not a number");
    return v;
  }

  long long integer(std::size_t col, long long min, long long max) const {
    const std::string s = required(col);
    std::size_t used = 0;
    long long v = 0;
    try {
      v = std::stoll(s, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != s.size() || v < min || v > max) {
      fail(col, "'" + s + "' is not an integer in [" + std::to_string(min) + ", " + std::to_string(max) + "]");
    }
    return v;
  }

  std::string oneOf(std::size_t col, const std::vector<std::string>& allowed) const {
    const std::string& s = fields_[col];
    if (std::find(allowed.begin(), allowed.end(), s) == allowed.end()) {
      fail(col, "'" + s + "' is not one of " + joined(allowed, ", "));
    }
    return s;
  }

  [[noreturn]] void fail(std::size_t col, const std::string& what) const {
    throw InputError(where() + ": column " + kIndexColumns[col] + ": " + what);
  }
  std::string where() const { return file_.string() + ":" + std::to_string(line_); }

 private:
  const fs::path& file_;
  int line_;
  const std::vector<std::string>& fields_;
};

IndexRow parseRow(const fs::path& file, const fs::path& dir, int line, const std::string& text) {
  const std::vector<std::string> fields = splitFields(text, ',');
  if (fields.size() != kIndexColumns.size()) {
    throw InputError(file.string() + ":" + std::to_string(line) + ": " + std::to_string(fields.size()) +
                     " fields, expected " + std::to_string(kIndexColumns.size()) + " (" + joined(kIndexColumns, ",") +
                     ")");
  }
  const RowReader r(file, line, fields);
  static const std::vector<std::string> kPlanners = {"proposed", "agnostic", "rrtstar"};
  IndexRow row;
  row.line = line;
  row.id = r.required(0);
  row.scene = r.required(1);
  row.planner = r.required(2);
  if (std::find(kPlanners.begin(), kPlanners.end(), row.planner) == kPlanners.end() &&
      !isExternalPlannerName(row.planner)) {
    r.fail(2, "'" + row.planner + "' is not one of " + joined(kPlanners, ", ") + " nor an external planner's name");
  }
  row.samples = static_cast<int>(r.integer(3, 0, 1000000000));
  row.seed = static_cast<std::uint64_t>(r.integer(4, 0, std::numeric_limits<long long>::max()));
  row.params = r.text(5);
  row.status = r.oneOf(6, trialStatusNames());
  std::optional<double>* numbers[] = {
      &row.path_length_m, &row.planned_length_m,  &row.goal_error_m, &row.final_distance_to_goal_m,
      &row.ate_rmse_m,    &row.plan_time_s,       &row.wall_time_s,  &row.sim_time_s,
      &row.vo_lost_at_s,  &row.distance_tracked_m};
  for (std::size_t k = 0; k < std::size(numbers); ++k) *numbers[k] = r.number(7 + k);

  const std::string folder = r.required(17);
  row.folder = (dir / folder).lexically_normal();
  std::error_code ec;
  if (!fs::is_directory(row.folder, ec)) {
    throw InputError(r.where() + ": trial " + row.id + ": " + folder + " is missing");
  }
  const std::string metrics = (fs::path(folder) / "metrics.json").string();
  if (!fs::is_regular_file(row.folder / "metrics.json", ec)) {
    throw InputError(r.where() + ": trial " + row.id + ": " + metrics + " is missing");
  }
  readTrialMetrics(row.folder / "metrics.json", (file.parent_path() / metrics).string(), row);
  if (fs::is_regular_file(row.folder / "plan.json", ec)) {
    readTrialPlan(row.folder / "plan.json", (file.parent_path() / folder / "plan.json").string(), row);
  }
  return row;
}

std::string csvSummary(const std::optional<Summary>& s) {
  if (!s) return ",,";
  return std::to_string(s->n) + "," + csvNumber(s->mean) + "," + (s->n > 1 ? csvNumber(s->std) : "0");
}

// Decimals that print |v| to 3 significant figures (none past the units for |v| >= 100).
int sig3Decimals(double v) {
  v = std::abs(v);
  if (v == 0.0 || !std::isfinite(v)) return 0;
  const int digits = static_cast<int>(std::floor(std::log10(v))) + 1;
  int decimals = std::max(0, 3 - digits);
  // Rounding may carry into a new digit: 9.996 prints as 10.0, not 10.00.
  const double scale = std::pow(10.0, decimals);
  if (decimals > 0 && std::round(v * scale) / scale >= std::pow(10.0, digits)) --decimals;
  return decimals;
}

std::string fixed(double v, int decimals) {
  char s[64];
  std::snprintf(s, sizeof s, "%.*f", decimals, v);
  return s;
}

// Characters on screen of UTF-8 text (the table holds "±" and "–").
std::size_t displayWidth(const std::string& s) {
  return static_cast<std::size_t>(
      std::count_if(s.begin(), s.end(), [](char c) { return (static_cast<unsigned char>(c) & 0xC0) != 0x80; }));
}

}  // namespace

std::string csvNumber(double v) {
  char s[40];
  std::snprintf(s, sizeof s, "%.10g", v);
  return s;
}

std::string markdownCell(std::string s) {
  for (std::size_t i = s.find('|'); i != std::string::npos; i = s.find('|', i + 2)) s.replace(i, 1, "\\|");
  return s;
}

std::vector<IndexRow> parseIndexCsv(const std::string& text, const fs::path& file, const fs::path& dir) {
  const auto lines = csvLines(text);
  checkHeader(lines, file, kIndexColumns);
  if (lines.size() == 1) throw InputError(file.string() + ": no finished trials yet");
  std::vector<IndexRow> rows;
  std::map<std::string, int> seen;  // id -> line
  for (std::size_t i = 1; i < lines.size(); ++i) {
    IndexRow row = parseRow(file, dir, lines[i].first, lines[i].second);
    const auto [it, fresh] = seen.emplace(row.id, row.line);
    if (!fresh) {
      throw InputError(file.string() + ":" + std::to_string(row.line) + ": column id: trial '" + row.id +
                       "' is already on line " + std::to_string(it->second));
    }
    rows.push_back(std::move(row));
  }
  return rows;
}

SweepIndex readSweep(const fs::path& dir) {
  std::error_code ec;
  if (!fs::exists(dir, ec)) throw InputError(dir.string() + ": no such directory");
  if (!fs::is_directory(dir, ec)) throw InputError(dir.string() + ": not a directory");
  const fs::path index = dir / "index.csv";
  if (!fs::exists(index, ec)) throw InputError(dir.string() + " is not a sweep folder: no index.csv");
  SweepIndex sweep;
  sweep.dir = fs::absolute(dir).lexically_normal();
  sweep.rows = parseIndexCsv(readTextFile(index), index, sweep.dir);
  const fs::path manifest = dir / "trials.csv";
  if (fs::exists(manifest, ec)) {
    const auto lines = csvLines(readTextFile(manifest));
    checkHeader(lines, manifest, kManifestColumns);
    std::set<std::string> ids;
    for (std::size_t i = 1; i < lines.size(); ++i) ids.insert(splitFields(lines[i].second, ',').front());
    sweep.manifest_trials = static_cast<int>(ids.size());
    // A finished trial the manifest does not list belongs to another sweep (or a stale index).
    for (const IndexRow& row : sweep.rows) {
      if (!ids.count(row.id)) {
        throw InputError(index.string() + ":" + std::to_string(row.line) + ": column id: trial '" + row.id +
                         "' is not in " + manifest.string());
      }
    }
  }
  return sweep;
}

std::optional<Summary> summarise(const std::vector<double>& values) {
  if (values.empty()) return std::nullopt;
  Summary s;
  s.n = static_cast<int>(values.size());
  for (const double v : values) s.mean += v;
  s.mean /= s.n;
  if (s.n > 1) {
    double ss = 0.0;
    for (const double v : values) ss += (v - s.mean) * (v - s.mean);
    s.std = std::sqrt(ss / (s.n - 1));
  }
  return s;
}

std::string plannerLabel(const std::string& planner, int samples, const std::string& params) {
  std::string label = planner == "proposed"   ? "Proposed"
                      : planner == "agnostic" ? "AP"
                      : planner == "rrtstar"  ? "R-" + std::to_string(samples)
                                              : planner;
  if (!params.empty()) label += " [" + paramsLabel(params) + "]";
  return label;
}

std::vector<ReportGroup> groupTrials(const std::vector<IndexRow>& rows) {
  std::vector<ReportGroup> groups;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const IndexRow& r = rows[i];
    auto it = std::find_if(groups.begin(), groups.end(), [&](const ReportGroup& g) {
      return g.scene == r.scene && g.planner == r.planner && g.samples == r.samples && g.params == r.params;
    });
    if (it == groups.end()) {
      groups.push_back({r.scene, r.planner, r.samples, r.params, plannerLabel(r.planner, r.samples, r.params), {}});
      it = std::prev(groups.end());
    }
    it->trials.push_back(i);
  }
  return groups;
}

TableRow tableRow(const ReportGroup& group, const std::vector<IndexRow>& rows) {
  TableRow t;
  t.scene = group.scene;
  t.planner = group.planner;
  t.samples = group.samples;
  t.params = group.params;
  t.label = group.label;
  std::vector<double> length, goal, plan, ate;
  std::map<std::string, int> counts;
  for (const std::size_t i : group.trials) {
    const IndexRow& r = rows[i];
    ++t.trials;
    ++counts[r.status];
    const bool flew = r.status != "plan_failed";
    if (r.status == "success") ++t.successes;
    if (r.status == "drifted") ++t.drifted;
    if (flew && r.path_length_m) length.push_back(*r.path_length_m);
    // Drifted trials tracked to the goal too: leaving them out would flatter the goal error.
    if ((r.status == "success" || r.status == "drifted") && r.goal_error_m) goal.push_back(*r.goal_error_m);
    if (r.plan_time_s) plan.push_back(*r.plan_time_s);
    if (flew && r.ate_rmse_m && r.tracked_frames.value_or(true)) ate.push_back(*r.ate_rmse_m);
  }
  t.length_m = summarise(length);
  t.goal_error_m = summarise(goal);
  t.plan_time_s = summarise(plan);
  t.ate_rmse_m = summarise(ate);
  for (const std::string& status : trialStatusNames()) {
    if (counts.count(status)) t.outcomes.emplace_back(status, counts[status]);
  }
  return t;
}

std::vector<TableRow> tableRows(const std::vector<ReportGroup>& groups, const std::vector<IndexRow>& rows) {
  std::vector<TableRow> out;
  out.reserve(groups.size());
  for (const ReportGroup& g : groups) out.push_back(tableRow(g, rows));
  return out;
}

std::string formatSig3(double value) {
  if (!std::isfinite(value)) return "nan";
  const std::string s = fixed(value, sig3Decimals(value));
  return s == "-0" ? "0" : s;
}

std::string formatSummary(const std::optional<Summary>& s) {
  if (!s) return "–";
  if (s->n == 1) return formatSig3(s->mean);
  const int decimals = sig3Decimals(s->mean != 0.0 ? s->mean : s->std);
  return fixed(s->mean, decimals) + " ± " + fixed(s->std, decimals);
}

std::string formatOutcomes(const std::vector<std::pair<std::string, int>>& outcomes) {
  std::string out;
  for (const auto& [status, count] : outcomes) out += (out.empty() ? "" : ", ") + std::to_string(count) + " " + status;
  return out;
}

std::string table2Csv(const std::vector<TableRow>& rows) {
  std::ostringstream out;
  out << "scene,planner,samples,params,label,trials,successes,vo_success_rate,length_n,length_mean_m,length_std_m,"
         "goal_error_n,goal_error_mean_m,goal_error_std_m,plan_time_n,plan_time_mean_s,plan_time_std_s,ate_n,"
         "ate_rmse_mean_m,ate_rmse_std_m";
  for (const std::string& status : trialStatusNames()) out << ',' << status;
  out << '\n';
  for (const TableRow& t : rows) {
    out << t.scene << ',' << t.planner << ',' << t.samples << ',' << t.params << ',' << t.label << ',' << t.trials
        << ',' << t.successes << ',' << csvNumber(static_cast<double>(t.successes) / t.trials) << ','
        << csvSummary(t.length_m) << ',' << csvSummary(t.goal_error_m) << ',' << csvSummary(t.plan_time_s) << ','
        << csvSummary(t.ate_rmse_m);
    for (const std::string& status : trialStatusNames()) {
      const auto it =
          std::find_if(t.outcomes.begin(), t.outcomes.end(), [&](const auto& o) { return o.first == status; });
      out << ',' << (it == t.outcomes.end() ? 0 : it->second);
    }
    out << '\n';
  }
  return out.str();
}

std::string markdownTable(const std::vector<std::string>& header, const std::vector<bool>& right,
                          const std::vector<std::vector<std::string>>& cells) {
  std::vector<std::size_t> width(header.size());
  for (std::size_t c = 0; c < header.size(); ++c) {
    width[c] = std::max<std::size_t>(3, displayWidth(header[c]));
    for (const auto& row : cells) width[c] = std::max(width[c], displayWidth(row[c]));
  }
  auto line = [&](const std::vector<std::string>& row) {
    std::string s = "|";
    for (std::size_t c = 0; c < row.size(); ++c) {
      const std::string pad(width[c] - displayWidth(row[c]), ' ');
      s += " " + (right[c] ? pad + row[c] : row[c] + pad) + " |";
    }
    return s + "\n";
  };
  std::string out = line(header) + "|";
  for (std::size_t c = 0; c < header.size(); ++c) {
    out += (right[c] ? " " + std::string(width[c] - 1, '-') + ":" : " " + std::string(width[c], '-')) + " |";
  }
  out += "\n";
  for (const auto& row : cells) out += line(row);
  return out;
}

std::string table2Markdown(const std::vector<TableRow>& rows, int finished, std::optional<int> manifest,
                           const std::string& sweep_name) {
  const std::vector<std::string> header = {"Scene",      "Planner", "Trials",        "Length (m)",   "Goal error (m)*",
                                           "VO success", "Drifted", "Plan time (s)", "ATE RMSE (m)", "Outcomes"};
  const std::vector<bool> right = {false, false, true, true, true, true, true, true, true, false};
  std::vector<std::vector<std::string>> cells;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const TableRow& t = rows[i];
    const bool first_of_scene = i == 0 || rows[i - 1].scene != t.scene;
    cells.push_back({first_of_scene ? "*" + markdownCell(t.scene) + "*" : "", markdownCell(t.label),
                     std::to_string(t.trials), formatSummary(t.length_m), formatSummary(t.goal_error_m),
                     formatSuccessInterval(t.successes, t.trials),
                     std::to_string(t.drifted) + "/" + std::to_string(t.trials), formatSummary(t.plan_time_s),
                     formatSummary(t.ate_rmse_m), formatOutcomes(t.outcomes)});
  }
  std::ostringstream out;
  out << "# Table II: " << sweep_name << "\n\n";
  if (manifest) {
    out << finished << " of " << *manifest << " trials finished.\n\n";
  } else {
    out << finished << " trials finished (the sweep has no trials.csv manifest).\n\n";
  }
  out << markdownTable(header, right, cells);
  out << "\nMean ± sample standard deviation over the trials of each group. Length: the flown (ground-truth) "
         "path, trials that flew. *Goal error: |estimated − true| final position, over the trials whose VO "
         "tracked to the goal (success and drifted; the paper's Table II: its successful trials). VO success: "
         "trials whose VO tracked all the way to the goal and ended within trial.max_drift_ratio of the distance "
         "flown, with its 95 % Wilson interval. Drifted: trials whose VO tracked to the goal but ended further off. "
         "ATE RMSE: trials with tracked "
         "frames.\n";
  return out.str();
}

}  // namespace tgnav::harness
