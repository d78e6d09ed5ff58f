#pragma once
// The `tgnav fly` job: take off from the scene's start and fly a setpoint trajectory file through
// the PX4-like cascade on ground truth; write the flown trajectory (gt.tum, flight.csv) and a
// tracking summary (tracking.json), and optionally record the onboard RGB-D camera as a TUM RGB-D
// sequence into its own new folder.
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

namespace tgnav::harness {

struct FlyJob {
  std::filesystem::path scene;       // scene YAML, or an MJCF that includes the vehicle
  std::filesystem::path trajectory;  // CSV (harness/io/trajectory_csv.h)
  std::filesystem::path out;
  // Vehicle description; empty: the scene's (its `vehicle`, else the vehicle its MJCF includes).
  std::filesystem::path vehicle;
  // Controller YAML over the vehicle's gains (its description's controller_config, else the
  // built-in defaults); "" = none.
  std::string controller;
  // Recording of the onboard camera (empty record: none).
  std::string record;
  double record_rate_hz = 20.0;
  std::string camera_config;
  std::optional<int> width_px;  // overrides the camera config
  std::optional<int> height_px;
  std::uint64_t seed = 0;  // camera noise
};

// False positive: clang-tidy 14 takes the implicit default constructor for noexcept (it is not: json's can throw).
// NOLINTNEXTLINE(bugprone-exception-escape)
struct FlyRunResult {
  std::filesystem::path out;
  nlohmann::ordered_json tracking;  // tracking.json as written
  int clamped_setpoints = 0;
};

// InputError for bad input (files, a trajectory that does not start at the scene's start or
// leaves its bounds, a recording rate that does not divide the physics rate, a taken --record).
FlyRunResult runFly(const FlyJob& job);

// The lines `tgnav fly` prints: the flight, and the recording when there was one.
std::string flySummaryLines(const FlyRunResult& result);

}  // namespace tgnav::harness
