#include "harness/run/eval_run.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "harness/base/errors.h"
#include "harness/base/files.h"
#include "harness/io/staged_output.h"
#include "vo/metrics.h"
#include "vo/text_fields.h"
#include "vo/trajectory_formats.h"

namespace tgnav::harness {

namespace {

namespace fs = std::filesystem;
using vo::text::str;

struct Settings {
  vo::TrajectoryFormat format = vo::TrajectoryFormat::kTum;
  vo::Alignment align = vo::Alignment::kSe3;
  vo::RpeUnit rpe_unit = vo::RpeUnit::kMetres;
};

Settings checkedSettings(const EvalJob& job) {
  Settings s;
  try {
    s.format = vo::parseTrajectoryFormat(job.format);
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string("--format: ") + e.what());
  }
  try {
    s.align = vo::parseAlignment(job.align);
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string("--align: ") + e.what());
  }
  if (job.rpe_unit == "frames") {
    s.rpe_unit = vo::RpeUnit::kFrames;
  } else if (job.rpe_unit != "m") {
    throw InputError("--rpe-unit: '" + job.rpe_unit + "' is not a unit; expected m or frames");
  }
  const double d = job.rpe_delta;
  if (s.rpe_unit == vo::RpeUnit::kFrames && !(d >= 1.0 && d <= 1e9 && d == std::floor(d))) {
    throw InputError("--rpe-delta: " + str(d) + " is not a whole number of frames >= 1 (--rpe-unit frames)");
  }
  if (s.rpe_unit == vo::RpeUnit::kMetres && !(d > 0.0 && std::isfinite(d))) {
    throw InputError("--rpe-delta: " + str(d) + " is not a distance > 0 in metres (--rpe-unit m)");
  }
  if (!(job.max_dt_s >= 0.0 && std::isfinite(job.max_dt_s))) {
    throw InputError("--max-dt: " + str(job.max_dt_s) + " is not a time >= 0 in seconds");
  }
  return s;
}

// The poses of `file`; errors name the file and line ("est.txt:3: expected 8 numbers (...), got 12
// (read as --format tum)").
std::vector<vo::StampedPose> readTrajectory(const fs::path& file, vo::TrajectoryFormat format) {
  const std::string text = readTextFile(file);
  std::vector<vo::StampedPose> poses;
  try {
    poses = vo::parseTrajectory(text, format);
  } catch (const std::invalid_argument& e) {
    // A wrong count of numbers on a line is most often a file of another format.
    const std::string message = inFile(file.string(), e.what());
    const bool count = message.find(": expected ") != std::string::npos;
    throw InputError(message + (count ? std::string(" (read as --format ") + toString(format) + ")" : ""));
  }
  if (poses.empty()) throw InputError(file.string() + ": no poses (an empty trajectory)");
  return poses;
}

// The earliest and latest timestamps (files need not be in time order).
std::string timeSpan(const std::vector<vo::StampedPose>& poses) {
  const auto [first, last] = std::minmax_element(
      poses.begin(), poses.end(), [](const vo::StampedPose& a, const vo::StampedPose& b) { return a.t_s < b.t_s; });
  return "t " + str(first->t_s) + " .. " + str(last->t_s) + " s";
}

// Pairs by time, or by line for KITTI (whose timestamps are the line indices).
std::vector<vo::PosePair> associated(const EvalJob& job, vo::TrajectoryFormat format,
                                     const std::vector<vo::StampedPose>& ref, const std::vector<vo::StampedPose>& est) {
  if (format == vo::TrajectoryFormat::kKitti) {
    if (est.size() != ref.size()) {
      throw InputError(job.est.string() + ": " + std::to_string(est.size()) + " poses but " + job.ref.string() +
                       " has " + std::to_string(ref.size()) +
                       "; KITTI poses are paired by line, so both files need as many");
    }
    return vo::associate(est, ref, 0.0);
  }
  std::vector<vo::PosePair> pairs = vo::associate(est, ref, job.max_dt_s);
  if (pairs.empty()) {
    throw InputError(job.est.string() + ": no pose within --max-dt " + str(job.max_dt_s) + " s of a pose of " +
                     job.ref.string() + " (estimate " + timeSpan(est) + ", reference " + timeSpan(ref) + ")");
  }
  return pairs;
}

nlohmann::ordered_json alignmentJson(const vo::Similarity3& S) {
  nlohmann::ordered_json rotation = nlohmann::ordered_json::array();
  for (int r = 0; r < 3; ++r) rotation.push_back({S.R(r, 0), S.R(r, 1), S.R(r, 2)});
  return {{"rotation", rotation}, {"translation", {S.t.x(), S.t.y(), S.t.z()}}, {"scale", S.scale}};
}

// NaN statistics (no RPE pair) are written as null, as nlohmann::json does.
nlohmann::ordered_json summaryJson(const EvalJob& job, const Settings& s, const std::vector<vo::StampedPose>& ref,
                                   const std::vector<vo::StampedPose>& est, const vo::ApeResult& ape,
                                   const vo::RpeStatistics& rpe) {
  const vo::ErrorStatistics& a = ape.stats_m;
  nlohmann::ordered_json j;
  j["ref"] = fs::absolute(job.ref).lexically_normal().string();
  j["est"] = fs::absolute(job.est).lexically_normal().string();
  j["format"] = toString(s.format);
  j["align"] = toString(s.align);
  j["max_dt_s"] = nullptr;  // KITTI: paired by line
  if (s.format != vo::TrajectoryFormat::kKitti) j["max_dt_s"] = job.max_dt_s;
  j["ref_poses"] = ref.size();
  j["est_poses"] = est.size();
  j["ref_non_increasing"] = vo::nonIncreasingTimes(ref);
  j["est_non_increasing"] = vo::nonIncreasingTimes(est);
  j["pairs"] = a.n;
  j["alignment"] = alignmentJson(ape.alignment);
  j["ate"] = {{"rmse_m", a.rmse}, {"mean_m", a.mean}, {"median_m", a.median}, {"std_m", a.std},
              {"min_m", a.min},   {"max_m", a.max},   {"sse_m2", a.sse}};
  j["rpe"] = {{"delta", rpe.delta},
              {"unit", rpe.unit == vo::RpeUnit::kFrames ? "frames" : "m"},
              {"pairs", rpe.trans_m.n},
              {"trans_rmse_m", rpe.trans_m.rmse},
              {"trans_mean_m", rpe.trans_m.mean},
              {"rot_rmse_deg", rpe.rot_rad.rmse * 180.0 / M_PI}};
  j["ref_path_length_m"] = vo::pathLength(ref);
  return j;
}

// One row per pair: time, reference and aligned estimate positions, error, distance along the
// reference (through the paired poses).
std::string pairsCsv(const std::vector<vo::PosePair>& aligned, const std::vector<double>& errors_m) {
  std::string out = "t,ref_x,ref_y,ref_z,est_x,est_y,est_z,error_m,distance_m\n";
  double distance = 0.0;
  for (std::size_t i = 0; i < aligned.size(); ++i) {
    const Eigen::Vector3d& ref = aligned[i].X_WC_gt.translation();
    const Eigen::Vector3d& est = aligned[i].X_WC_est.translation();
    if (i > 0) distance += (ref - aligned[i - 1].X_WC_gt.translation()).norm();
    for (const double v : {aligned[i].t_s, ref.x(), ref.y(), ref.z(), est.x(), est.y(), est.z(), errors_m[i]}) {
      vo::text::appendNumber(out, v);
      out.push_back(',');
    }
    vo::text::appendNumber(out, distance);
    out.push_back('\n');
  }
  return out;
}

}  // namespace

EvalResult runEval(const EvalJob& job) {
  const Settings settings = checkedSettings(job);
  EvalResult result;
  result.figure_format = job.figure_format;
  if (!job.out.empty()) result.out = newOutputDir(job.out, "tgnav eval");
  const std::vector<vo::StampedPose> ref = readTrajectory(job.ref, settings.format);
  const std::vector<vo::StampedPose> est = readTrajectory(job.est, settings.format);
  const std::vector<vo::PosePair> pairs = associated(job, settings.format, ref, est);
  const vo::ApeResult ape = vo::absolutePoseError(pairs, settings.align);
  // RPE of the aligned estimate: a rigid alignment leaves it unchanged, sim3's scale does not.
  const std::vector<vo::PosePair> aligned = vo::alignedPairs(pairs, ape.alignment);
  const vo::RpeStatistics rpe = vo::rpeStatistics(aligned, job.rpe_delta, settings.rpe_unit);
  result.summary = summaryJson(job, settings, ref, est, ape, rpe);
  for (const auto& [file, key] :
       {std::pair{&job.ref, "ref_non_increasing"}, std::pair{&job.est, "est_non_increasing"}}) {
    const int n = result.summary[key].get<int>();
    if (n > 0) {
      result.warnings.push_back("tgnav eval: warning: " + file->string() + ": " + std::to_string(n) +
                                " of its timestamps repeat or go back; poses are paired by evo's rule (nearest in "
                                "time, ties to the first in the file)");
    }
  }
  if (result.out.empty()) return result;

  StagedDir staged(result.out);
  writeFileAtomic(staged.staging() / "eval.json", result.summary.dump(2) + "\n");
  writeFileAtomic(staged.staging() / "eval_pairs.csv", pairsCsv(aligned, ape.errors_m));
  result.figures = drawFigures("eval", staged.staging(), job.figure_format);
  staged.commit(OnExisting::kRefuse, "evaluating");
  return result;
}

std::string evalSummaryLine(const EvalResult& r) {
  const nlohmann::ordered_json& j = r.summary;
  const nlohmann::ordered_json& ate = j["ate"];
  const nlohmann::ordered_json& rpe = j["rpe"];
  std::ostringstream line;
  line.precision(4);
  line << "tgnav eval: " << j["pairs"].get<int>() << " pairs of " << j["est_poses"].get<std::size_t>() << " estimates ("
       << j["format"].get<std::string>() << ", " << j["align"].get<std::string>() << "): ATE rmse "
       << ate["rmse_m"].get<double>() << " m (mean " << ate["mean_m"].get<double>() << ", median "
       << ate["median_m"].get<double>() << ", max " << ate["max_m"].get<double>() << ")";
  if (j["align"] == "sim3") line << ", scale " << j["alignment"]["scale"].get<double>();
  line << "; RPE (" << rpe["delta"].get<double>() << " " << rpe["unit"].get<std::string>() << ") ";
  if (rpe["pairs"].get<int>() > 0) {
    line << "rmse " << rpe["trans_rmse_m"].get<double>() << " m, " << rpe["rot_rmse_deg"].get<double>() << " deg over "
         << rpe["pairs"].get<int>() << " pairs";
  } else {
    line << "no pairs that far apart";
  }
  line << "; reference path " << j["ref_path_length_m"].get<double>() << " m";
  if (!r.out.empty()) {
    line << " -> " << r.out.string() << "/{eval.json,eval_pairs.csv,eval." << toString(r.figure_format) << "}";
  }
  return line.str();
}

}  // namespace tgnav::harness
