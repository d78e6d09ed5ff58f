#include "harness/run/external_plan.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <system_error>
#include <utility>

#include "harness/base/child_process.h"
#include "harness/base/clock.h"
#include "harness/base/errors.h"
#include "harness/io/grid_io.h"
#include "harness/io/planner_protocol.h"
#include "harness/io/staged_output.h"
#include "harness/run/given_route.h"
#include "harness/run/plan_run.h"

namespace tgnav::harness {

namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

constexpr double kShutdownGrace_s = 1.0;

// A fresh folder under the system's temporary folder, removed with everything in it.
class TempDir {
 public:
  TempDir() {
    std::string pattern = (fs::temp_directory_path() / "tgnav-planner-XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) throw InputError("cannot create a temporary folder in " + pattern);
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  TempDir(TempDir&&) = delete;
  TempDir& operator=(TempDir&&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

// The topological classes (the AP planner's) as classes.json: index, length and path per class
// (every class path has at least its start and its goal).
planner::TopoPlan writeClasses(const Scenario& scenario, const planner::VoxelMap& voxels, std::uint64_t seed,
                               const fs::path& file) {
  const auto solver = planner::makePlanner(planner::PlannerKind::kAgnostic, voxels, scenario.planner.perception,
                                           scenario.planner.rrt_star);
  planner::Plan plan = solver->solve(planner::PlanRequest{scenario.scene.start, scenario.scene.goal, seed});
  nlohmann::ordered_json classes = nlohmann::ordered_json::array();
  const double z = scenario.scene.start.p_WB.z();
  for (std::size_t k = 0; k < plan.topo.classes.size(); ++k) {
    const planner::HomologyClass& c = plan.topo.classes[k];
    nlohmann::ordered_json path = nlohmann::ordered_json::array();
    for (std::size_t i = 0; i < c.path.size(); ++i) {
      const std::size_t a = std::min(i, c.path.size() - 2);  // the segment leaving i (arriving, at the end)
      const Eigen::Vector2d d = c.path[a + 1] - c.path[a];
      path.push_back({c.path[i].x(), c.path[i].y(), z, std::atan2(d.y(), d.x())});
    }
    classes.push_back({{"index", k}, {"length_m", c.length_m}, {"path", path}});
  }
  writeFileAtomic(file, nlohmann::ordered_json{{"classes", classes}}.dump() + "\n");
  return std::move(plan.topo);
}

PlanRequestMessage requestFor(const Scenario& scenario, const fs::path& map_dir, const fs::path& tmp,
                              std::uint64_t seed, bool classes) {
  const planner::PerceptionPlannerConfig& perception = scenario.planner.perception;
  const planner::TrajectoryConfig& limits = scenario.planner.trajectory;
  const ClearanceBand band = clearanceBand(scenario);
  PlanRequestMessage m;
  m.seed = seed;
  m.time_budget_s = scenario.planner.external.timeout_s;
  m.start = scenario.scene.start;
  m.goal = scenario.scene.goal;
  m.bounds_min_m = scenario.scene.bounds_min_m;
  m.bounds_max_m = scenario.scene.bounds_max_m;
  m.flight_height_m = scenario.scene.start.p_WB.z();
  m.robot_radius_m = perception.robot_radius_m;
  m.check_band_lo_m = band.lo_m;
  m.check_band_hi_m = band.hi_m;
  m.nominal_speed_m_s = limits.nominal_speed_mps;
  m.max_speed_m_s = limits.max_speed_mps;
  m.max_accel_m_s2 = limits.max_accel_mps2;
  m.max_yaw_rate_rad_s = limits.max_yaw_rate_rad_s;
  m.width_px = scenario.camera.width_px;
  m.height_px = scenario.camera.height_px;
  m.camera_rate_hz = scenario.trial.camera_rate_hz;
  m.hfov_rad = perception.visibility.hfov_rad;
  m.vfov_rad = perception.visibility.vfov_rad;
  m.min_range_m = perception.visibility.min_range_m;
  m.max_range_m = perception.visibility.max_range_m;
  m.camera_forward_m = perception.visibility.camera_forward_m;
  m.camera_up_m = perception.visibility.camera_up_m;
  m.octomap = fs::absolute(map_dir / "map.bt").string();
  m.landmarks = fs::absolute(map_dir / "landmarks.csv").string();
  m.occupancy_yaml = (tmp / "occupancy.yaml").string();
  m.occupancy_pgm = (tmp / "occupancy.pgm").string();
  if (classes) m.classes = (tmp / "classes.json").string();
  return m;
}

// The occupancy slice (and the classes) written into `tmp`, and the request for `scenario`'s start
// with the map of `map_dir`. Fills out->topo and out->prepare_s.
PlanRequestMessage prepareRequest(const Scenario& scenario, const fs::path& map_dir, const planner::VoxelMap& voxels,
                                  std::uint64_t seed, const fs::path& tmp, ExternalPlan* out) {
  const ExternalPlannerConfig& ext = scenario.planner.external;
  const auto t0 = Clock::now();
  // The band above the floor's own voxel layer: where the band reaches down to it (a robot radius
  // of 0.38 m does at a 1 m flight height), the floor would block every cell of the slice.
  const ClearanceBand band = clearanceBand(scenario);
  const double lo_m = std::max(band.lo_m, scenario.scene.bounds_min_m.z() + 1.5 * voxels.resolution());
  writeRosMap(voxels.slice(lo_m, band.hi_m), tmp / "occupancy.yaml", tmp / "occupancy.pgm");
  if (ext.classes) out->topo = writeClasses(scenario, voxels, seed, tmp / "classes.json");
  PlanRequestMessage request = requestFor(scenario, map_dir, tmp, seed, ext.classes);
  out->prepare_s = secondsSince(t0);
  return request;
}

// Why a read or write ended without a line, with how the process ended when it did.
std::string ioFailure(ChildProcess::Io io, ChildProcess* child, double budget_s) {
  switch (io) {
    case ChildProcess::Io::kTimeout: {
      std::ostringstream s;
      s << "no answer within " << budget_s << " s (planner.external.timeout_s)";
      return s.str();
    }
    case ChildProcess::Io::kTooLong:
      return "invalid response: a line longer than " + std::to_string(kMaxResponseBytes >> 20) + " MiB";
    case ChildProcess::Io::kInterrupted:
      return "interrupted";
    default: {
      const std::string ended = child->waitExit(kShutdownGrace_s);
      return ended.empty() ? "closed its output" : ended + " before answering";
    }
  }
}

// One request and its response on a running planner. Fills out->call_s; returns the failure ("" when
// the response parsed).
std::string exchange(ChildProcess* child, const PlanRequestMessage& request, double timeout_s,
                     const std::atomic<bool>* interrupt, ExternalPlan* out, PlanResponse* response) {
  const auto t_call = Clock::now();
  const auto deadline = t_call + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout_s));
  std::string failure;
  ChildProcess::Io io = child->write(planRequestLine(request), deadline, interrupt);
  std::string line;
  if (io == ChildProcess::Io::kOk) io = child->readLine(&line, deadline, kMaxResponseBytes, interrupt);
  if (io != ChildProcess::Io::kOk) {
    failure = ioFailure(io, child, timeout_s);
  } else {
    try {
      *response = parsePlanResponse(line, request.id);
    } catch (const ProtocolError& e) {
      failure = e.what();
    }
  }
  out->call_s = secondsSince(t_call);
  return failure;
}

// Asks the planner to shut down and stops it (at once after a failure). Fills out->ended, stop_s.
void shutDown(ChildProcess* child, bool failed, ExternalPlan* out) {
  const auto t_stop = Clock::now();
  (void)child->write(shutdownLine(), Clock::now() + std::chrono::milliseconds(100));
  out->ended = child->stop(failed ? 0.0 : kShutdownGrace_s);
  out->stop_s = secondsSince(t_stop);
}

// The conversation: start, one request, one response, shutdown. Fills `out`; returns the failure
// ("" when the response parsed).
std::string converse(const Scenario& scenario, const PlanRequestMessage& request, const fs::path& tmp,
                     const std::atomic<bool>* interrupt, ExternalPlan* out, PlanResponse* response) {
  const ExternalPlannerConfig& ext = scenario.planner.external;
  const fs::path err = tmp / "stderr.txt";
  std::string failure;
  const auto t_start = Clock::now();
  try {
    ChildProcess child(ext.command, ext.dir, err);
    out->start_s = secondsSince(t_start);
    failure = exchange(&child, request, ext.timeout_s, interrupt, out, response);
    shutDown(&child, !failure.empty(), out);
  } catch (const std::runtime_error& e) {  // the system could not start it
    failure = e.what();
  }
  out->stderr_tail = fileTail(err);
  return failure;
}

// The planner's answer judged: its own failure, a class it was not sent, a route the map refuses.
// Sets out->ok and the route, or out->detail.
void judge(const Scenario& scenario, const planner::VoxelMap& voxels, PlanResponse response, ExternalPlan* out) {
  const ExternalPlannerConfig& ext = scenario.planner.external;
  const std::string who = "external planner " + ext.name + ": ";
  out->planner_s = response.solve_time_s;
  out->reason = response.reason;
  out->scores = response.scores;
  out->homology_class = response.homology_class;
  if (!response.ok) {
    out->no_path = true;
    out->detail = who + "no path" + (response.reason.empty() ? std::string() : ": " + response.reason);
    return;
  }
  const auto classes = static_cast<int>(out->topo.classes.size());
  if (ext.classes && response.homology_class && *response.homology_class >= classes) {
    out->detail = who + "invalid response: homology_class " + std::to_string(*response.homology_class) +
                  " is not one of the " + std::to_string(classes) + " classes sent";
    return;
  }
  const auto t_check = Clock::now();
  std::string refused;
  try {
    if (response.path) {
      checkGivenPath(scenario, voxels, *response.path, "path");
    } else {
      checkGivenTrajectory(scenario, voxels, *response.trajectory, "trajectory");
    }
  } catch (const InputError& e) {
    refused = e.what();
  }
  out->check_s = secondsSince(t_check);
  if (!refused.empty()) {
    out->detail = who + "route refused: " + refused;
    return;
  }
  out->path = std::move(response.path);
  out->trajectory = std::move(response.trajectory);
  out->ok = true;
}

}  // namespace

ExternalPlan askExternalPlanner(const Scenario& scenario, const fs::path& map_dir, const planner::VoxelMap& voxels,
                                std::uint64_t seed, const std::atomic<bool>* interrupt) {
  const ExternalPlannerConfig& ext = scenario.planner.external;
  ExternalPlan out;
  const TempDir tmp;
  const PlanRequestMessage request = prepareRequest(scenario, map_dir, voxels, seed, tmp.path(), &out);

  PlanResponse response;
  const std::string failure = converse(scenario, request, tmp.path(), interrupt, &out, &response);
  if (!failure.empty()) {
    out.detail = "external planner " + ext.name + ": " + failure;
    return out;
  }
  judge(scenario, voxels, std::move(response), &out);
  return out;
}

struct ExternalPlannerSession::Impl {
  TempDir tmp;
  std::unique_ptr<ChildProcess> child;
  int next_id = 1;
  std::string failure;  // why it was stopped
};

bool ExternalPlannerSession::stopped() const { return !impl_->failure.empty(); }

std::string ExternalPlannerSession::stderrTail() const { return fileTail(impl_->tmp.path() / "stderr.txt"); }

ExternalPlannerSession::ExternalPlannerSession() : impl_(std::make_unique<Impl>()) {}

ExternalPlannerSession::~ExternalPlannerSession() {
  if (!impl_->child) return;
  ExternalPlan ignored;
  shutDown(impl_->child.get(), false, &ignored);
}

ExternalPlan ExternalPlannerSession::ask(const Scenario& from_here, const planner::FeatureMap& map,
                                         const planner::VoxelMap& voxels, std::uint64_t seed,
                                         const std::atomic<bool>* interrupt) {
  const ExternalPlannerConfig& ext = from_here.planner.external;
  ExternalPlan out;
  if (stopped()) {
    out.detail = "external planner " + ext.name + ": " + impl_->failure;
    return out;
  }
  const fs::path& tmp = impl_->tmp.path();
  const auto t0 = Clock::now();
  fs::create_directories(tmp / "map");
  map.save(tmp / "map");
  PlanRequestMessage request = prepareRequest(from_here, tmp / "map", voxels, seed, tmp, &out);
  request.id = impl_->next_id++;
  out.prepare_s = secondsSince(t0);  // the map files included

  std::string failure;
  PlanResponse response;
  const fs::path err = tmp / "stderr.txt";
  try {
    if (!impl_->child) {
      const auto t_start = Clock::now();
      impl_->child = std::make_unique<ChildProcess>(ext.command, ext.dir, err);
      out.start_s = secondsSince(t_start);
    }
    failure = exchange(impl_->child.get(), request, ext.timeout_s, interrupt, &out, &response);
  } catch (const std::runtime_error& e) {  // the system could not start it
    failure = e.what();
  }
  if (!failure.empty()) {
    // A planner that failed once is not asked again.
    if (impl_->child) shutDown(impl_->child.get(), true, &out);
    impl_->child.reset();
    impl_->failure = failure;
    out.stderr_tail = fileTail(err);
    out.detail = "external planner " + ext.name + ": " + failure;
    return out;
  }
  judge(from_here, voxels, std::move(response), &out);
  return out;
}

}  // namespace tgnav::harness
