#include "harness/io/tum_sequence.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <locale>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>
#include <system_error>
#include <tuple>

#include "harness/base/errors.h"
#include "harness/base/files.h"
#include "harness/config/yaml_util.h"
#include "harness/io/staged_output.h"
#include "vo/metrics.h"

namespace tgnav::harness {

namespace fs = std::filesystem;

namespace {

std::string stamp(double t_s) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.6f", t_s);
  return buf;
}

std::string listHeader(const std::string& what) {
  return "# " + what + "\n# file: 'tgnav fly --record'\n# timestamp filename\n";
}

bool isCommentOrBlank(const std::string& line) {
  const auto first = line.find_first_not_of(" \t\r");
  return first == std::string::npos || line[first] == '#';
}

struct ListEntry {
  double t_s = 0.0;
  fs::path file;
  int line = 0;
};

// rgb.txt / depth.txt: "timestamp filename" lines, strictly increasing timestamps.
std::vector<ListEntry> readList(const fs::path& dir, const std::string& name) {
  const fs::path file = dir / name;
  if (!isRegularFile(file)) {
    throw InputError(file.string() +
                     ": missing (a TUM RGB-D sequence folder holds rgb.txt, depth.txt, rgb/ and depth/)");
  }
  std::istringstream in(readTextFile(file));
  std::vector<ListEntry> entries;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (isCommentOrBlank(line)) continue;
    const std::string where = file.string() + ":" + std::to_string(line_no) + ": ";
    std::istringstream fields(line);
    std::string t_text;
    std::string image;
    std::string extra;
    fields >> t_text >> image;
    if (image.empty() || (fields >> extra)) {
      throw InputError(where + "expected 'timestamp filename', got '" + line + "'");
    }
    double t = 0.0;
    std::size_t used = 0;
    try {
      t = std::stod(t_text, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != t_text.size() || !std::isfinite(t)) {
      throw InputError(where + "timestamp '" + t_text + "' is not a finite number");
    }
    if (!entries.empty() && !(t > entries.back().t_s)) {
      throw InputError(where + "timestamp " + t_text + " does not increase (previous " + stamp(entries.back().t_s) +
                       " on line " + std::to_string(entries.back().line) + ")");
    }
    entries.push_back(ListEntry{t, dir / image, line_no});
  }
  if (entries.empty()) throw InputError(file.string() + ": lists no images");
  return entries;
}

// TUM's own groundtruth.txt files write quaternions with 4 decimals (|q| off 1 by up to ~1e-4),
// which vo::parseTum (tolerance 1e-6) refuses: rows of 8 numbers whose |q| is within this of 1
// get their quaternion normalised first. Everything else passes unchanged, line for line, so
// parseTum's errors keep their line numbers.
constexpr double kTumQuaternionTolerance = 1e-3;

std::string normaliseQuaternions(const std::string& text) {
  std::istringstream in(text);
  std::ostringstream out;
  out.imbue(std::locale::classic());
  out.precision(17);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    fields.imbue(std::locale::classic());
    double v[8];
    bool ok = !isCommentOrBlank(line);
    for (double& x : v) ok = ok && (fields >> x) && std::isfinite(x);
    std::string extra;
    ok = ok && !(fields >> extra);
    const double norm = ok ? std::sqrt(v[4] * v[4] + v[5] * v[5] + v[6] * v[6] + v[7] * v[7]) : 0.0;
    if (!ok || std::abs(norm - 1.0) > kTumQuaternionTolerance) {
      out << line << '\n';
      continue;
    }
    for (int i = 4; i < 8; ++i) v[i] /= norm;
    for (int i = 0; i < 8; ++i) out << (i ? " " : "") << v[i];
    out << '\n';
  }
  return out.str();
}

std::vector<vo::StampedPose> readGroundtruth(const fs::path& file) {
  const std::string text = readTextFile(file);
  std::vector<vo::StampedPose> poses;
  try {
    poses = vo::parseTum(normaliseQuaternions(text));
  } catch (const std::invalid_argument& e) {
    throw InputError(inFile(file.string(), e.what()));
  }
  if (poses.empty()) throw InputError(file.string() + ": holds no poses");
  return poses;
}

void readIntrinsics(const fs::path& file, Sequence& seq) {
  const YamlDoc doc = YamlDoc::load(file);
  vo::CameraIntrinsics k;
  k.width_px = -1;
  k.height_px = -1;
  k.fx = k.fy = k.cx = k.cy = std::nan("");
  FieldReader(doc, doc.root(), "")
      .read("width", k.width_px)
      .read("height", k.height_px)
      .read("fx", k.fx)
      .read("fy", k.fy)
      .read("cx", k.cx)
      .read("cy", k.cy)
      .read("depth_scale", seq.depth_scale)
      .finish();
  for (const char* key : {"width", "height", "fx", "fy", "cx", "cy"}) {
    if (!doc.root()[key]) doc.fail(doc.root(), std::string("missing required key '") + key + "'");
  }
  auto positive = [&](const char* key, double v) {
    if (!(v > 0.0)) doc.fail(doc.root()[key], std::string("key '") + key + "' must be > 0");
  };
  positive("width", k.width_px);
  positive("height", k.height_px);
  positive("fx", k.fx);
  positive("fy", k.fy);
  if (doc.root()["depth_scale"]) positive("depth_scale", seq.depth_scale);
  seq.intrinsics = k;
}

cv::Mat readImage(const fs::path& image, const fs::path& list, int line) {
  const std::string where = image.string() + " (" + list.filename().string() + ":" + std::to_string(line) + ")";
  if (!isRegularFile(image)) throw InputError(where + ": no such image file");
  cv::Mat m;
  try {
    m = cv::imread(image.string(), cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception&) {
    m.release();
  }
  if (m.empty()) throw InputError(where + ": cannot read image");
  return m;
}

}  // namespace

// --- writer ---------------------------------------------------------------------------------

SequenceWriter::SequenceWriter(const fs::path& dir, const vo::CameraIntrinsics& intrinsics) : intrinsics_(intrinsics) {
  const fs::path target = dir.has_filename() ? dir : dir.parent_path();  // "seq/" is "seq"
  if (!target.has_filename() || target.filename() == "." || target.filename() == "..") {
    throw InputError("'" + dir.string() + "': not a name for a new directory");
  }
  std::error_code ec;
  if (fs::exists(target, ec)) {
    throw InputError(target.string() + ": already exists; a sequence is written into a new directory");
  }
  staged_ = std::make_unique<StagedDir>(target, "--record");
  makeOutputDir(staged_->staging() / "rgb");
  makeOutputDir(staged_->staging() / "depth");
  rgb_list_ = listHeader("color images");
  depth_list_ = listHeader("depth maps");
}

SequenceWriter::~SequenceWriter() = default;

void SequenceWriter::add(double t_s, const cv::Mat& bgr, const cv::Mat& depth_m, const Eigen::Isometry3d& X_WC) {
  if (finished_) throw std::logic_error("SequenceWriter::add after finish");
  // Every file holds the time as the lists write it (microseconds), so that they agree exactly.
  const std::string t_text = stamp(t_s);
  const double t_us = std::isfinite(t_s) ? std::stod(t_text) : t_s;
  if (!std::isfinite(t_us) || (!groundtruth_.empty() && !(t_us > groundtruth_.back().t_s))) {
    throw std::invalid_argument("SequenceWriter: time " + t_text + " s does not come after the previous frame's " +
                                (groundtruth_.empty() ? std::string("-") : stamp(groundtruth_.back().t_s)));
  }
  const cv::Size size(intrinsics_.width_px, intrinsics_.height_px);
  if (bgr.type() != CV_8UC3 || bgr.size() != size || depth_m.type() != CV_32FC1 || depth_m.size() != size) {
    throw std::invalid_argument("SequenceWriter: frame is not a CV_8UC3 image and CV_32FC1 depth of " +
                                std::to_string(size.width) + "x" + std::to_string(size.height));
  }
  cv::Mat depth(depth_m.size(), CV_16UC1);
  for (int r = 0; r < depth_m.rows; ++r) {
    const float* in = depth_m.ptr<float>(r);
    auto* out = depth.ptr<std::uint16_t>(r);
    for (int c = 0; c < depth_m.cols; ++c) {
      const double units = std::round(static_cast<double>(in[c]) * kTumDepthScale);
      out[c] = (std::isfinite(units) && units > 0.0 && units <= 65535.0) ? static_cast<std::uint16_t>(units) : 0;
    }
  }
  const std::string name = t_text + ".png";
  writeImageAtomic(staged_->staging() / "rgb" / name, bgr);
  writeImageAtomic(staged_->staging() / "depth" / name, depth);
  rgb_list_ += t_text + " rgb/" + name + "\n";
  depth_list_ += t_text + " depth/" + name + "\n";
  groundtruth_.push_back(vo::StampedPose{t_us, X_WC});
}

void SequenceWriter::finish() {
  if (finished_) return;
  const fs::path& tmp = staged_->staging();
  writeFileAtomic(tmp / "rgb.txt", rgb_list_);
  writeFileAtomic(tmp / "depth.txt", depth_list_);
  writeFileAtomic(tmp / "groundtruth.txt",
                  "# ground truth trajectory\n# file: 'tgnav fly --record'\n" + vo::toTum(groundtruth_));
  writeFileAtomic(tmp / "intrinsics.yaml", intrinsicsYaml(intrinsics_, kTumDepthScale));
  staged_->commit(OnExisting::kRefuse, "recording");
  finished_ = true;
}

// --- reader ---------------------------------------------------------------------------------

std::vector<std::pair<std::size_t, std::size_t>> associateTimestamps(const std::vector<double>& a,
                                                                     const std::vector<double>& b, double max_dt_s) {
  // Candidates (|dt|, i, j) within the window; both lists are sorted, so a sliding start in b.
  std::vector<std::tuple<double, std::size_t, std::size_t>> candidates;
  std::size_t lo = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    while (lo < b.size() && b[lo] <= a[i] - max_dt_s) ++lo;
    for (std::size_t j = lo; j < b.size() && b[j] < a[i] + max_dt_s; ++j) {
      const double dt = std::abs(a[i] - b[j]);
      if (dt < max_dt_s) candidates.emplace_back(dt, i, j);
    }
  }
  std::sort(candidates.begin(), candidates.end());
  std::vector<bool> used_a(a.size(), false);
  std::vector<bool> used_b(b.size(), false);
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  for (const auto& [dt, i, j] : candidates) {
    if (used_a[i] || used_b[j]) continue;
    used_a[i] = used_b[j] = true;
    pairs.emplace_back(i, j);
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

Sequence loadSequence(const fs::path& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw InputError(dir.string() + ": no such sequence directory");
  Sequence seq;
  seq.dir = dir;
  const std::vector<ListEntry> rgb = readList(dir, "rgb.txt");
  const std::vector<ListEntry> depth = readList(dir, "depth.txt");
  if (fs::exists(dir / "intrinsics.yaml")) readIntrinsics(dir / "intrinsics.yaml", seq);
  if (fs::exists(dir / "groundtruth.txt")) {
    seq.groundtruth = readGroundtruth(dir / "groundtruth.txt");
    seq.has_groundtruth = true;
    seq.groundtruth_non_increasing = vo::nonIncreasingTimes(seq.groundtruth);
  }

  std::vector<double> t_rgb;
  std::vector<double> t_depth;
  t_rgb.reserve(rgb.size());
  t_depth.reserve(depth.size());
  for (const ListEntry& e : rgb) t_rgb.push_back(e.t_s);
  for (const ListEntry& e : depth) t_depth.push_back(e.t_s);
  const auto pairs = associateTimestamps(t_rgb, t_depth, kMaxPairDtS);
  if (pairs.empty()) {
    std::ostringstream msg;
    msg << dir.string() << ": no rgb.txt/depth.txt pair within " << kMaxPairDtS << " s (rgb " << stamp(t_rgb.front())
        << " .. " << stamp(t_rgb.back()) << " s, depth " << stamp(t_depth.front()) << " .. " << stamp(t_depth.back())
        << " s)";
    throw InputError(msg.str());
  }
  for (const auto& [i, j] : pairs) {
    SequenceEntry e;
    e.t_s = rgb[i].t_s;
    e.depth_t_s = depth[j].t_s;
    e.rgb = rgb[i].file;
    e.depth = depth[j].file;
    e.rgb_line = rgb[i].line;
    e.depth_line = depth[j].line;
    if (!isRegularFile(e.rgb)) {
      throw InputError(e.rgb.string() + " (rgb.txt:" + std::to_string(e.rgb_line) + "): no such image file");
    }
    if (!isRegularFile(e.depth)) {
      throw InputError(e.depth.string() + " (depth.txt:" + std::to_string(e.depth_line) + "): no such image file");
    }
    seq.frames.push_back(e);
  }
  seq.unpaired_rgb = static_cast<int>(rgb.size() - pairs.size());
  seq.unpaired_depth = static_cast<int>(depth.size() - pairs.size());
  return seq;
}

SequenceImages loadFrame(const Sequence& seq, std::size_t index) {
  const SequenceEntry& e = seq.frames.at(index);
  const std::string rgb_where = e.rgb.string() + " (rgb.txt:" + std::to_string(e.rgb_line) + ")";
  const std::string depth_where = e.depth.string() + " (depth.txt:" + std::to_string(e.depth_line) + ")";
  SequenceImages out;
  const cv::Mat rgb = readImage(e.rgb, "rgb.txt", e.rgb_line);
  switch (rgb.type()) {
    case CV_8UC3:
    case CV_8UC1:
      out.bgr = rgb;
      break;
    case CV_8UC4:
      cv::cvtColor(rgb, out.bgr, cv::COLOR_BGRA2BGR);
      break;
    default:
      throw InputError(rgb_where + ": rgb image is not 8-bit with 1, 3 or 4 channels (depth " +
                       std::to_string(rgb.depth()) + ", " + std::to_string(rgb.channels()) + " channels)");
  }
  const cv::Mat depth = readImage(e.depth, "depth.txt", e.depth_line);
  if (depth.type() != CV_16UC1) {
    throw InputError(depth_where + ": depth image is not 16-bit single-channel (" +
                     std::to_string(8 * static_cast<int>(depth.elemSize1())) + "-bit, " +
                     std::to_string(depth.channels()) + " channels)");
  }
  if (depth.size() != rgb.size()) {
    throw InputError(depth_where + ": depth image is " + std::to_string(depth.cols) + "x" + std::to_string(depth.rows) +
                     " but its rgb image " + e.rgb.string() + " is " + std::to_string(rgb.cols) + "x" +
                     std::to_string(rgb.rows));
  }
  if (seq.intrinsics && (rgb.cols != seq.intrinsics->width_px || rgb.rows != seq.intrinsics->height_px)) {
    throw InputError(rgb_where + ": image is " + std::to_string(rgb.cols) + "x" + std::to_string(rgb.rows) + " but " +
                     (seq.dir / "intrinsics.yaml").string() + " says " + std::to_string(seq.intrinsics->width_px) +
                     "x" + std::to_string(seq.intrinsics->height_px));
  }
  depth.convertTo(out.depth_m, CV_32FC1, 1.0 / seq.depth_scale);
  return out;
}

std::string intrinsicsYaml(const vo::CameraIntrinsics& k, double depth_scale, const YAML::Node& extra) {
  YAML::Emitter out;
  out.SetDoublePrecision(17);
  out << YAML::Comment(
      "Pinhole intrinsics of the RGB-D images (pixel centres on integers, as in OpenCV). Depth images "
      "are uint16, depth_scale units per metre, 0 = invalid. Camera frame: x right, y down, z forward.");
  out << YAML::BeginMap;
  out << YAML::Key << "width" << YAML::Value << k.width_px;
  out << YAML::Key << "height" << YAML::Value << k.height_px;
  out << YAML::Key << "fx" << YAML::Value << k.fx;
  out << YAML::Key << "fy" << YAML::Value << k.fy;
  out << YAML::Key << "cx" << YAML::Value << k.cx;
  out << YAML::Key << "cy" << YAML::Value << k.cy;
  out << YAML::Key << "depth_scale" << YAML::Value << depth_scale;
  if (extra.IsMap()) {
    for (const auto& kv : extra) out << YAML::Key << kv.first << YAML::Value << kv.second;
  }
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace tgnav::harness
