#include "vo/tum.h"

#include "vo/text_fields.h"

namespace tgnav::vo {

std::string toTum(const std::vector<StampedPose>& poses) {
  std::string out = "# timestamp tx ty tz qx qy qz qw\n";
  for (const StampedPose& p : poses) {
    const Eigen::Quaterniond q = text::canonical(Eigen::Quaterniond(p.X_WC.linear()));
    const Eigen::Vector3d& t = p.X_WC.translation();
    for (const double v : {p.t_s, t.x(), t.y(), t.z(), q.x(), q.y(), q.z()}) {
      text::appendNumber(out, v);
      out.push_back(' ');
    }
    text::appendNumber(out, q.w());
    out.push_back('\n');
  }
  return out;
}

std::vector<StampedPose> parseTum(const std::string& tum, std::vector<int>* lines) {
  std::vector<StampedPose> poses;
  text::forEachDataLine(tum, [&](const std::string& line, int line_no) {
    const std::vector<double> v = text::exactNumbers(line, 8, "timestamp tx ty tz qx qy qz qw", line_no);
    StampedPose p;
    p.t_s = v[0];
    p.X_WC.linear() = text::unitQuaternionRotation(Eigen::Quaterniond(v[7], v[4], v[5], v[6]), line_no);
    p.X_WC.translation() = Eigen::Vector3d(v[1], v[2], v[3]);
    poses.push_back(p);
    if (lines != nullptr) lines->push_back(line_no);
  });
  return poses;
}

}  // namespace tgnav::vo
