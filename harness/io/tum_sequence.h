#pragma once
// TUM RGB-D benchmark sequence folders (https://cvg.cit.tum.de/data/datasets/rgbd-dataset/file_formats):
//
//   DIR/rgb/<t>.png       8-bit colour images
//   DIR/depth/<t>.png     16-bit depth, depth_scale units per metre (5000: 1/5 mm), 0 = invalid
//   DIR/rgb.txt           '#' comment lines, then "timestamp filename" (relative to DIR) per line
//   DIR/depth.txt         the same for the depth images
//   DIR/groundtruth.txt   optional: TUM trajectory "timestamp tx ty tz qx qy qz qw", the camera
//                         (optical frame: x right, y down, z forward) in the world
//   DIR/intrinsics.yaml   tgnav's addition (not in TUM's own sequences): width, height, fx, fy,
//                         cx, cy and optionally depth_scale
//
// rgb and depth images are paired as TUM's associate.py does: candidate pairs closer than
// kMaxPairDtS in time, taken greedily from the closest, each image used at most once.
#include <yaml-cpp/yaml.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "harness/io/staged_output.h"
#include "vo/odometry.h"
#include "vo/tum.h"

namespace tgnav::harness {

constexpr double kTumDepthScale = 5000.0;  // depth PNG units per metre
constexpr double kMaxPairDtS = 0.02;       // associate.py's default max_difference

// Writes a sequence into DIR whole or not at all: frames go into the sibling DIR.partial,
// which finish() renames to DIR. A writer destroyed without finish() removes DIR.partial.
class SequenceWriter {
 public:
  // InputError naming `dir` when it already exists or cannot be created.
  SequenceWriter(const std::filesystem::path& dir, const vo::CameraIntrinsics& intrinsics);
  ~SequenceWriter();
  SequenceWriter(const SequenceWriter&) = delete;
  SequenceWriter& operator=(const SequenceWriter&) = delete;
  SequenceWriter(SequenceWriter&&) = delete;
  SequenceWriter& operator=(SequenceWriter&&) = delete;

  // `bgr`: CV_8UC3 of the intrinsics' size; `depth_m`: CV_32FC1 metres, 0 (or non-finite, or
  // beyond 65535 / kTumDepthScale m) invalid; `X_WC`: the camera's true pose. Times are rounded
  // to microseconds (the 6 decimals of the lists and file names; groundtruth.txt gets the same
  // rounded times) and must increase after rounding; std::invalid_argument otherwise.
  void add(double t_s, const cv::Mat& bgr, const cv::Mat& depth_m, const Eigen::Isometry3d& X_WC);
  // Writes the lists, groundtruth.txt and intrinsics.yaml, then renames the staging folder
  // (StagedDir) to DIR.
  void finish();
  int frames() const { return static_cast<int>(groundtruth_.size()); }
  const std::filesystem::path& dir() const { return staged_->target(); }
  const std::filesystem::path& staging() const { return staged_->staging(); }

 private:
  std::unique_ptr<StagedDir> staged_;
  vo::CameraIntrinsics intrinsics_;
  std::vector<vo::StampedPose> groundtruth_;
  std::string rgb_list_;
  std::string depth_list_;
  bool finished_ = false;
};

// One associated rgb/depth pair of a sequence, with where it was listed (for error messages).
struct SequenceEntry {
  double t_s = 0.0;  // the rgb image's timestamp, the frame's time
  double depth_t_s = 0.0;
  std::filesystem::path rgb;  // absolute or relative to the working directory
  std::filesystem::path depth;
  int rgb_line = 0;    // line in rgb.txt
  int depth_line = 0;  // line in depth.txt
};

struct Sequence {
  std::filesystem::path dir;
  std::vector<SequenceEntry> frames;  // in time order
  int unpaired_rgb = 0;               // listed images without a partner within kMaxPairDtS
  int unpaired_depth = 0;
  std::vector<vo::StampedPose> groundtruth;  // empty when there is no groundtruth.txt; in file order
  bool has_groundtruth = false;
  int groundtruth_non_increasing = 0;              // its timestamps that repeat or go back (vo::nonIncreasingTimes)
  std::optional<vo::CameraIntrinsics> intrinsics;  // from intrinsics.yaml, when present
  double depth_scale = kTumDepthScale;             // intrinsics.yaml may override it
};

// The intrinsics.yaml written beside RGB-D images (a recorded sequence, `tgnav render`): width,
// height, fx, fy, cx, cy, depth_scale (units per metre of the 16-bit depth images), then the keys
// of `extra` (a mapping), if any. The one writer of the file, so that every copy reads back alike.
std::string intrinsicsYaml(const vo::CameraIntrinsics& k, double depth_scale, const YAML::Node& extra = {});

// Reads the lists, ground truth and intrinsics (not the images) of the sequence in `dir`.
// InputError naming the file and line for: a missing folder, rgb.txt or depth.txt; malformed
// or empty lists; list timestamps that do not increase; listed image files that do not exist (of
// paired frames); no rgb/depth pair within kMaxPairDtS; a malformed groundtruth.txt or
// intrinsics.yaml. Ground-truth timestamps may repeat or go back (TUM's own files repeat some):
// they are counted, and vo::associate() pairs them by evo's rule.
Sequence loadSequence(const std::filesystem::path& dir);

struct SequenceImages {
  cv::Mat bgr;      // CV_8UC3 (or CV_8UC1 for grey rgb images)
  cv::Mat depth_m;  // CV_32FC1 metres, 0 = invalid
};

// Reads frame `index` of `seq`. InputError naming the image and its list line when it cannot be
// read, the depth is not 16-bit single-channel, the rgb is not 8-bit, or their sizes differ.
SequenceImages loadFrame(const Sequence& seq, std::size_t index);

// TUM's associate.py: index pairs (i into `a`, j into `b`) with |a_i - b_j| < max_dt_s, greedily
// from the closest, each index at most once; sorted by i. Both inputs sorted ascending.
std::vector<std::pair<std::size_t, std::size_t>> associateTimestamps(const std::vector<double>& a,
                                                                     const std::vector<double>& b,
                                                                     double max_dt_s = kMaxPairDtS);

}  // namespace tgnav::harness
