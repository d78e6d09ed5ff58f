#pragma once
// TUM RGB-D trajectory text: "timestamp tx ty tz qx qy qz qw" per line, '#' comments, the pose
// of the camera in the world (the format evo and the TUM benchmark tools read).
#include <Eigen/Geometry>
#include <string>
#include <vector>

namespace tgnav::vo {

struct StampedPose {
  double t_s = 0.0;
  Eigen::Isometry3d X_WC = Eigen::Isometry3d::Identity();
};

// A '# timestamp tx ty tz qx qy qz qw' header, then one line per pose. Every number is the
// shortest decimal that reads back to the same double (std::to_chars), so parseTum returns the
// timestamps and translations bit-identical, and reads the quaternion coefficients back exactly as
// written. The quaternion is Eigen's of the rotation matrix, with one sign per rotation: w >= 0
// (w == 0: the first non-zero of x, y, z positive). The rotation matrix parseTum rebuilds from it
// agrees with the original to rounding (~1e-16), not bit for bit: a second toTum of parsed poses can
// differ from the first in the last digits of the quaternion (a 3x3 rotation matrix and a
// quaternion are not exact inverses in floating point). Non-finite values are written as "inf" /
// "nan", which parseTum rejects.
std::string toTum(const std::vector<StampedPose>& poses);
// Reads toTum's format (any run of spaces or tabs between numbers; blank lines and '#' lines
// skipped). Throws std::invalid_argument naming the (1-based) line for a line that is not 8 finite
// numbers ("line 3: expected 8 numbers (timestamp tx ty tz qx qy qz qw), got 12": a KITTI file,
// say), or whose quaternion's norm is not within 1e-3 of 1 (vo::text::kUnitTolerance); a
// quaternion within that is normalised. Timestamps are not checked for order here (associate()
// and parseTrajectory() do). `lines`, when given, receives the line of each pose.
std::vector<StampedPose> parseTum(const std::string& text, std::vector<int>* lines = nullptr);

}  // namespace tgnav::vo
