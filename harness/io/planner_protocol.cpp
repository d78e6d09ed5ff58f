#include "harness/io/planner_protocol.h"

#include <cmath>
#include <nlohmann/json.hpp>
#include <utility>

namespace tgnav::harness {

namespace {

using nlohmann::json;
using nlohmann::ordered_json;

ordered_json pose(const planner::Pose4& p) { return {p.p_WB.x(), p.p_WB.y(), p.p_WB.z(), p.yaw_rad}; }
ordered_json vec3(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

[[noreturn]] void invalid(const std::string& what) { throw ProtocolError("invalid response: " + what); }

// A finite number at `where`.
double number(const json& v, const std::string& where) {
  if (!v.is_number()) invalid(where + " is not a number");
  const double x = v.get<double>();
  if (!std::isfinite(x)) invalid(where + " is not a finite number");
  return x;
}

// An array of `min`..`max` rows, each an array of one of the sizes in `widths` (all rows alike).
std::vector<std::vector<double>> rows(const json& v, const std::string& key, std::size_t min, std::size_t max,
                                      const std::vector<std::size_t>& widths) {
  if (!v.is_array()) invalid("'" + key + "' is not an array");
  if (v.size() < min) {
    invalid("'" + key + "' has " + std::to_string(v.size()) + " points, at least " + std::to_string(min) + " needed");
  }
  if (v.size() > max) {
    invalid("'" + key + "' has " + std::to_string(v.size()) + " points, at most " + std::to_string(max) + " allowed");
  }
  std::vector<std::vector<double>> out;
  out.reserve(v.size());
  std::size_t width = 0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const std::string where = key + "[" + std::to_string(i) + "]";
    const json& row = v[i];
    if (!row.is_array()) invalid(where + " is not an array");
    if (i == 0) {
      width = row.size();
      bool allowed = false;
      for (std::size_t w : widths) allowed = allowed || w == width;
      if (!allowed) invalid(where + " has " + std::to_string(width) + " numbers");
    } else if (row.size() != width) {
      invalid(where + " has " + std::to_string(row.size()) + " numbers, " + key + "[0] has " + std::to_string(width));
    }
    std::vector<double> r(width);
    for (std::size_t k = 0; k < width; ++k) r[k] = number(row[k], where + "[" + std::to_string(k) + "]");
    out.push_back(std::move(r));
  }
  return out;
}

std::vector<planner::Pose4> pathOf(const json& v) {
  std::vector<planner::Pose4> path;
  for (const auto& r : rows(v, "path", 2, kMaxPathPoints, {4})) {
    planner::Pose4 p;
    p.p_WB = Eigen::Vector3d(r[0], r[1], r[2]);
    p.yaw_rad = r[3];
    path.push_back(p);
  }
  return path;
}

// Rows of t,x,y,z,yaw [,vx,vy,vz [,ax,ay,az [,yaw_rate]]].
control::SetpointTrajectory trajectoryOf(const json& v) {
  std::vector<double> t;
  std::vector<control::TrajectorySetpoint> sp;
  for (const auto& r : rows(v, "trajectory", 2, kMaxTrajectoryRows, {5, 8, 11, 12})) {
    t.push_back(r[0]);
    control::TrajectorySetpoint s;
    s.p_WB = Eigen::Vector3d(r[1], r[2], r[3]);
    s.yaw_rad = r[4];
    if (r.size() >= 8) s.v_WB = Eigen::Vector3d(r[5], r[6], r[7]);
    if (r.size() >= 11) s.a_WB = Eigen::Vector3d(r[8], r[9], r[10]);
    if (r.size() >= 12) s.yaw_rate_rad_s = r[11];
    sp.push_back(s);
  }
  try {
    return control::SetpointTrajectory(std::move(t), std::move(sp));
  } catch (const std::invalid_argument& e) {
    invalid(std::string("trajectory: ") + e.what());
  }
}

// One line of at most 200 characters.
std::string oneLine(std::string s) {
  for (char& c : s) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  if (s.size() > 200) s = s.substr(0, 197) + "...";
  return s;
}

}  // namespace

std::string planRequestLine(const PlanRequestMessage& m) {
  ordered_json j;
  j["protocol"] = kPlannerProtocolName;
  j["version"] = kPlannerProtocolVersion;
  j["type"] = "plan";
  j["id"] = m.id;
  j["seed"] = m.seed;
  j["time_budget_s"] = m.time_budget_s;
  j["start"] = pose(m.start);
  j["goal"] = pose(m.goal);
  j["bounds"] = {{"min", vec3(m.bounds_min_m)}, {"max", vec3(m.bounds_max_m)}};
  j["flight_height_m"] = m.flight_height_m;
  j["robot_radius_m"] = m.robot_radius_m;
  j["check_band_m"] = {m.check_band_lo_m, m.check_band_hi_m};
  j["vehicle"] = {{"nominal_speed_m_s", m.nominal_speed_m_s},
                  {"max_speed_m_s", m.max_speed_m_s},
                  {"max_accel_m_s2", m.max_accel_m_s2},
                  {"max_yaw_rate_rad_s", m.max_yaw_rate_rad_s}};
  j["camera"] = {{"width_px", m.width_px},       {"height_px", m.height_px},        {"rate_hz", m.camera_rate_hz},
                 {"hfov_rad", m.hfov_rad},       {"vfov_rad", m.vfov_rad},          {"min_range_m", m.min_range_m},
                 {"max_range_m", m.max_range_m}, {"forward_m", m.camera_forward_m}, {"up_m", m.camera_up_m}};
  j["map"] = {{"octomap", m.octomap},
              {"landmarks", m.landmarks},
              {"occupancy_yaml", m.occupancy_yaml},
              {"occupancy_pgm", m.occupancy_pgm},
              {"classes", m.classes.empty() ? ordered_json(nullptr) : ordered_json(m.classes)}};
  return j.dump() + "\n";
}

std::string shutdownLine() {
  ordered_json j;
  j["protocol"] = kPlannerProtocolName;
  j["version"] = kPlannerProtocolVersion;
  j["type"] = "shutdown";
  return j.dump() + "\n";
}

PlanResponse parsePlanResponse(const std::string& line, int expected_id) {
  if (line.find_first_not_of(" \t\r") == std::string::npos) throw ProtocolError("empty response");
  const json j = json::parse(line, nullptr, false);
  if (j.is_discarded()) {
    const bool non_finite = line.find("NaN") != std::string::npos || line.find("Infinity") != std::string::npos;
    invalid(non_finite ? "not JSON (NaN and Infinity are not JSON numbers)"
                       : "not JSON: " + oneLine(line.substr(0, 60)));
  }
  if (!j.is_object()) invalid("not a JSON object");
  if (!j.contains("protocol") || j["protocol"] != kPlannerProtocolName) invalid("'protocol' is not \"tgnav-planner\"");
  if (!j.contains("version") || !j["version"].is_number_integer()) invalid("'version' is not an integer");
  if (j["version"].get<long long>() != kPlannerProtocolVersion) {
    throw ProtocolError("protocol version " + j["version"].dump() + ", expected " +
                        std::to_string(kPlannerProtocolVersion));
  }
  for (const auto& item : j.items()) {
    static const char* const kKeys[] = {"protocol", "version",    "id",     "status",         "reason",
                                        "path",     "trajectory", "scores", "homology_class", "solve_time_s"};
    bool known = false;
    for (const char* k : kKeys) known = known || item.key() == k;
    if (!known) invalid("unknown key '" + oneLine(item.key()) + "'");
  }
  if (!j.contains("id") || !j["id"].is_number_integer() || j["id"].get<long long>() != expected_id) {
    invalid("'id' is " + (j.contains("id") ? oneLine(j["id"].dump()) : std::string("missing")) + ", expected " +
            std::to_string(expected_id));
  }
  PlanResponse r;
  if (j.contains("reason")) {
    if (!j["reason"].is_string()) invalid("'reason' is not a string");
    r.reason = oneLine(j["reason"].get<std::string>());
  }
  if (j.contains("solve_time_s")) {
    const double t = number(j["solve_time_s"], "solve_time_s");
    if (t < 0.0) invalid("solve_time_s is negative");
    r.solve_time_s = t;
  }
  const json status = j.contains("status") ? j["status"] : json();
  if (status == "no_path") {
    if (j.contains("path") || j.contains("trajectory")) invalid("status no_path with a route");
    return r;
  }
  if (status != "ok") invalid("'status' is " + oneLine(status.dump()) + ", expected \"ok\" or \"no_path\"");
  r.ok = true;
  if (j.contains("path") == j.contains("trajectory")) invalid("give one of 'path' and 'trajectory'");
  std::size_t points = 0;
  if (j.contains("path")) {
    r.path = pathOf(j["path"]);
    points = r.path->size();
  } else {
    r.trajectory = trajectoryOf(j["trajectory"]);
    points = r.trajectory->times().size();
  }
  if (j.contains("scores")) {
    const json& s = j["scores"];
    if (!s.is_array() || s.size() != points) {
      invalid("'scores' is not an array of " + std::to_string(points) + " numbers (one per point)");
    }
    for (std::size_t i = 0; i < s.size(); ++i) r.scores.push_back(number(s[i], "scores[" + std::to_string(i) + "]"));
  }
  if (j.contains("homology_class")) {
    const json& c = j["homology_class"];
    if (!c.is_number_integer() || c.get<long long>() < 0 || c.get<long long>() > 1000000) {
      invalid("'homology_class' is not an integer >= 0");
    }
    r.homology_class = c.get<int>();
  }
  return r;
}

}  // namespace tgnav::harness
