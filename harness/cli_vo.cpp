// tgnav vo: run the RGB-D visual odometry over a TUM RGB-D sequence folder (recorded by
// `tgnav fly --record` or one of TUM's own) and score it against the ground truth.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>
#include <system_error>

#include "harness/cli.h"
#include "harness/config_io.h"
#include "harness/errors.h"
#include "harness/output.h"
#include "harness/tum_sequence.h"
#include "vo/metrics.h"
#include "vo/odometry.h"
#include "vo/tum.h"

namespace tgnav::cli {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr double kRpeDeltaM = 1.0;

struct VoOptions {
  std::string sequence;
  std::string out;
  std::string config;
  std::string intrinsics;
  bool reinitialise = false;
};

// The odometry settings in force, in loadOdometryConfig's keys.
nlohmann::ordered_json resolvedConfig(const vo::OdometryConfig& c) {
  const vo::FeatureConfig& f = c.features;
  nlohmann::ordered_json j;
  j["features"] = {
      {"max_features", f.max_features},          {"grid_cols", f.grid_cols},       {"grid_rows", f.grid_rows},
      {"fast_threshold", f.fast_threshold},      {"scale_factor", f.scale_factor}, {"pyramid_levels", f.pyramid_levels},
      {"edge_threshold_px", f.edge_threshold_px}};
  j["min_depth_m"] = c.min_depth_m;
  j["max_depth_m"] = c.max_depth_m;
  j["depth_edge_m"] = c.depth_edge_m;
  j["init_min_features"] = c.init_min_features;
  j["min_inliers"] = c.min_inliers;
  j["weak_inliers"] = c.weak_inliers;
  j["search_radius_px"] = c.search_radius_px;
  j["max_descriptor_distance"] = c.max_descriptor_distance;
  j["ratio_test"] = c.ratio_test;
  j["ransac_reprojection_px"] = c.ransac_reprojection_px;
  j["ransac_iterations"] = c.ransac_iterations;
  j["ransac_confidence"] = c.ransac_confidence;
  j["local_map_keyframes"] = c.local_map_keyframes;
  j["keyframe_inlier_ratio"] = c.keyframe_inlier_ratio;
  j["keyframe_translation_m"] = c.keyframe_translation_m;
  j["keyframe_rotation_rad"] = c.keyframe_rotation_rad;
  j["landmark_max_misses"] = c.landmark_max_misses;
  j["reinitialise_after_lost"] = c.reinitialise_after_lost;
  return j;
}

// Ground truth at time t: interpolated inside its span (linear position, slerp rotation), the
// end pose within kMaxPairDtS outside it; nothing otherwise.
bool groundtruthAt(const std::vector<vo::StampedPose>& gt, double t, Eigen::Isometry3d* X_WC) {
  if (gt.empty()) return false;
  if (t <= gt.front().t_s || t >= gt.back().t_s) {
    const vo::StampedPose& end = t <= gt.front().t_s ? gt.front() : gt.back();
    if (std::abs(end.t_s - t) >= harness::kMaxPairDtS) return false;
    *X_WC = end.X_WC;
    return true;
  }
  const auto next =
      std::lower_bound(gt.begin(), gt.end(), t, [](const vo::StampedPose& p, double time) { return p.t_s < time; });
  const vo::StampedPose& b = *next;
  const vo::StampedPose& a = *(next - 1);
  const double s = (t - a.t_s) / (b.t_s - a.t_s);
  const Eigen::Quaterniond qa(a.X_WC.linear());
  const Eigen::Quaterniond qb(b.X_WC.linear());
  *X_WC = Eigen::Isometry3d::Identity();
  X_WC->linear() = qa.slerp(s, qb).normalized().toRotationMatrix();
  X_WC->translation() = (1.0 - s) * a.X_WC.translation() + s * b.X_WC.translation();
  return true;
}

std::string csvField(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c == '\n' ? ' ' : c);
  return quoted + "\"";
}

nlohmann::ordered_json numberOrNull(double v) {
  return std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json(nullptr);
}

void runVo(const VoOptions& opt) {
  fs::path out = fs::absolute(opt.out).lexically_normal();
  if (!out.has_filename()) out = out.parent_path();  // "out/" is "out"
  if (!out.has_filename() || out.filename() == "..") {
    throw InputError("--out: '" + opt.out + "' is not a name for a new directory");
  }
  std::error_code ec;
  if (fs::exists(out, ec)) {
    throw InputError("--out: " + opt.out + " already exists; tgnav vo writes a new directory and never overwrites");
  }
  vo::OdometryConfig config;
  if (!opt.config.empty()) config = harness::loadOdometryConfig(opt.config);
  if (opt.reinitialise) config.reinitialise_after_lost = true;

  harness::Sequence seq = harness::loadSequence(opt.sequence);
  vo::CameraIntrinsics camera;
  std::string intrinsics_source;
  if (!opt.intrinsics.empty()) {
    const std::vector<double> k = parseNumbers(opt.intrinsics, 4, "--intrinsics", "fx,fy,cx,cy (pixels)");
    if (!(k[0] > 0.0) || !(k[1] > 0.0)) {
      throw InputError("--intrinsics: '" + opt.intrinsics + "': fx and fy must be > 0");
    }
    // The image size comes from the first frame; the sequence's own intrinsics.yaml is ignored.
    seq.intrinsics.reset();
    const harness::SequenceImages first = harness::loadFrame(seq, 0);
    camera = vo::CameraIntrinsics{first.bgr.cols, first.bgr.rows, k[0], k[1], k[2], k[3]};
    intrinsics_source = "--intrinsics";
  } else if (seq.intrinsics) {
    camera = *seq.intrinsics;
    intrinsics_source = (seq.dir / "intrinsics.yaml").string();
  } else {
    throw InputError((seq.dir / "intrinsics.yaml").string() +
                     ": missing; give the camera as --intrinsics fx,fy,cx,cy (TUM fr1, for example: "
                     "517.3,516.5,318.6,255.3)");
  }

  Eigen::Isometry3d X_WC0 = Eigen::Isometry3d::Identity();
  const bool start_from_gt = groundtruthAt(seq.groundtruth, seq.frames.front().t_s, &X_WC0);
  vo::RgbdOdometry odometry(camera, config, X_WC0);

  const bool tty = isatty(fileno(stderr)) != 0;
  const auto wall0 = Clock::now();
  double track_s = 0.0;
  double track_max_s = 0.0;
  double load_s = 0.0;
  int counts[3] = {0, 0, 0};  // ok, weak, lost
  int keyframes = 0;
  int reinitialisations = 0;
  std::vector<vo::StampedPose> est;
  std::ostringstream status;
  status << "t,status,features,with_depth,matches,inliers,keyframe,reason\n";
  const std::size_t n = seq.frames.size();
  for (std::size_t i = 0; i < n; ++i) {
    const auto t_load = Clock::now();
    const harness::SequenceImages images = harness::loadFrame(seq, i);
    const harness::SequenceEntry& e = seq.frames[i];
    if (images.bgr.cols != camera.width_px || images.bgr.rows != camera.height_px) {
      std::ostringstream msg;
      msg << e.rgb.string() << " (rgb.txt:" << e.rgb_line << "): image is " << images.bgr.cols << "x" << images.bgr.rows
          << " but the first frame is " << camera.width_px << "x" << camera.height_px;
      throw InputError(msg.str());
    }
    const auto t_track = Clock::now();
    load_s += std::chrono::duration<double>(t_track - t_load).count();
    const vo::FrameResult r = odometry.track(e.t_s, images.bgr, images.depth_m);
    const double dt = std::chrono::duration<double>(Clock::now() - t_track).count();
    track_s += dt;
    track_max_s = std::max(track_max_s, dt);

    ++counts[r.status == vo::TrackingStatus::kOk ? 0 : r.status == vo::TrackingStatus::kWeak ? 1 : 2];
    keyframes += r.keyframe ? 1 : 0;
    reinitialisations += r.reinitialised ? 1 : 0;
    if (r.status != vo::TrackingStatus::kLost) est.push_back(vo::StampedPose{e.t_s, r.X_WC});
    char t_text[64];
    std::snprintf(t_text, sizeof(t_text), "%.6f", e.t_s);
    status << t_text << ',' << vo::toString(r.status) << ',' << r.features << ',' << r.with_depth << ',' << r.matches
           << ',' << r.inliers << ',' << (r.keyframe ? 1 : 0) << ',' << csvField(r.reason) << '\n';
    if (tty && ((i + 1) % 50 == 0 || i + 1 == n)) {
      std::fprintf(stderr, "\rtgnav vo: %zu/%zu frames", i + 1, n);
    }
  }
  if (tty) std::fprintf(stderr, "\n");
  const double wall_s = std::chrono::duration<double>(Clock::now() - wall0).count();

  nlohmann::ordered_json j;
  j["sequence"] = opt.sequence;
  j["frames"] = n;
  j["ok"] = counts[0];
  j["weak"] = counts[1];
  j["lost"] = counts[2];
  j["failed_at_s"] = numberOrNull(odometry.failedAt());
  j["keyframes"] = keyframes;
  j["reinitialise_after_lost"] = config.reinitialise_after_lost;
  j["reinitialisations"] = reinitialisations;
  j["unpaired_rgb"] = seq.unpaired_rgb;
  j["unpaired_depth"] = seq.unpaired_depth;
  j["intrinsics"] = {{"source", intrinsics_source},
                     {"width", camera.width_px},
                     {"height", camera.height_px},
                     {"fx", camera.fx},
                     {"fy", camera.fy},
                     {"cx", camera.cx},
                     {"cy", camera.cy}};
  j["initial_pose"] = start_from_gt ? "groundtruth" : "identity";
  j["config"] = opt.config.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(opt.config);
  j["odometry_config"] = resolvedConfig(config);
  j["groundtruth"] = seq.has_groundtruth;

  // Trajectory metrics over the tracked frames (null without ground truth or tracked frames).
  const double nan = std::nan("");
  double ate_aligned = nan;
  double ate_anchored = nan;
  double distance = nan;
  double goal = nan;
  vo::RpeResult rpe;
  rpe.trans_rmse_m = rpe.trans_rmse_percent = rpe.rot_rmse_rad = nan;
  std::size_t pairs_n = 0;
  if (seq.has_groundtruth) {
    const std::vector<vo::PosePair> pairs = vo::associate(est, seq.groundtruth, harness::kMaxPairDtS);
    pairs_n = pairs.size();
    if (!pairs.empty()) {
      ate_aligned = vo::absoluteTrajectoryError(pairs, true).rmse_m;
      ate_anchored = vo::absoluteTrajectoryError(pairs, false).rmse_m;
      distance = vo::distanceTravelled(pairs);
      goal = vo::goalError(pairs);
      rpe = vo::relativePoseError(pairs, kRpeDeltaM);
      if (rpe.pairs == 0) rpe.trans_rmse_m = rpe.trans_rmse_percent = rpe.rot_rmse_rad = nan;
    }
  }
  j["evaluated_pairs"] = pairs_n;
  j["ate_rmse_aligned_m"] = numberOrNull(ate_aligned);
  j["ate_rmse_anchored_m"] = numberOrNull(ate_anchored);
  j["rpe_delta_m"] = kRpeDeltaM;
  j["rpe_pairs"] = rpe.pairs;
  j["rpe_trans_rmse_m"] = numberOrNull(rpe.trans_rmse_m);
  j["rpe_trans_rmse_percent"] = numberOrNull(rpe.trans_rmse_percent);
  j["rpe_rot_rmse_deg"] = numberOrNull(rpe.rot_rmse_rad * 180.0 / M_PI);
  j["distance_travelled_m"] = numberOrNull(distance);
  j["goal_error_m"] = numberOrNull(goal);
  j["ms_per_frame"] = n > 0 ? 1e3 * track_s / n : 0.0;
  j["ms_per_frame_max"] = 1e3 * track_max_s;
  j["load_ms_per_frame"] = n > 0 ? 1e3 * load_s / n : 0.0;
  j["wall_time_s"] = wall_s;

  // Everything into a sibling temp dir, renamed to `out` only when complete.
  const fs::path tmp = out.string() + ".partial";
  if (fs::is_directory(tmp, ec)) fs::remove_all(tmp, ec);
  harness::makeOutputDir(tmp);
  try {
    harness::writeFileAtomic(tmp / "est.tum", vo::toTum(est));
    harness::writeFileAtomic(tmp / "status.csv", status.str());
    harness::writeFileAtomic(tmp / "summary.json", j.dump(2) + "\n");
    if (fs::exists(out, ec)) throw InputError("--out: " + opt.out + " appeared while the odometry ran");
    fs::rename(tmp, out);
  } catch (...) {
    fs::remove_all(tmp, ec);
    throw;
  }

  std::ostringstream line;
  line.precision(3);
  line << std::fixed << "tgnav vo: " << n << " frames: " << counts[0] << " ok, " << counts[1] << " weak, " << counts[2]
       << " lost";
  if (odometry.failed()) line << " (first lost at " << odometry.failedAt() << " s)";
  if (std::isfinite(ate_aligned)) {
    line << "; ATE rmse " << ate_aligned << " m aligned, " << ate_anchored << " m anchored";
    if (std::isfinite(rpe.trans_rmse_percent)) line << ", RPE(1 m) " << rpe.trans_rmse_percent << " %";
    line << ", goal error " << goal << " m over " << distance << " m";
  } else if (seq.has_groundtruth) {
    line << "; no tracked frame to evaluate";
  } else {
    line << "; no ground truth";
  }
  line.precision(1);
  line << "; " << (n > 0 ? 1e3 * track_s / n : 0.0) << " ms/frame -> " << out.string()
       << "/{est.tum,status.csv,summary.json}";
  std::printf("%s\n", line.str().c_str());
}

}  // namespace

void addVoCommand(CLI::App& app) {
  auto opt = std::make_shared<VoOptions>();
  CLI::App* cmd = app.add_subcommand("vo", "Run the RGB-D visual odometry over a TUM RGB-D sequence and score it");
  cmd->add_option("--sequence", opt->sequence,
                  "TUM RGB-D sequence folder (rgb.txt, depth.txt, rgb/, depth/, optional groundtruth.txt and "
                  "intrinsics.yaml), e.g. from tgnav fly --record")
      ->required();
  cmd->add_option("--out", opt->out, "Output directory (must not exist)")->required();
  cmd->add_option("--config", opt->config,
                  "Odometry YAML: fields of vo::OdometryConfig (features: vo::FeatureConfig); default built-in");
  cmd->add_option("--intrinsics", opt->intrinsics,
                  "fx,fy,cx,cy in pixels, for sequences without intrinsics.yaml (overrides it otherwise)");
  cmd->add_flag("--reinitialise", opt->reinitialise, "Restart the odometry after it is lost (default: stay lost)");
  cmd->callback([opt] { runVo(*opt); });
}

}  // namespace tgnav::cli
