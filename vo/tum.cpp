#include "vo/tum.h"

#include <charconv>
#include <cmath>
#include <locale>
#include <sstream>
#include <stdexcept>

namespace tgnav::vo {
namespace {

// |q| must be within this of 1; within it, q is normalised. Loose enough for the TUM RGB-D
// benchmark's own ground truth, which rounds quaternions to 4 decimals (|q| - 1 ~ 1e-5).
constexpr double kUnitTolerance = 1e-3;

// Shortest decimal text that reads back to the same double (std::to_chars, locale-independent).
void appendNumber(std::string& out, double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof(buf), v);
  out.append(buf, r.ptr);
}

// One quaternion per rotation: w >= 0, and for w == 0 (half turns) the first non-zero of
// x, y, z positive; no negative zeros.
Eigen::Quaterniond canonical(Eigen::Quaterniond q) {
  bool flip = q.w() < 0.0;
  if (q.w() == 0.0) {
    for (int i = 0; i < 3; ++i) {
      if (q.coeffs()[i] != 0.0) {
        flip = q.coeffs()[i] < 0.0;
        break;
      }
    }
  }
  if (flip) q.coeffs() = -q.coeffs();
  q.coeffs().array() += 0.0;  // -0 + 0 = +0
  return q;
}

[[noreturn]] void fail(int line_no, const std::string& what) {
  throw std::invalid_argument("line " + std::to_string(line_no) + ": " + what);
}

}  // namespace

std::string toTum(const std::vector<StampedPose>& poses) {
  std::string out = "# timestamp tx ty tz qx qy qz qw\n";
  for (const StampedPose& p : poses) {
    const Eigen::Quaterniond q = canonical(Eigen::Quaterniond(p.X_WC.linear()));
    const Eigen::Vector3d& t = p.X_WC.translation();
    for (const double v : {p.t_s, t.x(), t.y(), t.z(), q.x(), q.y(), q.z()}) {
      appendNumber(out, v);
      out.push_back(' ');
    }
    appendNumber(out, q.w());
    out.push_back('\n');
  }
  return out;
}

std::vector<StampedPose> parseTum(const std::string& text) {
  std::vector<StampedPose> poses;
  std::istringstream in(text);
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream fields(line);
    fields.imbue(std::locale::classic());  // '.' decimal point whatever the global locale
    double v[8];
    for (double& x : v) {
      if (!(fields >> x) || !std::isfinite(x)) fail(line_no, "expected 8 numbers 'timestamp tx ty tz qx qy qz qw'");
    }
    std::string extra;
    if (fields >> extra) fail(line_no, "more than 8 columns");
    const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    const double norm = q.norm();
    if (!(std::abs(norm - 1.0) <= kUnitTolerance)) {
      std::string msg = "quaternion is not unit length (|q| = ";
      appendNumber(msg, norm);
      fail(line_no, msg + ", tolerance 1e-6)");
    }
    StampedPose p;
    p.t_s = v[0];
    p.X_WC.linear() = q.normalized().toRotationMatrix();
    p.X_WC.translation() = Eigen::Vector3d(v[1], v[2], v[3]);
    poses.push_back(p);
  }
  return poses;
}

}  // namespace tgnav::vo
