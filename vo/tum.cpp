#include "vo/tum.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace tgnav::vo {

std::string toTum(const std::vector<StampedPose>& poses) {
  std::ostringstream out;
  out.precision(9);
  out << std::fixed;
  out << "# timestamp tx ty tz qx qy qz qw\n";
  for (const StampedPose& p : poses) {
    Eigen::Quaterniond q(p.X_WC.linear());
    if (q.w() < 0.0) q.coeffs() = -q.coeffs();  // one sign per rotation: w >= 0
    const Eigen::Vector3d& t = p.X_WC.translation();
    out << p.t_s << ' ' << t.x() << ' ' << t.y() << ' ' << t.z() << ' ' << q.x() << ' ' << q.y() << ' '
        << q.z() << ' ' << q.w() << '\n';
  }
  return out.str();
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
    double v[8];
    for (double& x : v) {
      if (!(fields >> x) || !std::isfinite(x)) {
        throw std::invalid_argument("line " + std::to_string(line_no) + ": expected 8 numbers "
                                    "'timestamp tx ty tz qx qy qz qw'");
      }
    }
    std::string extra;
    if (fields >> extra) throw std::invalid_argument("line " + std::to_string(line_no) + ": more than 8 columns");
    const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    if (std::abs(q.norm() - 1.0) > 1e-3) {
      throw std::invalid_argument("line " + std::to_string(line_no) + ": quaternion is not unit length");
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
