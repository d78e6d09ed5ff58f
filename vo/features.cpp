#include "vo/features.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "vo/check.h"

namespace tgnav::vo {

namespace {
// ORB keeps only its globally strongest corners; ask for enough candidates that weakly
// textured cells still have theirs when the grid picks per cell.
constexpr int kCandidateFactor = 10;
}  // namespace

void FeatureConfig::validate() const {
  require(max_features > 0, "max_features", max_features, "must be > 0");
  require(grid_cols > 0 && grid_cols <= 64, "grid_cols", grid_cols, "must be in [1, 64]");
  require(grid_rows > 0 && grid_rows <= 64, "grid_rows", grid_rows, "must be in [1, 64]");
  require(fast_threshold > 0 && fast_threshold < 255, "fast_threshold", fast_threshold, "must be in [1, 254]");
  require(scale_factor > 1.0 && scale_factor <= 2.0, "scale_factor", scale_factor, "must be in (1, 2]");
  require(pyramid_levels >= 1 && pyramid_levels <= 16, "pyramid_levels", pyramid_levels, "must be in [1, 16]");
  require(edge_threshold_px >= 3, "edge_threshold_px", edge_threshold_px, "must be >= 3");
}

FeatureDetector::FeatureDetector(const FeatureConfig& config) : config_(config) {
  config_.validate();
  orb_ = cv::ORB::create(kCandidateFactor * config_.max_features, static_cast<float>(config_.scale_factor),
                         config_.pyramid_levels, config_.edge_threshold_px, 0, 2, cv::ORB::HARRIS_SCORE, 31,
                         config_.fast_threshold);
}

Features FeatureDetector::detect(const cv::Mat& gray) const {
  CV_Assert(gray.type() == CV_8UC1);
  std::vector<cv::KeyPoint> candidates;
  orb_->detect(gray, candidates);

  const int cells = config_.grid_cols * config_.grid_rows;
  std::vector<std::vector<int>> by_cell(cells);
  for (int i = 0; i < static_cast<int>(candidates.size()); ++i) {
    const cv::Point2f& p = candidates[i].pt;
    const int cx = std::min(config_.grid_cols - 1, static_cast<int>(p.x * config_.grid_cols / gray.cols));
    const int cy = std::min(config_.grid_rows - 1, static_cast<int>(p.y * config_.grid_rows / gray.rows));
    by_cell[cy * config_.grid_cols + cx].push_back(i);
  }
  auto stronger = [&](int a, int b) {
    if (candidates[a].response != candidates[b].response) {
      return candidates[a].response > candidates[b].response;
    }
    return a < b;  // deterministic tie-break
  };
  const std::size_t share = std::max(1, config_.max_features / cells);
  std::vector<int> kept;
  std::vector<int> leftover;
  for (auto& cell : by_cell) {
    std::sort(cell.begin(), cell.end(), stronger);
    const std::size_t n = std::min(share, cell.size());
    kept.insert(kept.end(), cell.begin(), cell.begin() + n);
    leftover.insert(leftover.end(), cell.begin() + n, cell.end());
  }
  const std::size_t budget = static_cast<std::size_t>(config_.max_features);
  if (kept.size() < budget) {
    std::sort(leftover.begin(), leftover.end(), stronger);
    const std::size_t extra = std::min(budget - kept.size(), leftover.size());
    kept.insert(kept.end(), leftover.begin(), leftover.begin() + extra);
  }
  std::sort(kept.begin(), kept.end());

  Features out;
  out.keypoints.reserve(kept.size());
  for (int i : kept) out.keypoints.push_back(candidates[i]);
  orb_->compute(gray, out.keypoints, out.descriptors);
  // ORB reports a keypoint found on pyramid level o at (level pixel) x scale^o, but the level
  // image is the full image resized to round(size / scale^o) with pixel centres aligned: the
  // pixel it was found at is at (x_o + 0.5) size / size_o - 0.5 in the full image. Without this
  // the coarse levels' keypoints are off by up to ~1.5 px (a magnification that biases pose and
  // depth estimates).
  for (cv::KeyPoint& kp : out.keypoints) {
    if (kp.octave <= 0) continue;
    const double sf = std::pow(config_.scale_factor, kp.octave);
    const double w_o = std::round(gray.cols / sf);
    const double h_o = std::round(gray.rows / sf);
    kp.pt.x = static_cast<float>((kp.pt.x / sf + 0.5) * gray.cols / w_o - 0.5);
    kp.pt.y = static_cast<float>((kp.pt.y / sf + 0.5) * gray.rows / h_o - 0.5);
  }
  return out;
}

}  // namespace tgnav::vo
