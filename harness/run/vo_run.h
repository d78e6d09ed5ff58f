#pragma once
// The `tgnav vo` job: the RGB-D visual odometry over a TUM RGB-D sequence folder (recorded by
// `tgnav fly --record`, or one of TUM's own), scored against its ground truth, written into a new
// folder: est.tum, status.csv (one row per frame) and summary.json.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "vo/odometry.h"

namespace tgnav::harness {

struct VoJob {
  std::filesystem::path sequence;
  std::filesystem::path out;  // a new folder; an existing one is refused
  std::string config;         // odometry YAML (vo::OdometryConfig keys); "" = built-in defaults
  std::string intrinsics;     // "fx,fy,cx,cy" overriding the sequence's intrinsics.yaml; "" = its own
  bool reinitialise = false;  // restart after a loss instead of staying lost
  bool progress = false;      // frame count on stderr
};

struct VoRunResult {
  std::filesystem::path out;       // the folder written
  nlohmann::ordered_json summary;  // summary.json as written
};

// InputError for bad input (a missing or malformed sequence, --out taken, bad intrinsics).
VoRunResult runVo(const VoJob& job);

// The one line `tgnav vo` prints for a finished run.
std::string voSummaryLine(const VoRunResult& result);

}  // namespace tgnav::harness
