#pragma once
// The trajectory files users bring, beside TUM (vo/tum.h), as evo reads them:
//   KITTI odometry poses: one pose per line, 12 numbers = the 3x4 matrix [R | t] of the camera in
//     the world, row by row; no timestamps: poses are associated by line, so the index of the
//     pose (0, 1, 2, ...) is its timestamp.
//   EuRoC ground-truth CSV: "#timestamp [ns], p_RS_R_x, p_RS_R_y, p_RS_R_z, q_RS_w, q_RS_x,
//     q_RS_y, q_RS_z, ..." (extra columns allowed and ignored), time in integer nanoseconds,
//     quaternion w first.
// Every writer's text reads back to the same poses: numbers are the shortest decimals that read
// back to the same double (as toTum), except EuRoC's times, which are whole nanoseconds. Readers
// skip blank lines and '#' lines, and throw std::invalid_argument "line N: what" (N 1-based) for a
// line with too few or too many numbers, a field that is not a finite number, a quaternion that is
// not unit length within 1e-3, or a KITTI rotation that is not orthonormal within 1e-3.
#include <string>
#include <vector>

#include "vo/tum.h"

namespace tgnav::vo {

enum class TrajectoryFormat { kTum, kKitti, kEuroc };
// "tum" | "kitti" | "euroc"; std::invalid_argument otherwise.
TrajectoryFormat parseTrajectoryFormat(const std::string& name);
const char* toString(TrajectoryFormat format);

// Rows "r00 r01 r02 tx r10 r11 r12 ty r20 r21 r22 tz"; the timestamps are not written.
std::string toKitti(const std::vector<StampedPose>& poses);
// Exactly 12 numbers per line; the rotation must be orthonormal (max |R R^T - I| <= 1e-3) and
// proper (det > 0), and is replaced by the nearest rotation (SVD). t_s = the pose's index.
// `lines`, when given, receives the line of each pose.
std::vector<StampedPose> parseKitti(const std::string& text, std::vector<int>* lines = nullptr);

// A "#timestamp [ns],p_RS_R_x [m],...,q_RS_z []" header, then "ns,px,py,pz,qw,qx,qy,qz" rows, the
// quaternion as toTum's (w >= 0). Times are rounded to whole nanoseconds, so they read back within
// 1e-9 s, or within the double's own resolution for Unix times (about 2.4e-7 s in 2014).
// std::invalid_argument for a timestamp that is not finite or beyond +-9.2e9 s (int64 ns).
std::string toEuroc(const std::vector<StampedPose>& poses);
// At least 8 comma-separated numbers per line (those past the 8th are not read); t_s = ns / 1e9.
std::vector<StampedPose> parseEuroc(const std::string& text, std::vector<int>* lines = nullptr);

// The writer or reader of `format`. Timestamps are taken in the file's order, repeated or going
// back included (associate() pairs them by evo's rule; nonIncreasingTimes() counts them).
std::string toTrajectory(const std::vector<StampedPose>& poses, TrajectoryFormat format);
std::vector<StampedPose> parseTrajectory(const std::string& text, TrajectoryFormat format);

}  // namespace tgnav::vo
