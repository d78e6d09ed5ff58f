#include "harness/run/vo_run.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <system_error>

#include "harness/base/errors.h"
#include "harness/config/config_io.h"
#include "harness/config/values.h"
#include "harness/io/staged_output.h"
#include "harness/io/tum_sequence.h"
#include "vo/metrics.h"
#include "vo/tum.h"

namespace tgnav::harness {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr double kRpeDeltaM = 1.0;

// Ground truth at time t: interpolated inside its span (linear position, slerp rotation), the
// end pose within kMaxPairDtS outside it; nothing otherwise.
std::string nonIncreasingWarning(const Sequence& seq) {
  return "tgnav vo: warning: " + (seq.dir / "groundtruth.txt").string() + ": " +
         std::to_string(seq.groundtruth_non_increasing) +
         " of its timestamps repeat or go back; poses are paired by evo's rule (nearest in time, ties to the first in "
         "the file)";
}

// `gt` in time order (ties in any order).
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

struct SequenceCamera {
  vo::CameraIntrinsics intrinsics;
  std::string source;  // where it came from
};

// From --intrinsics (the image size from the first frame) or the sequence's intrinsics.yaml.
SequenceCamera sequenceCamera(Sequence* seq, const std::string& intrinsics) {
  if (!intrinsics.empty()) {
    const std::vector<double> k = parseNumbers(intrinsics, 4, "--intrinsics", "fx,fy,cx,cy (pixels)");
    if (!(k[0] > 0.0) || !(k[1] > 0.0)) {
      throw InputError("--intrinsics: '" + intrinsics + "': fx and fy must be > 0");
    }
    // The sequence's own intrinsics.yaml is ignored.
    seq->intrinsics.reset();
    const SequenceImages first = loadFrame(*seq, 0);
    return {vo::CameraIntrinsics{first.bgr.cols, first.bgr.rows, k[0], k[1], k[2], k[3]}, "--intrinsics"};
  }
  if (seq->intrinsics) return {*seq->intrinsics, (seq->dir / "intrinsics.yaml").string()};
  throw InputError((seq->dir / "intrinsics.yaml").string() +
                   ": missing; give the camera as --intrinsics fx,fy,cx,cy (TUM fr1, for example: "
                   "517.3,516.5,318.6,255.3)");
}

// What the odometry did over the sequence.
struct Tracking {
  std::vector<vo::StampedPose> est;  // tracked frames
  std::string status_csv;
  int counts[3] = {0, 0, 0};  // ok, weak, lost
  int keyframes = 0;
  std::map<std::string, int> keyframe_rules;  // how often each rule fired at a keyframe
  int reinitialisations = 0;
  vo::FrameResult::Timing cpu;  // CPU seconds per stage, summed
  double track_s = 0.0;
  double track_max_s = 0.0;
  double load_s = 0.0;
  double wall_s = 0.0;
};

void checkFrameSize(const SequenceEntry& e, const SequenceImages& images, const vo::CameraIntrinsics& camera) {
  if (images.bgr.cols == camera.width_px && images.bgr.rows == camera.height_px) return;
  std::ostringstream msg;
  msg << e.rgb.string() << " (rgb.txt:" << e.rgb_line << "): image is " << images.bgr.cols << "x" << images.bgr.rows
      << " but the first frame is " << camera.width_px << "x" << camera.height_px;
  throw InputError(msg.str());
}

void record(const SequenceEntry& e, const vo::FrameResult& r, Tracking* t) {
  ++t->counts[r.status == vo::TrackingStatus::kOk ? 0 : r.status == vo::TrackingStatus::kWeak ? 1 : 2];
  t->keyframes += r.keyframe ? 1 : 0;
  for (std::size_t b = 0, e = 0; b < r.keyframe_rule.size(); b = e + 1) {
    e = std::min(r.keyframe_rule.find('+', b), r.keyframe_rule.size());
    ++t->keyframe_rules[r.keyframe_rule.substr(b, e - b)];
  }
  t->cpu.features_s += r.cpu.features_s;
  t->cpu.matching_s += r.cpu.matching_s;
  t->cpu.pnp_s += r.cpu.pnp_s;
  t->cpu.map_s += r.cpu.map_s;
  t->cpu.ba_s += r.cpu.ba_s;
  t->reinitialisations += r.reinitialised ? 1 : 0;
  if (r.status != vo::TrackingStatus::kLost) t->est.push_back(vo::StampedPose{e.t_s, r.X_WC});
  char t_text[64];
  std::snprintf(t_text, sizeof(t_text), "%.6f", e.t_s);
  std::ostringstream row;
  row << t_text << ',' << vo::toString(r.status) << ',' << r.features << ',' << r.with_depth << ',' << r.matches << ','
      << r.inliers << ',' << (r.keyframe ? 1 : 0) << ',' << r.keyframe_rule << ',' << csvField(r.reason) << '\n';
  t->status_csv += row.str();
}

Tracking trackSequence(const Sequence& seq, const vo::CameraIntrinsics& camera, vo::RgbdOdometry* odometry,
                       bool progress) {
  Tracking t;
  t.status_csv = "t,status,features,with_depth,matches,inliers,keyframe,keyframe_rule,reason\n";
  const auto wall0 = Clock::now();
  const std::size_t n = seq.frames.size();
  for (std::size_t i = 0; i < n; ++i) {
    const auto t_load = Clock::now();
    const SequenceImages images = loadFrame(seq, i);
    const SequenceEntry& e = seq.frames[i];
    checkFrameSize(e, images, camera);
    const auto t_track = Clock::now();
    t.load_s += std::chrono::duration<double>(t_track - t_load).count();
    const vo::FrameResult r = odometry->track(e.t_s, images.bgr, images.depth_m);
    const double dt = std::chrono::duration<double>(Clock::now() - t_track).count();
    t.track_s += dt;
    t.track_max_s = std::max(t.track_max_s, dt);
    record(e, r, &t);
    if (progress && ((i + 1) % 50 == 0 || i + 1 == n)) std::fprintf(stderr, "\rtgnav vo: %zu/%zu frames", i + 1, n);
  }
  if (progress) std::fprintf(stderr, "\n");
  t.wall_s = std::chrono::duration<double>(Clock::now() - wall0).count();
  return t;
}

// Trajectory metrics over the tracked frames (null without ground truth or tracked frames).
void addTrajectoryMetrics(const Sequence& seq, const Tracking& t, nlohmann::ordered_json* j) {
  const double nan = std::nan("");
  double ate_aligned = nan, ate_anchored = nan, distance = nan, goal = nan;
  vo::RpeResult rpe;
  rpe.trans_rmse_m = rpe.trans_rmse_percent = rpe.rot_rmse_rad = nan;
  std::size_t pairs_n = 0;
  if (seq.has_groundtruth) {
    const std::vector<vo::PosePair> pairs = vo::associate(t.est, seq.groundtruth, kMaxPairDtS);
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
  (*j)["evaluated_pairs"] = pairs_n;
  (*j)["ate_rmse_aligned_m"] = numberOrNull(ate_aligned);
  (*j)["ate_rmse_anchored_m"] = numberOrNull(ate_anchored);
  (*j)["rpe_delta_m"] = kRpeDeltaM;
  (*j)["rpe_pairs"] = rpe.pairs;
  (*j)["rpe_trans_rmse_m"] = numberOrNull(rpe.trans_rmse_m);
  (*j)["rpe_trans_rmse_percent"] = numberOrNull(rpe.trans_rmse_percent);
  (*j)["rpe_rot_rmse_deg"] = numberOrNull(rpe.rot_rmse_rad * 180.0 / M_PI);
  (*j)["distance_travelled_m"] = numberOrNull(distance);
  (*j)["goal_error_m"] = numberOrNull(goal);
}

nlohmann::ordered_json summaryJson(const VoJob& job, const Sequence& seq, const SequenceCamera& camera,
                                   const vo::OdometryConfig& config, const vo::RgbdOdometry& odometry,
                                   bool start_from_gt, const Tracking& t) {
  const vo::CameraIntrinsics& k = camera.intrinsics;
  const std::size_t n = seq.frames.size();
  nlohmann::ordered_json j;
  j["sequence"] = job.sequence.string();
  j["frames"] = n;
  j["ok"] = t.counts[0];
  j["weak"] = t.counts[1];
  j["lost"] = t.counts[2];
  j["failed_at_s"] = numberOrNull(odometry.failedAt());
  j["keyframes"] = t.keyframes;
  j["keyframe_rules"] = t.keyframe_rules;  // a keyframe may count under several
  j["reinitialise_after_lost"] = config.reinitialise_after_lost;
  j["reinitialisations"] = t.reinitialisations;
  j["unpaired_rgb"] = seq.unpaired_rgb;
  j["unpaired_depth"] = seq.unpaired_depth;
  j["groundtruth_non_increasing"] = seq.groundtruth_non_increasing;
  j["intrinsics"] = {{"source", camera.source},
                     {"width", k.width_px},
                     {"height", k.height_px},
                     {"fx", k.fx},
                     {"fy", k.fy},
                     {"cx", k.cx},
                     {"cy", k.cy}};
  j["initial_pose"] = start_from_gt ? "groundtruth" : "identity";
  j["config"] = job.config.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(job.config);
  j["odometry_config"] = toJson(toYaml(config));
  j["groundtruth"] = seq.has_groundtruth;
  addTrajectoryMetrics(seq, t, &j);
  j["ms_per_frame"] = n > 0 ? 1e3 * t.track_s / n : 0.0;
  j["ms_per_frame_max"] = 1e3 * t.track_max_s;
  j["load_ms_per_frame"] = n > 0 ? 1e3 * t.load_s / n : 0.0;
  const double per_frame = n > 0 ? 1e3 / static_cast<double>(n) : 0.0;
  j["cpu_ms_per_frame"] = {{"features", t.cpu.features_s * per_frame},
                           {"matching", t.cpu.matching_s * per_frame},
                           {"pnp", t.cpu.pnp_s * per_frame},
                           {"map", t.cpu.map_s * per_frame},
                           {"ba", t.cpu.ba_s * per_frame},
                           {"total", t.cpu.total() * per_frame}};
  j["wall_time_s"] = t.wall_s;
  return j;
}

}  // namespace

VoRunResult runVo(const VoJob& job) {
  const fs::path out = newOutputDir(job.out, "tgnav vo");
  vo::OdometryConfig config;
  if (!job.config.empty()) config = loadOdometryConfig(job.config);
  if (job.reinitialise) config.reinitialise_after_lost = true;

  Sequence seq = loadSequence(job.sequence);
  if (seq.groundtruth_non_increasing > 0) std::fprintf(stderr, "%s\n", nonIncreasingWarning(seq).c_str());
  const SequenceCamera camera = sequenceCamera(&seq, job.intrinsics);
  Eigen::Isometry3d X_WC0 = Eigen::Isometry3d::Identity();
  std::vector<vo::StampedPose> by_time = seq.groundtruth;
  std::stable_sort(by_time.begin(), by_time.end(),
                   [](const vo::StampedPose& a, const vo::StampedPose& b) { return a.t_s < b.t_s; });
  const bool start_from_gt = groundtruthAt(by_time, seq.frames.front().t_s, &X_WC0);
  vo::RgbdOdometry odometry(camera.intrinsics, config, X_WC0);
  const Tracking tracking = trackSequence(seq, camera.intrinsics, &odometry, job.progress);

  VoRunResult result{out, summaryJson(job, seq, camera, config, odometry, start_from_gt, tracking)};
  StagedDir staged(out);
  writeFileAtomic(staged.staging() / "est.tum", vo::toTum(tracking.est));
  writeFileAtomic(staged.staging() / "status.csv", tracking.status_csv);
  writeFileAtomic(staged.staging() / "summary.json", result.summary.dump(2) + "\n");
  staged.commit(OnExisting::kRefuse, "the odometry ran");
  return result;
}

std::string voSummaryLine(const VoRunResult& r) {
  const nlohmann::ordered_json& j = r.summary;
  std::ostringstream line;
  line.precision(3);
  line << std::fixed << "tgnav vo: " << j["frames"].get<std::size_t>() << " frames: " << j["ok"].get<int>() << " ok, "
       << j["weak"].get<int>() << " weak, " << j["lost"].get<int>() << " lost";
  if (!j["failed_at_s"].is_null()) line << " (first lost at " << j["failed_at_s"].get<double>() << " s)";
  if (!j["ate_rmse_aligned_m"].is_null()) {
    line << "; ATE rmse " << j["ate_rmse_aligned_m"].get<double>() << " m aligned, "
         << j["ate_rmse_anchored_m"].get<double>() << " m anchored";
    if (!j["rpe_trans_rmse_percent"].is_null()) {
      line << ", RPE(1 m) " << j["rpe_trans_rmse_percent"].get<double>() << " %";
    }
    line << ", goal error " << j["goal_error_m"].get<double>() << " m over " << j["distance_travelled_m"].get<double>()
         << " m";
  } else if (j["groundtruth"].get<bool>()) {
    line << "; no tracked frame to evaluate";
  } else {
    line << "; no ground truth";
  }
  line.precision(1);
  line << "; " << j["ms_per_frame"].get<double>() << " ms/frame -> " << r.out.string()
       << "/{est.tum,status.csv,summary.json}";
  return line.str();
}

}  // namespace tgnav::harness
