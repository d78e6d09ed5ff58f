#include "vo/trajectory_formats.h"

#include <Eigen/SVD>
#include <cmath>
#include <stdexcept>

#include "vo/text_fields.h"

namespace tgnav::vo {
namespace {

// KITTI's ground truth writes 6 significant digits: R R^T is off the identity by ~1e-6.
constexpr double kOrthonormalTolerance = 1e-3;
// The largest |t| in seconds whose nanoseconds fit an int64.
constexpr double kMaxEurocTimeS = 9.2e9;

Eigen::Matrix3d nearestRotation(const Eigen::Matrix3d& R, int line_no) {
  const double off = (R * R.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (!(off <= kOrthonormalTolerance)) {
    text::fail(line_no, "rotation is not orthonormal (max |R R^T - I| = " + text::str(off) + ", tolerance " +
                            text::str(kOrthonormalTolerance) + ")");
  }
  if (!(R.determinant() > 0.0)) text::fail(line_no, "rotation is a reflection (det R < 0)");
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
  return svd.matrixU() * svd.matrixV().transpose();
}

}  // namespace

TrajectoryFormat parseTrajectoryFormat(const std::string& name) {
  for (const TrajectoryFormat f : {TrajectoryFormat::kTum, TrajectoryFormat::kKitti, TrajectoryFormat::kEuroc}) {
    if (name == toString(f)) return f;
  }
  throw std::invalid_argument("'" + name + "' is not a trajectory format; expected tum, kitti or euroc");
}

const char* toString(TrajectoryFormat format) {
  switch (format) {
    case TrajectoryFormat::kTum:
      return "tum";
    case TrajectoryFormat::kKitti:
      return "kitti";
    case TrajectoryFormat::kEuroc:
      return "euroc";
  }
  return "?";
}

std::string toKitti(const std::vector<StampedPose>& poses) {
  std::string out;
  for (const StampedPose& p : poses) {
    const Eigen::Matrix<double, 3, 4> M = p.X_WC.matrix().topRows<3>();
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c) {
        text::appendNumber(out, M(r, c));
        out.push_back(r == 2 && c == 3 ? '\n' : ' ');
      }
    }
  }
  return out;
}

std::vector<StampedPose> parseKitti(const std::string& kitti, std::vector<int>* lines) {
  std::vector<StampedPose> poses;
  text::forEachDataLine(kitti, [&](const std::string& line, int line_no) {
    const std::vector<double> v = text::exactNumbers(line, 12, "the 3x4 pose matrix [R | t] row by row", line_no);
    Eigen::Matrix3d R;
    R << v[0], v[1], v[2], v[4], v[5], v[6], v[8], v[9], v[10];
    StampedPose p;
    p.t_s = static_cast<double>(poses.size());
    p.X_WC.linear() = nearestRotation(R, line_no);
    p.X_WC.translation() = Eigen::Vector3d(v[3], v[7], v[11]);
    poses.push_back(p);
    if (lines != nullptr) lines->push_back(line_no);
  });
  return poses;
}

std::string toEuroc(const std::vector<StampedPose>& poses) {
  std::string out = "#timestamp [ns],p_RS_R_x [m],p_RS_R_y [m],p_RS_R_z [m],q_RS_w [],q_RS_x [],q_RS_y [],q_RS_z []\n";
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const StampedPose& p = poses[i];
    if (!(std::abs(p.t_s) < kMaxEurocTimeS)) {
      throw std::invalid_argument("toEuroc: pose " + std::to_string(i) + " has timestamp " + text::str(p.t_s) +
                                  " s, which is not a number of nanoseconds in an int64");
    }
    out += std::to_string(std::llround(p.t_s * 1e9));
    const Eigen::Quaterniond q = text::canonical(Eigen::Quaterniond(p.X_WC.linear()));
    const Eigen::Vector3d& t = p.X_WC.translation();
    for (const double v : {t.x(), t.y(), t.z(), q.w(), q.x(), q.y(), q.z()}) {
      out.push_back(',');
      text::appendNumber(out, v);
    }
    out.push_back('\n');
  }
  return out;
}

std::vector<StampedPose> parseEuroc(const std::string& euroc, std::vector<int>* lines) {
  std::vector<StampedPose> poses;
  text::forEachDataLine(euroc, [&](const std::string& line, int line_no) {
    const std::vector<std::string> fields = text::splitFields(line, ',');
    if (fields.size() < 8) {
      text::fail(line_no, "expected at least 8 comma-separated numbers (timestamp [ns], p x y z, q w x y z), got " +
                              std::to_string(fields.size()));
    }
    const std::vector<double> v = text::numbers(fields, 8, line_no);
    StampedPose p;
    p.t_s = v[0] / 1e9;
    p.X_WC.linear() = text::unitQuaternionRotation(Eigen::Quaterniond(v[4], v[5], v[6], v[7]), line_no);
    p.X_WC.translation() = Eigen::Vector3d(v[1], v[2], v[3]);
    poses.push_back(p);
    if (lines != nullptr) lines->push_back(line_no);
  });
  return poses;
}

std::string toTrajectory(const std::vector<StampedPose>& poses, TrajectoryFormat format) {
  switch (format) {
    case TrajectoryFormat::kTum:
      return toTum(poses);
    case TrajectoryFormat::kKitti:
      return toKitti(poses);
    case TrajectoryFormat::kEuroc:
      return toEuroc(poses);
  }
  throw std::invalid_argument("toTrajectory: unknown format");
}

std::vector<StampedPose> parseTrajectory(const std::string& content, TrajectoryFormat format) {
  std::vector<StampedPose> poses;
  switch (format) {
    case TrajectoryFormat::kTum:
      poses = parseTum(content);
      break;
    case TrajectoryFormat::kKitti:
      poses = parseKitti(content);
      break;
    case TrajectoryFormat::kEuroc:
      poses = parseEuroc(content);
      break;
  }
  return poses;
}

}  // namespace tgnav::vo
