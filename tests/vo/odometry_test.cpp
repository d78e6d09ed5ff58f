// RgbdOdometry on synthetic RGB-D frames: a textured plane 2 m ahead seen by a camera sliding
// sideways (the image is a shifted crop of a larger texture, depth constant), bad frames, and
// decideStatus's thresholds.
#include "vo/odometry.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>
#include <vector>

namespace tgnav::vo {
namespace {

constexpr int kW = 320;
constexpr int kH = 240;
constexpr double kF = 208.0;
constexpr double kDepth = 2.0;

CameraIntrinsics camera() { return CameraIntrinsics{kW, kH, kF, kF, (kW - 1) / 2.0, (kH - 1) / 2.0}; }

// Blurred random blobs: plenty of corners at every scale.
cv::Mat texture(int w, int h) {
  cv::Mat t(h, w, CV_8UC1);
  cv::RNG rng(3);
  rng.fill(t, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(t, t, cv::Size(0, 0), 2.0);
  cv::normalize(t, t, 0, 255, cv::NORM_MINMAX);
  return t;
}

cv::Mat flatDepth(float z = static_cast<float>(kDepth)) { return cv::Mat(kH, kW, CV_32FC1, cv::Scalar(z)); }

TEST(Odometry, TracksASidewaysSlideOverATexturedPlane) {
  const cv::Mat tex = texture(kW + 400, kH);
  RgbdOdometry vo(camera(), OdometryConfig{});
  // 4 px per frame to the right in the image = the camera moving along +x by 4 z / f.
  for (int i = 0; i < 100; ++i) {
    const cv::Mat image = tex(cv::Rect(4 * i, 0, kW, kH)).clone();
    const FrameResult r = vo.track(0.05 * i, image, flatDepth());
    ASSERT_NE(r.status, TrackingStatus::kLost) << "frame " << i << ": " << r.reason;
    const double truth = 4.0 * i * kDepth / kF;
    // One plane 2 m ahead leaves yaw and sideways translation weakly separable: a keyframe's few
    // millimetres of error (~0.5 px) carry over to the frames tracked against its landmarks.
    EXPECT_NEAR(r.X_WC.translation().x(), truth, 0.01 * truth + 8e-3) << "frame " << i;
    // A single plane leaves rotation and sideways translation weakly separable: small drift.
    EXPECT_NEAR(r.X_WC.translation().y(), 0.0, 0.005 + 0.005 * truth) << "frame " << i;
    EXPECT_NEAR(r.X_WC.translation().z(), 0.0, 0.01 + 0.01 * truth) << "frame " << i;
    EXPECT_LT(Eigen::AngleAxisd(r.X_WC.linear()).angle(), 0.01) << "frame " << i;
    if (i > 0) {
      EXPECT_GE(r.inliers, 200) << "frame " << i;
    }
  }
  EXPECT_FALSE(vo.failed());
  EXPECT_GT(vo.history().back().features, 500);
}

// The inliers' columns (FrameResult::inlier_columns) count every inlier, in the bin of the part
// of the image it lies in: texture on the left half only leaves the right half's bins empty.
TEST(Odometry, CountsTheInliersColumnsWhereTheTextureIs) {
  const cv::Mat tex = texture(kW + 400, kH);
  RgbdOdometry vo(camera(), OdometryConfig{});
  for (int i = 0; i < 10; ++i) {
    cv::Mat image = tex(cv::Rect(4 * i, 0, kW, kH)).clone();
    image(cv::Rect(kW / 2, 0, kW / 2, kH)).setTo(cv::Scalar(128));
    const FrameResult r = vo.track(0.05 * i, image, flatDepth());
    ASSERT_NE(r.status, TrackingStatus::kLost) << "frame " << i << ": " << r.reason;
    int sum = 0;
    for (const int n : r.inlier_columns) sum += n;
    EXPECT_EQ(sum, r.inliers) << "frame " << i;
    EXPECT_GT(r.inliers, 100) << "frame " << i;
    const int half = FrameResult::kColumnBins / 2;
    for (int b = half + 1; b < FrameResult::kColumnBins; ++b) {
      EXPECT_EQ(r.inlier_columns[static_cast<std::size_t>(b)], 0) << "frame " << i << ", bin " << b;
    }
  }
}

// A jerk the motion model does not foresee: the image slides 4 px a frame, then 40 px back in one
// frame (44 px from the prediction, beyond the 24 px window). Without wide_retry the frame is
// lost; with it (the default) the wider window finds the landmarks and the pose follows the jump.
TEST(Odometry, AWideRetryTracksAJerkTheMotionModelMissed) {
  const cv::Mat tex = texture(kW + 400, kH);
  for (const bool retry : {false, true}) {
    OdometryConfig config;
    config.wide_retry = retry;
    RgbdOdometry vo(camera(), config);
    FrameResult r;
    for (int i = 0; i <= 10; ++i) {
      const int offset = i < 10 ? 100 + 4 * i : 136 - 40;
      r = vo.track(0.05 * i, tex(cv::Rect(offset, 0, kW, kH)).clone(), flatDepth());
      if (i < 10) ASSERT_NE(r.status, TrackingStatus::kLost) << "frame " << i << ": " << r.reason;
    }
    if (!retry) {
      EXPECT_EQ(r.status, TrackingStatus::kLost);
      continue;
    }
    ASSERT_NE(r.status, TrackingStatus::kLost) << r.reason;
    EXPECT_GE(r.inliers, 200);
    EXPECT_NEAR(r.X_WC.translation().x(), -4.0 * kDepth / kF, 0.01);  // 96 px from where it started
  }
}

// Bundle adjustment runs on keyframes (at each with ba.every_keyframes = 1; not on the first,
// which has nothing to adjust against) and reports what it changed there; with ba.enabled =
// false nothing is reported. Both track the slide; on exact depth BA's corrections are small.
TEST(Odometry, BundleAdjustmentRefinesKeyframesOnly) {
  const cv::Mat tex = texture(kW + 400, kH);
  for (const bool ba : {true, false}) {
    OdometryConfig config;
    config.ba.enabled = ba;
    config.ba.every_keyframes = 1;
    RgbdOdometry vo(camera(), config);
    int adjusted = 0;
    for (int i = 0; i < 100; ++i) {
      const FrameResult r = vo.track(0.05 * i, tex(cv::Rect(4 * i, 0, kW, kH)).clone(), flatDepth());
      ASSERT_NE(r.status, TrackingStatus::kLost) << "frame " << i << ": " << r.reason;
      const double truth = 4.0 * i * kDepth / kF;
      EXPECT_NEAR(r.X_WC.translation().x(), truth, 0.01 * truth + 8e-3) << "frame " << i << ", ba " << ba;
      if (!std::isfinite(r.ba_correction_m)) continue;
      ++adjusted;
      EXPECT_TRUE(ba);
      EXPECT_TRUE(r.keyframe) << "frame " << i;
      EXPECT_GT(i, 0);
      EXPECT_LT(r.ba_correction_m, 0.02) << "frame " << i;
      EXPECT_LT(r.ba_correction_rad, 0.01) << "frame " << i;
    }
    if (ba) {
      EXPECT_GE(adjusted, 5);  // 2.8 m of slide: a keyframe every 0.4 m at least
    } else {
      EXPECT_EQ(adjusted, 0);
    }
  }
}

// ba.every_keyframes = 3: the adjustment runs at every third keyframe after the first, and the
// slide is tracked as well as with one at each.
TEST(Odometry, BundleAdjustmentAtEveryNthKeyframe) {
  const cv::Mat tex = texture(kW + 400, kH);
  OdometryConfig config;
  config.ba.every_keyframes = 3;
  RgbdOdometry vo(camera(), config);
  int keyframes = 0;
  int adjusted = 0;
  for (int i = 0; i < 100; ++i) {
    const FrameResult r = vo.track(0.05 * i, tex(cv::Rect(4 * i, 0, kW, kH)).clone(), flatDepth());
    ASSERT_NE(r.status, TrackingStatus::kLost) << "frame " << i << ": " << r.reason;
    const double truth = 4.0 * i * kDepth / kF;
    EXPECT_NEAR(r.X_WC.translation().x(), truth, 0.01 * truth + 8e-3) << "frame " << i;
    if (r.keyframe && i > 0) ++keyframes;
    const bool lands = std::isfinite(r.ba_correction_m);
    EXPECT_EQ(lands, r.keyframe && i > 0 && keyframes % 3 == 0) << "frame " << i << ", keyframe " << keyframes;
    adjusted += lands ? 1 : 0;
  }
  EXPECT_GE(keyframes, 6);
  EXPECT_EQ(adjusted, keyframes / 3);
}

// Bundle adjustment in the background (ba.latency_frames = 3): each adjustment is applied 3
// frames after the keyframe that started it, or after the frame that applied the one before
// (one in flight at a time); the run tracks the slide as well as adjusting at the keyframe, and
// two runs give the same poses bit for bit, however the threads were scheduled. Keyframes name
// the rule that made them.
TEST(Odometry, BackgroundBundleAdjustmentLandsAFixedNumberOfFramesLater) {
  const cv::Mat tex = texture(kW + 400, kH);
  OdometryConfig config;
  config.ba.latency_frames = 3;
  config.ba.every_keyframes = 1;
  std::vector<std::vector<FrameResult>> runs;
  for (int run = 0; run < 2; ++run) {
    RgbdOdometry vo(camera(), config);
    std::vector<FrameResult> results;
    for (int i = 0; i < 100; ++i) {
      results.push_back(vo.track(0.05 * i, tex(cv::Rect(4 * i, 0, kW, kH)).clone(), flatDepth()));
      const FrameResult& r = results.back();
      ASSERT_NE(r.status, TrackingStatus::kLost) << "frame " << i << ": " << r.reason;
      const double truth = 4.0 * i * kDepth / kF;
      EXPECT_NEAR(r.X_WC.translation().x(), truth, 0.01 * truth + 8e-3) << "frame " << i;
      EXPECT_EQ(r.keyframe, !r.keyframe_rule.empty()) << "frame " << i;
    }
    runs.push_back(std::move(results));
  }
  const std::vector<FrameResult>& r = runs[0];
  EXPECT_EQ(r[0].keyframe_rule, "first");
  int applied = 0;
  long due = -1;  // frame at which the adjustment in flight lands
  bool queued = false;
  for (std::size_t i = 0; i < r.size(); ++i) {
    const bool lands = std::isfinite(r[i].ba_correction_m);
    EXPECT_EQ(lands, static_cast<long>(i) == due) << "frame " << i;
    if (lands) {
      ++applied;
      due = queued ? static_cast<long>(i) + 3 : -1;
      queued = false;
    }
    if (i > 0 && r[i].keyframe) {
      if (due < 0) {
        due = static_cast<long>(i) + 3;
      } else if (static_cast<long>(i) != due || !lands) {
        queued = true;
      }
    }
    EXPECT_TRUE(runs[1][i].X_WC.matrix() == r[i].X_WC.matrix()) << "frame " << i;
  }
  EXPECT_GE(applied, 5);
}

// ORB-SLAM2's keyframe policy: a keyframe when the frame tracks too few of the reference
// keyframe's well-observed landmarks ("reference"), or too few close ones while many close
// features are new ("close"). The slide over a plane 2 m ahead (all close) tracks with fewer
// keyframes than the ratio rule takes, each named by its rule.
TEST(Odometry, OrbSlam2KeyframePolicy) {
  const cv::Mat tex = texture(kW + 400, kH);
  int keyframes[2] = {0, 0};
  for (const KeyframePolicy policy : {KeyframePolicy::kRatio, KeyframePolicy::kOrbSlam2}) {
    OdometryConfig config;
    config.keyframe_policy = policy;
    RgbdOdometry vo(camera(), config);
    for (int i = 0; i < 100; ++i) {
      const FrameResult r = vo.track(0.05 * i, tex(cv::Rect(4 * i, 0, kW, kH)).clone(), flatDepth());
      ASSERT_NE(r.status, TrackingStatus::kLost) << "frame " << i << ": " << r.reason;
      const double truth = 4.0 * i * kDepth / kF;
      EXPECT_NEAR(r.X_WC.translation().x(), truth, 0.02 * truth + 0.01) << "frame " << i;
      if (!r.keyframe || i == 0) continue;
      ++keyframes[policy == KeyframePolicy::kRatio ? 0 : 1];
      if (policy == KeyframePolicy::kOrbSlam2) {
        EXPECT_TRUE(r.keyframe_rule == "reference" || r.keyframe_rule == "close" ||
                    r.keyframe_rule == "reference+close")
            << r.keyframe_rule;
      } else {
        const auto has = [&](const char* rule) { return r.keyframe_rule.find(rule) != std::string::npos; };
        EXPECT_TRUE(has("inliers") || has("translation") || has("rotation")) << r.keyframe_rule;
      }
    }
  }
  EXPECT_GT(keyframes[1], 2);
  EXPECT_LT(keyframes[1], keyframes[0]) << keyframes[0] << " ratio keyframes";
}

// keyframe_richer_ratio: a still camera sees the whole texture (every corner: no feature cap), a
// view that narrows to a strip at its left edge (each narrowing a keyframe by the inlier rule; the
// rest's landmarks, expected but unmatched, are culled while it stays there) and widens again. The
// widening tracks the strip's landmarks, more than the strip's keyframe had, so the ratio rule
// alone makes no keyframe once the inlier count stops falling, and the VO stays anchored to a
// fifth of what it sees; with the rule at 2 a view with twice the features of the last keyframe
// makes one ("richer"), and it tracks several times as many.
TEST(Odometry, AViewFarRicherThanTheLastKeyframeMakesOneWithTheRicherRule) {
  const cv::Mat tex = texture(kW, kH);
  // Frames 5-10 narrow the view to a 36 px strip, 11-20 stay there, 21-25 widen it again.
  const auto view = [&](int i) {
    const int widths[] = {200, 140, 100, 70, 50, 36};
    cv::Mat image = tex.clone();
    const int w = i < 5 || i > 25 ? kW : widths[i < 20 ? std::min(i - 5, 5) : 25 - i];
    if (w < kW) image(cv::Rect(w, 0, kW - w, kH)).setTo(cv::Scalar(128));
    return image;
  };
  int end_inliers[2] = {0, 0};
  for (const double richer : {0.0, 2.0}) {
    OdometryConfig config;
    config.keyframe_richer_ratio = richer;
    config.features.max_features = 20000;  // every corner the view has: its texture limits them
    RgbdOdometry vo(camera(), config);
    int richer_alone = 0;  // keyframes the inlier rule did not ask for
    FrameResult r;
    for (int i = 0; i < 40; ++i) {
      r = vo.track(0.05 * i, view(i), flatDepth());
      ASSERT_NE(r.status, TrackingStatus::kLost) << "frame " << i << ": " << r.reason;
      EXPECT_LT(r.X_WC.translation().norm(), 0.05) << "frame " << i;  // a 36 px strip pins little
      const bool by_richer = r.keyframe_rule.find("richer") != std::string::npos;
      if (richer == 0.0 || i <= 20) {
        EXPECT_FALSE(by_richer) << "frame " << i;
      }
      if ((i > 10 && i <= 20) || (richer == 0.0 && i > 23)) {
        EXPECT_FALSE(r.keyframe) << "frame " << i << ": " << r.keyframe_rule;
      }
      richer_alone += r.keyframe_rule == "richer" ? 1 : 0;
    }
    end_inliers[richer > 0.0 ? 1 : 0] = r.inliers;
    if (richer == 0.0) {
      EXPECT_LT(r.inliers, 0.25 * r.with_depth);  // anchored to the strip's last keyframes
    } else {
      EXPECT_GE(richer_alone, 1);
      EXPECT_GE(r.inliers, 0.5 * r.with_depth);
    }
  }
  EXPECT_GT(end_inliers[1], 2 * end_inliers[0]);
}

// The local map keeps a landmark while a keyframe in it observed the landmark, not only while
// the keyframe that created it does. A still camera, a keyframe at every frame, a local map of
// two keyframes: K0 sees the whole texture and creates its landmarks, K1 sees only the right
// half (and tracks it), K2 only the left half. When K0 leaves the map at K2, the right half's
// landmarks stay (K1 observed them), so the whole texture is tracked again at the next frame.
TEST(Odometry, LandmarksStayWhileAKeyframeOfTheLocalMapObservedThem) {
  const cv::Mat tex = texture(kW, kH);
  const auto blanked = [&](int x0, int x1) {
    cv::Mat image = tex.clone();
    image(cv::Rect(x0, 0, x1 - x0, kH)).setTo(cv::Scalar(128));
    return image;
  };
  OdometryConfig config;
  config.local_map_keyframes = 2;
  config.keyframe_inlier_ratio = 1.0;  // every frame that tracks fewer than its keyframe did
  RgbdOdometry vo(camera(), config);
  const FrameResult k0 = vo.track(0.0, tex, flatDepth());
  const FrameResult k1 = vo.track(0.05, blanked(0, kW / 2), flatDepth());   // right half
  const FrameResult k2 = vo.track(0.10, blanked(kW / 2, kW), flatDepth());  // left half
  for (const FrameResult* r : {&k0, &k1, &k2}) {
    ASSERT_NE(r->status, TrackingStatus::kLost) << r->reason;
    EXPECT_TRUE(r->keyframe) << "t = " << r->t_s;
  }
  const FrameResult whole = vo.track(0.15, tex, flatDepth());
  ASSERT_NE(whole.status, TrackingStatus::kLost) << whole.reason;
  // Had they gone with K0, only the left half (and the few corners K1 and K2 created at the
  // blank's edge) would match: about half.
  EXPECT_GE(whole.inliers, 0.85 * k0.with_depth) << k1.inliers << " + " << k2.inliers << " of " << k0.with_depth;
  EXPECT_LT(whole.X_WC.translation().norm(), 1e-3);
}

TEST(Odometry, BlankSaturatedOrDepthlessFramesAreLost) {
  const cv::Mat black(kH, kW, CV_8UC1, cv::Scalar(0));
  const cv::Mat white(kH, kW, CV_8UC3, cv::Scalar(255, 255, 255));
  const cv::Mat tex = texture(kW, kH);
  const cv::Mat no_depth(kH, kW, CV_32FC1, cv::Scalar(0.0f));
  const cv::Mat nan_depth(kH, kW, CV_32FC1, cv::Scalar(std::numeric_limits<float>::quiet_NaN()));
  struct Case {
    const char* what;
    cv::Mat image, depth;
  } cases[] = {{"black", black, flatDepth()},
               {"saturated", white, flatDepth()},
               {"no depth", tex, no_depth},
               {"NaN depth", tex, nan_depth},
               {"too far", tex, flatDepth(20.0f)}};
  for (const Case& c : cases) {
    RgbdOdometry vo(camera(), OdometryConfig{});
    const FrameResult r = vo.track(0.0, c.image, c.depth);
    EXPECT_EQ(r.status, TrackingStatus::kLost) << c.what;
    EXPECT_FALSE(r.reason.empty()) << c.what;
    EXPECT_TRUE(vo.failed()) << c.what;
    EXPECT_EQ(vo.failedAt(), 0.0) << c.what;
  }
}

TEST(Odometry, LostStaysFailedUnlessReinitialisedWhichContinuesFromTheLastPose) {
  const cv::Mat tex = texture(kW + 400, kH);
  const cv::Mat blank(kH, kW, CV_8UC1, cv::Scalar(128));
  for (const bool reinit : {false, true}) {
    OdometryConfig config;
    config.reinitialise_after_lost = reinit;
    RgbdOdometry vo(camera(), config);
    for (int i = 0; i < 10; ++i) vo.track(0.05 * i, tex(cv::Rect(4 * i, 0, kW, kH)).clone(), flatDepth());
    const Eigen::Isometry3d before = vo.history().back().X_WC;
    const FrameResult lost = vo.track(0.5, blank, flatDepth());  // a blank frame: nothing to match
    EXPECT_EQ(lost.status, TrackingStatus::kLost);
    EXPECT_TRUE(lost.X_WC.isApprox(before));
    const FrameResult next = vo.track(0.55, tex(cv::Rect(44, 0, kW, kH)).clone(), flatDepth());
    EXPECT_TRUE(vo.failed());
    EXPECT_DOUBLE_EQ(vo.failedAt(), 0.5);
    if (reinit) {
      EXPECT_EQ(next.status, TrackingStatus::kOk) << next.reason;
      EXPECT_TRUE(next.reinitialised);
      EXPECT_TRUE(next.X_WC.isApprox(before));
    } else {
      EXPECT_EQ(next.status, TrackingStatus::kLost);
      EXPECT_NE(next.reason.find("lost at t = 0.5"), std::string::npos) << next.reason;
    }
  }
}

TEST(Odometry, BadFramesAndConfigsAreRefused) {
  RgbdOdometry vo(camera(), OdometryConfig{});
  const cv::Mat tex = texture(kW, kH);
  EXPECT_THROW(vo.track(0.0, cv::Mat(kH, kW + 1, CV_8UC1, cv::Scalar(0)), flatDepth()), std::invalid_argument);
  EXPECT_THROW(vo.track(0.0, tex, cv::Mat(kH, kW, CV_16UC1, cv::Scalar(0))), std::invalid_argument);
  EXPECT_THROW(vo.track(0.0, cv::Mat(), flatDepth()), std::invalid_argument);
  vo.track(1.0, tex, flatDepth());
  EXPECT_THROW(vo.track(1.0, tex, flatDepth()), std::invalid_argument);  // time must increase
  EXPECT_THROW(vo.track(0.5, tex, flatDepth()), std::invalid_argument);
  auto message = [](OdometryConfig c) {
    try {
      c.validate();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  OdometryConfig c;
  c.min_inliers = 2;
  EXPECT_NE(message(c).find("min_inliers = 2"), std::string::npos);
  c = OdometryConfig{};
  c.weak_inliers = 10;
  EXPECT_NE(message(c).find("weak_inliers = 10"), std::string::npos);
  c = OdometryConfig{};
  c.max_depth_m = 0.1;
  EXPECT_NE(message(c).find("max_depth_m"), std::string::npos);
  c = OdometryConfig{};
  c.ratio_test = 1.5;
  EXPECT_NE(message(c).find("ratio_test"), std::string::npos);
  c = OdometryConfig{};
  c.ba.max_iterations = 0;
  EXPECT_NE(message(c).find("ba.max_iterations = 0"), std::string::npos);
  c = OdometryConfig{};
  c.ba.robust_iterations = 0;
  EXPECT_NE(message(c).find("ba.robust_iterations = 0"), std::string::npos);
  c = OdometryConfig{};
  c.ba.every_keyframes = 0;
  EXPECT_NE(message(c).find("ba.every_keyframes = 0"), std::string::npos);
  c = OdometryConfig{};
  c.keyframe_richer_ratio = 0.9;
  EXPECT_NE(message(c).find("keyframe_richer_ratio = 0.9"), std::string::npos);
  c.keyframe_richer_ratio = 2.0;
  c.keyframe_policy = KeyframePolicy::kOrbSlam2;
  EXPECT_NE(message(c).find("keyframe_richer_ratio = 2: applies to keyframe_policy ratio only"), std::string::npos)
      << message(c);
  EXPECT_THROW(RgbdOdometry(CameraIntrinsics{kW, kH, 0.0, kF, 0.0, 0.0}, OdometryConfig{}), std::invalid_argument);
}

// decideStatus: lost below min_inliers, weak from there to below weak_inliers, ok from
// weak_inliers on; each threshold's boundary belongs to the better status.
TEST(DecideStatus, ThresholdsAndTheirBoundaries) {
  const OdometryConfig defaults;  // min_inliers 30 (ORB-SLAM2's), weak_inliers 60
  ASSERT_EQ(defaults.min_inliers, 30);
  ASSERT_EQ(defaults.weak_inliers, 60);
  EXPECT_EQ(decideStatus(0, defaults), TrackingStatus::kLost);
  EXPECT_EQ(decideStatus(29, defaults), TrackingStatus::kLost);
  EXPECT_EQ(decideStatus(30, defaults), TrackingStatus::kWeak);
  EXPECT_EQ(decideStatus(59, defaults), TrackingStatus::kWeak);
  EXPECT_EQ(decideStatus(60, defaults), TrackingStatus::kOk);
  EXPECT_EQ(decideStatus(1000, defaults), TrackingStatus::kOk);

  OdometryConfig config;
  config.min_inliers = 4;  // the least PnP allows
  config.weak_inliers = 5;
  config.validate();
  EXPECT_EQ(decideStatus(3, config), TrackingStatus::kLost);
  EXPECT_EQ(decideStatus(4, config), TrackingStatus::kWeak);
  EXPECT_EQ(decideStatus(5, config), TrackingStatus::kOk);
}

TEST(DecideStatus, NoWeakBandWhenBothThresholdsAgree) {
  OdometryConfig config;
  config.min_inliers = 40;
  config.weak_inliers = 40;
  config.validate();
  EXPECT_EQ(decideStatus(39, config), TrackingStatus::kLost);
  EXPECT_EQ(decideStatus(40, config), TrackingStatus::kOk);
}

// Every tracked frame's status is decideStatus of its inliers. The weak threshold only labels
// frames (tracking goes on the same), so one at the median of a first run's inliers gives the
// same run with both weak and ok frames.
TEST(DecideStatus, TrackedFramesTakeTheStatusOfTheirInliers) {
  const cv::Mat tex = texture(kW + 400, kH);
  auto run = [&](const OdometryConfig& config) {
    RgbdOdometry vo(camera(), config);
    for (int i = 0; i < 40; ++i) vo.track(0.05 * i, tex(cv::Rect(4 * i, 0, kW, kH)).clone(), flatDepth());
    return vo.history();
  };
  const std::vector<FrameResult> first = run(OdometryConfig{});
  std::vector<int> inliers;
  for (std::size_t i = 1; i < first.size(); ++i) inliers.push_back(first[i].inliers);
  std::nth_element(inliers.begin(), inliers.begin() + inliers.size() / 2, inliers.end());
  OdometryConfig config;
  config.weak_inliers = inliers[inliers.size() / 2];
  const std::vector<FrameResult> second = run(config);
  ASSERT_EQ(second.size(), first.size());
  int weak = 0, ok = 0;
  for (std::size_t i = 1; i < second.size(); ++i) {  // frame 0 initialises
    EXPECT_EQ(second[i].inliers, first[i].inliers) << "frame " << i;
    EXPECT_EQ(second[i].status, decideStatus(second[i].inliers, config)) << "frame " << i;
    weak += second[i].status == TrackingStatus::kWeak;
    ok += second[i].status == TrackingStatus::kOk;
  }
  EXPECT_GT(weak, 0);
  EXPECT_GT(ok, 0);
}

// A near plain surface covering the right half of a far texture: the corners its silhouette makes
// on the texture are no points in space. Checked over 3x3 pixels, keypoints of the coarse pyramid
// levels a few pixels off the silhouette keep a depth; over FAST's circle at each keypoint's own
// level (depth_edge_radius_px: 3) they do not. Without a discontinuity both keep the same.
TEST(Odometry, TheDepthEdgeCheckAtTheKeypointsLevelDropsCornersOnASilhouette) {
  const cv::Mat tex = texture(kW, kH);
  cv::Mat image = tex.clone();
  image(cv::Rect(kW / 2, 0, kW / 2, kH)).setTo(cv::Scalar(128));
  cv::Mat depth = flatDepth(5.0f);
  depth(cv::Rect(kW / 2, 0, kW / 2, kH)).setTo(cv::Scalar(1.0f));
  OdometryConfig level;
  level.depth_edge_radius_px = 3.0;
  auto withDepth = [&](const OdometryConfig& config, const cv::Mat& d) {
    RgbdOdometry vo(camera(), config);
    return vo.track(0.0, image, d).with_depth;
  };
  const int pixels = withDepth(OdometryConfig{}, depth);
  const int at_level = withDepth(level, depth);
  EXPECT_GT(pixels, 100);
  EXPECT_LE(at_level, pixels - 5);  // 999 against 989 when written
  EXPECT_EQ(withDepth(level, flatDepth(5.0f)), withDepth(OdometryConfig{}, flatDepth(5.0f)));
  level.depth_edge_radius_px = -1.0;
  EXPECT_THROW(RgbdOdometry(camera(), level), std::invalid_argument);
}

}  // namespace
}  // namespace tgnav::vo
