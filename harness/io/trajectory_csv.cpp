#include "harness/io/trajectory_csv.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "harness/base/errors.h"

namespace tgnav::harness {

namespace {

const std::array<const char*, 12> kColumns = {"t",  "x",  "y",  "z",  "yaw", "vx",
                                              "vy", "vz", "ax", "ay", "az",  "yaw_rate"};

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}

std::vector<std::string> splitCsv(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string item;
  while (std::getline(ss, item, ',')) out.push_back(trim(item));
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

// A CSV file with a header row naming its columns ('#' comment lines and blank lines skipped).
class HeaderedCsv {
 public:
  // `allowed` lists the columns, `columns_hint` says them in messages; the header must name every
  // column of `required`, and passes `check` (which may fail()) when one is given.
  HeaderedCsv(const std::filesystem::path& file, const char* what, std::vector<std::string> allowed,
              std::vector<std::string> required, std::string columns_hint,
              std::function<void(const HeaderedCsv&)> check = {})
      : in_(file),
        name_(file.string()),
        allowed_(std::move(allowed)),
        required_(std::move(required)),
        hint_(std::move(columns_hint)),
        check_(std::move(check)) {
    if (!in_) throw InputError(name_ + ": cannot open " + what + " file");
  }

  // The next data row's fields (the header is read first, on the first call); false at the end.
  bool next(std::vector<std::string>* fields) {
    std::string raw;
    while (std::getline(in_, raw)) {
      ++line_;
      const std::string line = trim(raw);
      if (line.empty() || line[0] == '#') continue;
      *fields = splitCsv(line);
      if (col_.empty()) {
        readHeader(*fields);
        continue;
      }
      if (fields->size() != col_.size()) {
        fail("row has " + std::to_string(fields->size()) + " fields, the header has " + std::to_string(col_.size()));
      }
      return true;
    }
    return false;
  }

  bool has(const char* column) const { return col_.count(column) > 0; }
  bool hasHeader() const { return !col_.empty(); }
  const std::string& name() const { return name_; }
  const std::string& text(const std::vector<std::string>& fields, const char* column) const {
    return fields[static_cast<std::size_t>(col_.at(column))];
  }

  // The finite number in `column` of the row (fallback when the file has no such column).
  double number(const std::vector<std::string>& fields, const char* column, double fallback = 0.0) const {
    if (!has(column)) return fallback;
    const std::string& t = text(fields, column);
    char* end = nullptr;
    const double v = std::strtod(t.c_str(), &end);
    if (t.empty() || end != t.c_str() + t.size() || !std::isfinite(v)) {
      fail(std::string("column '") + column + "' has value '" + t + "', expected a finite number");
    }
    return v;
  }

  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(name_ + ":" + std::to_string(line_) + ": " + what);
  }

 private:
  void readHeader(const std::vector<std::string>& fields) {
    for (std::size_t i = 0; i < fields.size(); ++i) {
      if (std::find(allowed_.begin(), allowed_.end(), fields[i]) == allowed_.end()) {
        fail("unknown column '" + fields[i] + "' (" + hint_ + ")");
      }
      if (!col_.emplace(fields[i], static_cast<int>(i)).second) fail("column '" + fields[i] + "' appears twice");
    }
    for (const std::string& c : required_) {
      if (!has(c.c_str())) fail("missing required column '" + c + "'");
    }
    if (check_) check_(*this);
  }

  std::ifstream in_;
  std::string name_;
  std::vector<std::string> allowed_;
  std::vector<std::string> required_;
  std::string hint_;
  std::function<void(const HeaderedCsv&)> check_;
  std::map<std::string, int> col_;  // column name -> index in the row
  int line_ = 0;
};

}  // namespace

std::vector<planner::Pose4> readPathCsv(const std::filesystem::path& file) {
  HeaderedCsv csv(file, "path", {"x", "y", "z", "yaw"}, {"x", "y", "z", "yaw"}, "a path has the columns x,y,z,yaw");
  std::vector<planner::Pose4> path;
  std::vector<std::string> fields;
  while (csv.next(&fields)) {
    planner::Pose4 p;
    p.p_WB = Eigen::Vector3d(csv.number(fields, "x"), csv.number(fields, "y"), csv.number(fields, "z"));
    p.yaw_rad = csv.number(fields, "yaw");
    path.push_back(p);
  }
  if (!csv.hasHeader()) throw InputError(csv.name() + ": empty path file (no header row)");
  if (path.size() < 2) {
    throw InputError(csv.name() + ": a path needs at least 2 waypoints, this one has " + std::to_string(path.size()));
  }
  return path;
}

control::SetpointTrajectory readTrajectoryCsv(const std::filesystem::path& file) {
  // The feed-forward groups come whole or not at all.
  auto groups = [](const HeaderedCsv& csv) {
    for (const auto& group :
         {std::array<const char*, 3>{"vx", "vy", "vz"}, std::array<const char*, 3>{"ax", "ay", "az"}}) {
      const int present = static_cast<int>(csv.has(group[0])) + static_cast<int>(csv.has(group[1])) +
                          static_cast<int>(csv.has(group[2]));
      if (present != 0 && present != 3) {
        csv.fail(std::string("columns ") + group[0] + "," + group[1] + "," + group[2] +
                 " come all together or not at all");
      }
    }
  };
  HeaderedCsv csv(file, "trajectory", {kColumns.begin(), kColumns.end()}, {"t", "x", "y", "z", "yaw"},
                  "columns: t,x,y,z,yaw and optionally vx,vy,vz,ax,ay,az,yaw_rate", groups);
  std::vector<double> times;
  std::vector<control::TrajectorySetpoint> setpoints;
  std::vector<std::string> fields;
  while (csv.next(&fields)) {
    const double t = csv.number(fields, "t");
    if (!times.empty() && !(t > times.back())) {
      char prev[64];
      std::snprintf(prev, sizeof(prev), "%g", times.back());
      csv.fail("column 't' has value '" + csv.text(fields, "t") + "', not after the previous " + prev +
               " (time must increase)");
    }
    control::TrajectorySetpoint sp;
    sp.p_WB = Eigen::Vector3d(csv.number(fields, "x"), csv.number(fields, "y"), csv.number(fields, "z"));
    sp.yaw_rad = csv.number(fields, "yaw");
    sp.v_WB = Eigen::Vector3d(csv.number(fields, "vx"), csv.number(fields, "vy"), csv.number(fields, "vz"));
    sp.a_WB = Eigen::Vector3d(csv.number(fields, "ax"), csv.number(fields, "ay"), csv.number(fields, "az"));
    sp.yaw_rate_rad_s = csv.number(fields, "yaw_rate");
    times.push_back(t);
    setpoints.push_back(sp);
  }
  if (!csv.hasHeader()) throw InputError(csv.name() + ": empty trajectory file (no header row)");
  if (times.empty()) throw InputError(csv.name() + ": trajectory has a header but no setpoints");
  return control::SetpointTrajectory(std::move(times), std::move(setpoints));
}

std::string trajectoryCsv(const control::SetpointTrajectory& trajectory) {
  // Shortest text that reads back to the same double: exact round trip, no padding digits.
  std::string out = "t,x,y,z,yaw,vx,vy,vz,ax,ay,az,yaw_rate\n";
  char buf[32];
  auto put = [&](double v, char end) {
    const auto r = std::to_chars(buf, buf + sizeof(buf), v);
    out.append(buf, r.ptr);
    out.push_back(end);
  };
  for (std::size_t i = 0; i < trajectory.times().size(); ++i) {
    const auto& s = trajectory.setpoints()[i];
    put(trajectory.times()[i], ',');
    for (int k = 0; k < 3; ++k) put(s.p_WB[k], ',');
    put(s.yaw_rad, ',');
    for (int k = 0; k < 3; ++k) put(s.v_WB[k], ',');
    for (int k = 0; k < 3; ++k) put(s.a_WB[k], ',');
    put(s.yaw_rate_rad_s, '\n');
  }
  return out;
}

}  // namespace tgnav::harness
