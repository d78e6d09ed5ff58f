#pragma once
// The pieces the trajectory text formats share (vo/tum.h, vo/trajectory_formats.h): lines split
// into fields, numbers read with the C locale and checked finite, numbers written as the shortest
// decimal that reads back to the same double, one sign per rotation quaternion, and errors as
// std::invalid_argument "line N: what" (N 1-based), which the harness turns into "FILE:N: what".
#include <Eigen/Geometry>
#include <string>
#include <vector>

namespace tgnav::vo::text {

// |q| must be within this of 1; within it, q is normalised. Loose enough for the TUM RGB-D
// benchmark's own ground truth, which rounds quaternions to 4 decimals (|q| - 1 ~ 1e-5).
constexpr double kUnitTolerance = 1e-3;

[[noreturn]] void fail(int line_no, const std::string& what);

// Calls fn(line, line_no) for each line of `text` that is neither blank nor a '#' comment.
template <typename Fn>
void forEachDataLine(const std::string& text, Fn fn) {
  int line_no = 0;
  std::size_t begin = 0;
  while (begin < text.size()) {
    std::size_t end = text.find('\n', begin);
    if (end == std::string::npos) end = text.size();
    const std::string line = text.substr(begin, end - begin);
    ++line_no;
    begin = end + 1;
    const auto first = line.find_first_not_of(" \t\r");
    if (first != std::string::npos && line[first] != '#') fn(line, line_no);
  }
}

// The fields of `line`: separated by runs of spaces and tabs (separator ' '), or by commas
// (separator ','; spaces and tabs around a field dropped). A trailing '\r' is ignored.
std::vector<std::string> splitFields(const std::string& line, char separator);

// The first `count` fields (there must be as many) as finite numbers; otherwise fail(line_no)
// with "field K '<text>' is not a number" or "field K is <value>; a pose must be finite".
std::vector<double> numbers(const std::vector<std::string>& fields, std::size_t count, int line_no);

// The numbers of a line separated by spaces and tabs: every field a finite number, and exactly
// `count` of them, else fail(line_no) ("expected 8 numbers (<layout>), got 12").
std::vector<double> exactNumbers(const std::string& line, std::size_t count, const std::string& layout, int line_no);

// Shortest decimal text that reads back to the same double (std::to_chars, locale-independent);
// non-finite values as "inf", "-inf", "nan".
void appendNumber(std::string& out, double v);
std::string str(double v);

// One quaternion per rotation: w >= 0, and for w == 0 (half turns) the first non-zero of x, y, z
// positive; no negative zeros.
Eigen::Quaterniond canonical(Eigen::Quaterniond q);

// The rotation of q, normalised when |q| is within kUnitTolerance of 1; fail(line_no) otherwise.
Eigen::Matrix3d unitQuaternionRotation(const Eigen::Quaterniond& q, int line_no);

}  // namespace tgnav::vo::text
