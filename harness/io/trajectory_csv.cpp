#include "harness/io/trajectory_csv.h"

#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
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

}  // namespace

std::vector<planner::Pose4> readPathCsv(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError(file.string() + ": cannot open path file");
  const std::string name = file.string();
  auto fail = [&](int line, const std::string& what) {
    throw InputError(name + ":" + std::to_string(line) + ": " + what);
  };
  std::map<std::string, int> col;
  std::vector<planner::Pose4> path;
  std::string raw;
  int line_no = 0;
  while (std::getline(in, raw)) {
    ++line_no;
    const std::string line = trim(raw);
    if (line.empty() || line[0] == '#') continue;
    const std::vector<std::string> fields = splitCsv(line);
    if (col.empty()) {
      for (std::size_t i = 0; i < fields.size(); ++i) {
        if (fields[i] != "x" && fields[i] != "y" && fields[i] != "z" && fields[i] != "yaw") {
          fail(line_no, "unknown column '" + fields[i] + "' (a path has the columns x,y,z,yaw)");
        }
        if (!col.emplace(fields[i], static_cast<int>(i)).second) {
          fail(line_no, "column '" + fields[i] + "' appears twice");
        }
      }
      for (const char* c : {"x", "y", "z", "yaw"}) {
        if (!col.count(c)) fail(line_no, std::string("missing required column '") + c + "'");
      }
      continue;
    }
    if (fields.size() != col.size()) {
      fail(line_no,
           "row has " + std::to_string(fields.size()) + " fields, the header has " + std::to_string(col.size()));
    }
    auto value = [&](const char* c) {
      const std::string& text = fields[static_cast<std::size_t>(col.at(c))];
      char* end = nullptr;
      const double v = std::strtod(text.c_str(), &end);
      if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(v)) {
        fail(line_no, std::string("column '") + c + "' has value '" + text + "', expected a finite number");
      }
      return v;
    };
    planner::Pose4 p;
    p.p_WB = Eigen::Vector3d(value("x"), value("y"), value("z"));
    p.yaw_rad = value("yaw");
    path.push_back(p);
  }
  if (col.empty()) throw InputError(name + ": empty path file (no header row)");
  if (path.size() < 2) {
    throw InputError(name + ": a path needs at least 2 waypoints, this one has " + std::to_string(path.size()));
  }
  return path;
}

control::SetpointTrajectory readTrajectoryCsv(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError(file.string() + ": cannot open trajectory file");
  const std::string name = file.string();
  auto fail = [&](int line, const std::string& what) {
    throw InputError(name + ":" + std::to_string(line) + ": " + what);
  };

  std::map<std::string, int> col;  // column name -> index in the row
  std::vector<double> times;
  std::vector<control::TrajectorySetpoint> setpoints;
  std::string raw;
  int line_no = 0;
  while (std::getline(in, raw)) {
    ++line_no;
    const std::string line = trim(raw);
    if (line.empty() || line[0] == '#') continue;
    const std::vector<std::string> fields = splitCsv(line);
    if (col.empty()) {
      for (std::size_t i = 0; i < fields.size(); ++i) {
        bool known = false;
        for (const char* c : kColumns) known = known || fields[i] == c;
        if (!known) {
          fail(line_no,
               "unknown column '" + fields[i] + "' (columns: t,x,y,z,yaw and optionally vx,vy,vz,ax,ay,az,yaw_rate)");
        }
        if (!col.emplace(fields[i], static_cast<int>(i)).second) {
          fail(line_no, "column '" + fields[i] + "' appears twice");
        }
      }
      for (const char* c : {"t", "x", "y", "z", "yaw"}) {
        if (!col.count(c)) fail(line_no, std::string("missing required column '") + c + "'");
      }
      for (const auto& group :
           {std::array<const char*, 3>{"vx", "vy", "vz"}, std::array<const char*, 3>{"ax", "ay", "az"}}) {
        const int present = static_cast<int>(col.count(group[0]) + col.count(group[1]) + col.count(group[2]));
        if (present != 0 && present != 3) {
          fail(line_no, std::string("columns ") + group[0] + "," + group[1] + "," + group[2] +
                            " come all together or not at all");
        }
      }
      continue;
    }
    if (fields.size() != col.size()) {
      fail(line_no,
           "row has " + std::to_string(fields.size()) + " fields, the header has " + std::to_string(col.size()));
    }
    auto value = [&](const char* c, double fallback) {
      const auto it = col.find(c);
      if (it == col.end()) return fallback;
      const std::string& text = fields[it->second];
      char* end = nullptr;
      const double v = std::strtod(text.c_str(), &end);
      if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(v)) {
        fail(line_no, std::string("column '") + c + "' has value '" + text + "', expected a finite number");
      }
      return v;
    };
    const double t = value("t", 0.0);
    if (!times.empty() && !(t > times.back())) {
      char prev[64];
      std::snprintf(prev, sizeof(prev), "%g", times.back());
      fail(line_no,
           "column 't' has value '" + fields[col["t"]] + "', not after the previous " + prev + " (time must increase)");
    }
    control::TrajectorySetpoint sp;
    sp.p_WB = Eigen::Vector3d(value("x", 0), value("y", 0), value("z", 0));
    sp.yaw_rad = value("yaw", 0);
    sp.v_WB = Eigen::Vector3d(value("vx", 0), value("vy", 0), value("vz", 0));
    sp.a_WB = Eigen::Vector3d(value("ax", 0), value("ay", 0), value("az", 0));
    sp.yaw_rate_rad_s = value("yaw_rate", 0);
    times.push_back(t);
    setpoints.push_back(sp);
  }
  if (col.empty()) throw InputError(name + ": empty trajectory file (no header row)");
  if (times.empty()) throw InputError(name + ": trajectory has a header but no setpoints");
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
