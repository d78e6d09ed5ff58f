#include "harness/run/views_run.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "harness/base/errors.h"
#include "harness/base/files.h"
#include "harness/config/scenario.h"
#include "harness/config/yaml_util.h"
#include "harness/io/staged_output.h"
#include "harness/run/frame_prediction.h"
#include "harness/run/map_cache.h"
#include "harness/run/plan_run.h"
#include "vo/tum.h"

namespace tgnav::harness {

namespace {

namespace fs = std::filesystem;

// A vo.csv frame's time may differ from its gt.tum pose's by the rounding of vo.csv's 6 decimals.
constexpr double kTimeTolerance_s = 1e-4;

struct VoRow {
  double t_s = 0.0;
  double detections = 0.0;  // predicted_detections as flown
};

// vo.csv's time and predicted_detections columns, by the header's names.
std::vector<VoRow> readVoCsv(const fs::path& file) {
  std::istringstream in(readTextFile(file));
  std::string line;
  if (!std::getline(in, line)) throw InputError(file.string() + ": empty (a trial's vo.csv has a header)");
  std::vector<std::string> header;
  {
    std::istringstream h(line);
    for (std::string name; std::getline(h, name, ',');) header.push_back(name);
  }
  const auto column = [&](const std::string& name) {
    const auto it = std::find(header.begin(), header.end(), name);
    if (it == header.end()) throw InputError(file.string() + ": no column '" + name + "' (not a trial's vo.csv)");
    return static_cast<std::size_t>(it - header.begin());
  };
  const std::size_t t_col = column("t");
  const std::size_t d_col = column("predicted_detections");
  std::vector<VoRow> rows;
  for (int n = 2; std::getline(in, line); ++n) {
    if (line.empty()) continue;
    std::vector<std::string> cells;
    std::istringstream r(line);
    for (std::string cell; std::getline(r, cell, ',');) cells.push_back(cell);
    const auto number = [&](std::size_t col, const char* name) {
      const std::string cell = col < cells.size() ? cells[col] : "";
      try {
        std::size_t used = 0;
        const double v = std::stod(cell, &used);
        if (used == cell.size() && std::isfinite(v)) return v;
      } catch (const std::exception&) {
      }
      throw InputError(file.string() + ": line " + std::to_string(n) + ": " + name + " '" + cell + "' is not a number");
    };
    rows.push_back({number(t_col, "t"), number(d_col, "predicted_detections")});
  }
  return rows;  // none: a trial that never flew (no plan), whose views are a header alone
}

std::vector<vo::StampedPose> readGroundTruth(const fs::path& file) {
  std::vector<vo::StampedPose> poses;
  try {
    poses = vo::parseTum(readTextFile(file));
  } catch (const std::invalid_argument& e) {
    throw InputError(file.string() + ": " + e.what());
  }
  if (poses.empty()) throw InputError(file.string() + ": no poses");
  for (std::size_t i = 1; i < poses.size(); ++i) {
    if (!(poses[i].t_s > poses[i - 1].t_s)) {
      throw InputError(file.string() + ": timestamps not increasing at " + std::to_string(poses[i].t_s) + " s");
    }
  }
  return poses;
}

// The pose of `gt` at time t (within kTimeTolerance_s), or nullptr. The trial's last frame may
// come one log step after the flight log's last pose: that pose stands for it.
const vo::StampedPose* poseAt(const std::vector<vo::StampedPose>& gt, double t_s) {
  if (gt.size() >= 2 && t_s > gt.back().t_s) {
    const double step = gt.back().t_s - gt[gt.size() - 2].t_s;
    return t_s - gt.back().t_s <= step + kTimeTolerance_s ? &gt.back() : nullptr;
  }
  auto it = std::lower_bound(gt.begin(), gt.end(), t_s, [](const vo::StampedPose& p, double t) { return p.t_s < t; });
  const vo::StampedPose* best = nullptr;
  if (it != gt.end()) best = &*it;
  if (it != gt.begin() && (best == nullptr || t_s - std::prev(it)->t_s < best->t_s - t_s)) best = &*std::prev(it);
  return best != nullptr && std::abs(best->t_s - t_s) <= kTimeTolerance_s ? best : nullptr;
}

}  // namespace

ViewsResult runViews(const ViewsJob& job) {
  const fs::path config = job.trial / "config.yaml";
  if (!isRegularFile(config)) {
    throw InputError("--trial: " + job.trial.string() + " holds no config.yaml (not a trial)");
  }
  if (job.out.empty()) throw InputError("--out: required");
  if (!job.force && fs::exists(job.out)) {
    throw InputError("--out: " + job.out.string() + " exists; use --force to replace it");
  }
  const YamlDoc overrides = YamlDoc::fromOverrides(job.set);
  const Scenario scenario = loadScenario(config, &overrides);
  const std::vector<VoRow> rows = readVoCsv(job.trial / "vo.csv");
  const std::vector<vo::StampedPose> gt =
      rows.empty() ? std::vector<vo::StampedPose>{} : readGroundTruth(job.trial / "gt.tum");
  std::vector<const vo::StampedPose*> poses;
  poses.reserve(rows.size());
  for (const VoRow& row : rows) {
    const vo::StampedPose* p = poseAt(gt, row.t_s);
    if (p == nullptr) {
      char t[32];
      std::snprintf(t, sizeof t, "%.6f", row.t_s);
      throw InputError((job.trial / "gt.tum").string() + ": no pose at t = " + t + " s, a frame of vo.csv");
    }
    poses.push_back(p);
  }

  const planner::FeatureMap map = loadSceneFeatureMap(scenario.scene, job.map, job.map_cache, "tgnav views");
  PlanRun run;
  buildPlanningVoxels(scenario, map, &run);
  const planner::PerceptionPlannerConfig& model = scenario.planner.perception;
  std::ostringstream out;
  {
    // The settings the columns were computed with, for the model fitted on them (its
    // view_settings, harness/config/track_model_file.h).
    char settings[256];
    std::snprintf(settings, sizeof settings,
                  "# view_settings: hfov_rad=%.17g vfov_rad=%.17g min_range_m=%.17g max_range_m=%.17g "
                  "max_incidence_rad=%.17g sight_to_face=%d\n",
                  model.visibility.hfov_rad, model.visibility.vfov_rad, model.visibility.min_range_m,
                  model.visibility.max_range_m, model.information.max_incidence_rad,
                  model.visibility.sight_to_face ? 1 : 0);
    out << settings;
  }
  out.precision(6);
  out << std::fixed << "t," << kPredictionColumns << '\n';
  ViewsResult result;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const FramePrediction f = predictFrame(*run.voxels, poses[i]->X_WC, model.visibility, model.information);
    out << rows[i].t_s << ',';
    writePredictionColumns(out, f);
    out << '\n';
    result.mean_detections += f.support.detections;
    result.mean_detections_vo += rows[i].detections;
  }
  writeFileAtomic(job.out, out.str());
  result.frames = static_cast<int>(rows.size());
  result.mean_detections /= std::max(1, result.frames);
  result.mean_detections_vo /= std::max(1, result.frames);
  char line[512];
  std::snprintf(line, sizeof line,
                "tgnav views: %d frames of %s at their true camera poses: mean predicted detections %.1f (as flown "
                "%.1f) -> %s",
                result.frames, job.trial.string().c_str(), result.mean_detections, result.mean_detections_vo,
                job.out.string().c_str());
  result.summary = line;
  return result;
}

}  // namespace tgnav::harness
