// TUM RGB-D sequence folders: what SequenceWriter writes, loadSequence/loadFrame read back
// (depth to 1/5000 m, timestamps and poses as written); rgb/depth association as TUM's
// associate.py does it; every kind of bad folder is an InputError naming the file and line.
#include "harness/io/tum_sequence.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <opencv2/imgcodecs.hpp>

#include "test_util.h"

namespace tgnav::harness {
namespace {

namespace fs = std::filesystem;

constexpr int kW = 32;
constexpr int kH = 24;

vo::CameraIntrinsics smallCamera() { return vo::CameraIntrinsics{kW, kH, 30.0, 31.0, 15.5, 11.5}; }

Eigen::Isometry3d poseAt(int i) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = (Eigen::AngleAxisd(0.1 * i, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(-0.05 * i, Eigen::Vector3d(1, 2, 3).normalized()))
                   .toRotationMatrix();
  X.translation() = Eigen::Vector3d(0.1 * i, -0.2 + 0.03 * i, 1.0 + 0.01 * i * i);
  return X;
}

cv::Mat colourAt(int i) {
  cv::Mat bgr(kH, kW, CV_8UC3);
  cv::randu(bgr, cv::Scalar::all(0), cv::Scalar::all(256));
  bgr.at<cv::Vec3b>(0, 0) = cv::Vec3b(static_cast<uchar>(i), 1, 2);
  return bgr;
}

cv::Mat depthAt(int i) {
  cv::Mat depth(kH, kW, CV_32FC1);
  for (int r = 0; r < kH; ++r) {
    for (int c = 0; c < kW; ++c) depth.at<float>(r, c) = static_cast<float>(0.5 + 0.0137 * (r * kW + c) + 0.1 * i);
  }
  depth.at<float>(0, 0) = 0.0f;   // invalid stays invalid
  depth.at<float>(0, 1) = 20.0f;  // beyond 65535 / 5000 m: invalid
  depth.at<float>(0, 2) = NAN;    // invalid
  return depth;
}

// A written sequence of `frames` frames at 20 Hz from t = 1.
fs::path writeSequence(const fs::path& dir, int frames = 5) {
  SequenceWriter writer(dir, smallCamera());
  for (int i = 0; i < frames; ++i) writer.add(1.0 + 0.05 * i, colourAt(i), depthAt(i), poseAt(i));
  writer.finish();
  return dir;
}

std::string slurp(const fs::path& file) {
  std::ifstream in(file);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

TEST(TumSequence, WriteReadRoundTrip) {
  const fs::path dir = test::tempDir() / "seq";
  cv::setRNGSeed(7);
  std::vector<cv::Mat> colours;
  {
    SequenceWriter writer(dir, smallCamera());
    EXPECT_TRUE(fs::exists(writer.staging()));
    EXPECT_EQ(writer.staging(), harness::stagingPathFor(fs::absolute(dir)));
    EXPECT_FALSE(fs::exists(dir)) << "the sequence appears only when complete";
    for (int i = 0; i < 5; ++i) {
      colours.push_back(colourAt(i));
      writer.add(1.0 + 0.05 * i, colours.back(), depthAt(i), poseAt(i));
    }
    EXPECT_FALSE(fs::exists(dir));
    writer.finish();
    EXPECT_EQ(writer.frames(), 5);
  }
  EXPECT_EQ(test::stagingLeftIn(dir.parent_path()), 0);
  for (const char* f : {"rgb.txt", "depth.txt", "groundtruth.txt", "intrinsics.yaml"}) {
    EXPECT_TRUE(fs::is_regular_file(dir / f)) << f;
  }
  // TUM's layout: three comment lines, then "timestamp filename" relative to the folder.
  EXPECT_EQ(slurp(dir / "rgb.txt").substr(0, 2), "# ");
  EXPECT_NE(slurp(dir / "rgb.txt").find("\n1.050000 rgb/1.050000.png\n"), std::string::npos);
  EXPECT_NE(slurp(dir / "depth.txt").find("\n1.200000 depth/1.200000.png\n"), std::string::npos);
  const cv::Mat raw = cv::imread((dir / "depth/1.000000.png").string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(raw.type(), CV_16UC1);
  EXPECT_EQ(raw.at<std::uint16_t>(1, 0), static_cast<std::uint16_t>(std::lround(depthAt(0).at<float>(1, 0) * 5000)));

  const Sequence seq = loadSequence(dir);
  ASSERT_EQ(seq.frames.size(), 5u);
  EXPECT_EQ(seq.unpaired_rgb, 0);
  EXPECT_EQ(seq.unpaired_depth, 0);
  ASSERT_TRUE(seq.intrinsics.has_value());
  EXPECT_EQ(seq.intrinsics->width_px, kW);
  EXPECT_EQ(seq.intrinsics->height_px, kH);
  EXPECT_DOUBLE_EQ(seq.intrinsics->fx, 30.0);
  EXPECT_DOUBLE_EQ(seq.intrinsics->fy, 31.0);
  EXPECT_DOUBLE_EQ(seq.intrinsics->cx, 15.5);
  EXPECT_DOUBLE_EQ(seq.intrinsics->cy, 11.5);
  EXPECT_DOUBLE_EQ(seq.depth_scale, 5000.0);
  ASSERT_TRUE(seq.has_groundtruth);
  ASSERT_EQ(seq.groundtruth.size(), 5u);
  for (int i = 0; i < 5; ++i) {
    const SequenceEntry& e = seq.frames[i];
    EXPECT_NEAR(e.t_s, 1.0 + 0.05 * i, 1e-12);
    EXPECT_EQ(e.t_s, e.depth_t_s);
    EXPECT_EQ(e.rgb_line, 4 + i);
    EXPECT_EQ(seq.groundtruth[i].t_s, e.t_s) << "groundtruth.txt and the lists agree exactly";
    EXPECT_TRUE(seq.groundtruth[i].X_WC.isApprox(poseAt(i), 1e-12)) << i;

    const SequenceImages images = loadFrame(seq, i);
    ASSERT_EQ(images.bgr.type(), CV_8UC3);
    EXPECT_EQ(cv::norm(images.bgr, colours[i], cv::NORM_INF), 0.0) << i;
    ASSERT_EQ(images.depth_m.type(), CV_32FC1);
    const cv::Mat truth = depthAt(i);
    EXPECT_EQ(images.depth_m.at<float>(0, 0), 0.0f);
    EXPECT_EQ(images.depth_m.at<float>(0, 1), 0.0f);
    EXPECT_EQ(images.depth_m.at<float>(0, 2), 0.0f);
    double worst = 0.0;
    for (int r = 1; r < kH; ++r) {
      for (int c = 0; c < kW; ++c) {
        worst = std::max(worst, std::abs(double(images.depth_m.at<float>(r, c)) - truth.at<float>(r, c)));
      }
    }
    EXPECT_LE(worst, 0.5 / 5000 + 1e-6) << i;
  }
}

TEST(TumSequence, WriterRefusesExistingDirAndCleansUpWhenAbandoned) {
  const fs::path root = test::tempDir();
  fs::create_directories(root / "taken");
  const std::string err = test::inputError([&] { SequenceWriter(root / "taken", smallCamera()); });
  EXPECT_NE(err.find((root / "taken").string() + ": already exists"), std::string::npos) << err;
  {
    SequenceWriter writer(root / "abandoned", smallCamera());
    writer.add(0.0, colourAt(0), depthAt(0), poseAt(0));
    EXPECT_THROW(writer.add(0.0, colourAt(1), depthAt(1), poseAt(1)), std::invalid_argument);
    EXPECT_THROW(writer.add(0.0000004, colourAt(1), depthAt(1), poseAt(1)), std::invalid_argument)
        << "the same microsecond";
    EXPECT_THROW(writer.add(1.0, cv::Mat(kH, kW + 1, CV_8UC3), depthAt(1), poseAt(1)), std::invalid_argument);
  }
  EXPECT_FALSE(fs::exists(root / "abandoned"));
  EXPECT_EQ(test::stagingLeftIn(root), 0);
}

TEST(TumSequence, AssociationIsGreedyNearestWithinTolerance) {
  // As associate.py: pairs by increasing |dt| below 0.02 s, each stamp used once.
  const std::vector<double> rgb = {1.000, 1.033, 1.066, 1.100, 1.300};
  const std::vector<double> depth = {0.990, 1.008, 1.041, 1.050, 1.090, 1.500};
  const auto pairs = associateTimestamps(rgb, depth, 0.02);
  const std::vector<std::pair<std::size_t, std::size_t>> expected = {{0, 1}, {1, 2}, {2, 3}, {3, 4}};
  EXPECT_EQ(pairs, expected);
  // 1.000 is as close to 0.990 as to 1.010: the first candidate in (dt, i, j) order wins, the other is free.
  EXPECT_EQ(associateTimestamps({1.0}, {0.99, 1.01}, 0.02).size(), 1u);
  EXPECT_TRUE(associateTimestamps({1.0}, {1.02}, 0.02).empty()) << "strictly below the tolerance";
}

TEST(TumSequence, LoadsJitteredListsAndSkipsUnpaired) {
  const fs::path dir = writeSequence(test::tempDir() / "seq");
  // Depth stamps shifted by up to 15 ms, one extra depth frame far away, no groundtruth.
  test::writeFile(dir / "depth.txt",
                  "# depth maps\n# file: 'x.bag'\n# timestamp filename\n"
                  "1.012 depth/1.000000.png\n1.041 depth/1.050000.png\n1.113 depth/1.100000.png\n"
                  "1.145 depth/1.150000.png\n1.185 depth/1.200000.png\n7.0 depth/1.200000.png\n");
  fs::remove(dir / "groundtruth.txt");
  const Sequence seq = loadSequence(dir);
  ASSERT_EQ(seq.frames.size(), 5u);
  EXPECT_EQ(seq.unpaired_depth, 1);
  EXPECT_FALSE(seq.has_groundtruth);
  EXPECT_NEAR(seq.frames[2].t_s, 1.1, 1e-12);
  EXPECT_NEAR(seq.frames[2].depth_t_s, 1.113, 1e-12);
  EXPECT_EQ(seq.frames[4].depth_line, 8);
}

TEST(TumSequence, ReadsTumsOwnGroundtruthFiles) {
  // As in rgbd_dataset_freiburg1_xyz: three comment lines, 4-decimal quaternions (|q| = 0.99998).
  const fs::path dir = writeSequence(test::tempDir() / "seq");
  test::writeFile(dir / "groundtruth.txt",
                  "# ground truth trajectory\n# file: 'rgbd_dataset_freiburg1_xyz.bag'\n"
                  "# timestamp tx ty tz qx qy qz qw\n"
                  "0.9900 1.3563 0.6305 1.6380 0.6132 0.5962 -0.3311 -0.3986\n"
                  "1.0000 1.3543 0.6306 1.6360 0.6129 0.5966 -0.3316 -0.3980\n");
  const Sequence seq = loadSequence(dir);
  ASSERT_EQ(seq.groundtruth.size(), 2u);
  EXPECT_EQ(seq.groundtruth[1].t_s, 1.0);
  EXPECT_EQ(seq.groundtruth[0].X_WC.translation(), Eigen::Vector3d(1.3563, 0.6305, 1.6380));
  const Eigen::Quaterniond q(seq.groundtruth[0].X_WC.linear());
  EXPECT_NEAR(std::abs(q.dot(Eigen::Quaterniond(-0.3986, 0.6132, 0.5962, -0.3311).normalized())), 1.0, 1e-12);
  EXPECT_EQ(seq.groundtruth_non_increasing, 0);

  // fr2/desk repeats a timestamp on consecutive lines; other files may go back. Both are read in
  // the file's order and counted (associate() pairs them by evo's rule).
  test::writeFile(dir / "groundtruth.txt",
                  "1.0 0 0 0 0 0 0 1\n1.1 1 0 0 0 0 0 1\n1.1 2 0 0 0 0 0 1\n1.05 3 0 0 0 0 0 1\n1.2 4 0 0 0 0 0 1\n");
  const Sequence repeated = loadSequence(dir);
  ASSERT_EQ(repeated.groundtruth.size(), 5u);
  EXPECT_EQ(repeated.groundtruth_non_increasing, 2);
  EXPECT_EQ(repeated.groundtruth[3].X_WC.translation().x(), 3.0);
}

// The InputError of loadSequence(dir) + loadFrame of every frame.
std::string loadError(const fs::path& dir) {
  return test::inputError([&] {
    const Sequence seq = loadSequence(dir);
    for (std::size_t i = 0; i < seq.frames.size(); ++i) loadFrame(seq, i);
  });
}

TEST(TumSequence, BadFoldersNameTheFileAndLine) {
  const fs::path root = test::tempDir();
  EXPECT_NE(loadError(root / "none").find((root / "none").string() + ": no such sequence directory"),
            std::string::npos);

  struct Case {
    const char* name;
    std::function<void(const fs::path&)> spoil;
    std::string expect;  // after the folder's path
  };
  const Case cases[] = {
      {"no_rgb_list", [](const fs::path& d) { fs::remove(d / "rgb.txt"); }, "/rgb.txt: missing"},
      {"no_depth_list", [](const fs::path& d) { fs::remove(d / "depth.txt"); }, "/depth.txt: missing"},
      {"empty_list", [](const fs::path& d) { test::writeFile(d / "rgb.txt", "# nothing\n"); },
       "/rgb.txt: lists no images"},
      {"malformed_line", [](const fs::path& d) { test::writeFile(d / "rgb.txt", "# c\n1.0 rgb/1.000000.png extra\n"); },
       "/rgb.txt:2: expected 'timestamp filename'"},
      {"bad_timestamp", [](const fs::path& d) { test::writeFile(d / "depth.txt", "x1 depth/1.000000.png\n"); },
       "/depth.txt:1: timestamp 'x1' is not a finite number"},
      {"non_monotonic",
       [](const fs::path& d) {
         test::writeFile(d / "rgb.txt", "# c\n1.0 rgb/1.000000.png\n1.1 rgb/1.100000.png\n1.05 rgb/1.050000.png\n");
       },
       "/rgb.txt:4: timestamp 1.05 does not increase (previous 1.100000 on line 3)"},
      {"no_pairs", [](const fs::path& d) { test::writeFile(d / "depth.txt", "5.0 depth/1.000000.png\n"); },
       ": no rgb.txt/depth.txt pair within 0.02 s"},
      {"missing_rgb", [](const fs::path& d) { fs::remove(d / "rgb/1.100000.png"); },
       "/rgb/1.100000.png (rgb.txt:6): no such image file"},
      {"missing_depth", [](const fs::path& d) { fs::remove(d / "depth/1.150000.png"); },
       "/depth/1.150000.png (depth.txt:7): no such image file"},
      {"unreadable_rgb", [](const fs::path& d) { test::writeFile(d / "rgb/1.050000.png", "not a png"); },
       "/rgb/1.050000.png (rgb.txt:5): cannot read image"},
      {"depth_8bit",
       [](const fs::path& d) { cv::imwrite((d / "depth/1.050000.png").string(), cv::Mat(kH, kW, CV_8UC1)); },
       "/depth/1.050000.png (depth.txt:5): depth image is not 16-bit single-channel (8-bit, 1 channels)"},
      {"depth_size",
       [](const fs::path& d) {
         cv::imwrite((d / "depth/1.100000.png").string(), cv::Mat(kH, kW + 2, CV_16UC1, cv::Scalar(1000)));
       },
       "/depth/1.100000.png (depth.txt:6): depth image is 34x24 but its rgb image"},
      {"rgb_vs_intrinsics",
       [](const fs::path& d) {
         cv::imwrite((d / "rgb/1.000000.png").string(), cv::Mat(kH + 1, kW, CV_8UC3));
         cv::imwrite((d / "depth/1.000000.png").string(), cv::Mat(kH + 1, kW, CV_16UC1));
       },
       "/rgb/1.000000.png (rgb.txt:4): image is 32x25 but"},
      {"groundtruth_row", [](const fs::path& d) { test::writeFile(d / "groundtruth.txt", "# c\n1.0 0 0 0 0 0 0\n"); },
       "/groundtruth.txt:2: expected 8 numbers"},
      {"groundtruth_quaternion",
       [](const fs::path& d) { test::writeFile(d / "groundtruth.txt", "# c\n# c\n1.0 0 0 0 0 0 0 0.9\n"); },
       "/groundtruth.txt:3: quaternion is not unit length"},
      {"intrinsics_key", [](const fs::path& d) { test::writeFile(d / "intrinsics.yaml", "fx: 1\nfy: 1\nfz: 2\n"); },
       "/intrinsics.yaml:3: unknown key 'fz'"},
      {"intrinsics_missing", [](const fs::path& d) { test::writeFile(d / "intrinsics.yaml", "fx: 1\n"); },
       "/intrinsics.yaml:1: missing required key 'width'"},
  };
  for (const Case& c : cases) {
    const fs::path dir = writeSequence(root / c.name);
    c.spoil(dir);
    const std::string err = loadError(dir);
    EXPECT_NE(err.find(dir.string() + c.expect), std::string::npos) << c.name << ": " << err;
  }
}

TEST(TumSequence, AllInvalidDepthAndBlackImagesAreFramesNotErrors) {
  const fs::path dir = test::tempDir() / "seq";
  {
    SequenceWriter writer(dir, smallCamera());
    writer.add(0.0, cv::Mat::zeros(kH, kW, CV_8UC3), cv::Mat::zeros(kH, kW, CV_32FC1), poseAt(0));
    writer.add(0.05, cv::Mat(kH, kW, CV_8UC3, cv::Scalar::all(255)), cv::Mat::zeros(kH, kW, CV_32FC1), poseAt(1));
    writer.finish();
  }
  const Sequence seq = loadSequence(dir);
  ASSERT_EQ(seq.frames.size(), 2u);
  const SequenceImages black = loadFrame(seq, 0);
  EXPECT_EQ(cv::countNonZero(black.depth_m), 0);
  EXPECT_EQ(cv::norm(loadFrame(seq, 1).bgr, cv::NORM_L1), 255.0 * 3 * kW * kH);
}

}  // namespace
}  // namespace tgnav::harness
