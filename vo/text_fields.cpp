#include "vo/text_fields.h"

#include <charconv>
#include <cmath>
#include <stdexcept>
#include <system_error>

namespace tgnav::vo::text {
namespace {

// A field quoted in an error: long ones (a whole CSV row read as one field) are cut.
std::string quoted(const std::string& field) {
  constexpr std::size_t kMaxShown = 40;
  return "'" + (field.size() > kMaxShown ? field.substr(0, kMaxShown) + "..." : field) + "'";
}

std::string trimmed(const std::string& s) {
  const auto first = s.find_first_not_of(" \t\r");
  if (first == std::string::npos) return "";
  return s.substr(first, s.find_last_not_of(" \t\r") - first + 1);
}

}  // namespace

void fail(int line_no, const std::string& what) {
  throw std::invalid_argument("line " + std::to_string(line_no) + ": " + what);
}

std::vector<std::string> splitFields(const std::string& line, char separator) {
  std::vector<std::string> fields;
  if (separator == ',') {
    std::size_t begin = 0;
    for (std::size_t comma; (comma = line.find(',', begin)) != std::string::npos; begin = comma + 1) {
      fields.push_back(trimmed(line.substr(begin, comma - begin)));
    }
    fields.push_back(trimmed(line.substr(begin)));
    return fields;
  }
  std::size_t begin = line.find_first_not_of(" \t\r");
  while (begin != std::string::npos) {
    const std::size_t end = line.find_first_of(" \t\r", begin);
    fields.push_back(line.substr(begin, end == std::string::npos ? std::string::npos : end - begin));
    begin = end == std::string::npos ? end : line.find_first_not_of(" \t\r", end);
  }
  return fields;
}

std::vector<double> numbers(const std::vector<std::string>& fields, std::size_t count, int line_no) {
  std::vector<double> values(count);
  for (std::size_t k = 0; k < count; ++k) {
    const std::string& f = fields.at(k);
    const char* begin = f.data() + (!f.empty() && f[0] == '+' ? 1 : 0);  // from_chars takes no '+'
    const char* end = f.data() + f.size();
    const auto [ptr, ec] = std::from_chars(begin, end, values[k]);
    const std::string where = "field " + std::to_string(k + 1) + " ";
    if (ec == std::errc::result_out_of_range) fail(line_no, where + quoted(f) + " is out of the range of a double");
    if (ec != std::errc() || ptr != end || f.empty()) fail(line_no, where + quoted(f) + " is not a number");
    if (!std::isfinite(values[k])) fail(line_no, where + "is " + f + "; a pose must be finite");
  }
  return values;
}

std::vector<double> exactNumbers(const std::string& line, std::size_t count, const std::string& layout, int line_no) {
  const std::vector<std::string> fields = splitFields(line, ' ');
  std::vector<double> v = numbers(fields, fields.size(), line_no);
  if (v.size() != count) {
    fail(line_no, "expected " + std::to_string(count) + " numbers (" + layout + "), got " + std::to_string(v.size()));
  }
  return v;
}

void appendNumber(std::string& out, double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof(buf), v);
  out.append(buf, r.ptr);
}

std::string str(double v) {
  std::string s;
  appendNumber(s, v);
  return s;
}

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

Eigen::Matrix3d unitQuaternionRotation(const Eigen::Quaterniond& q, int line_no) {
  const double norm = q.norm();
  if (!(std::abs(norm - 1.0) <= kUnitTolerance)) {
    fail(line_no, "quaternion is not unit length (|q| = " + str(norm) + ", tolerance " + str(kUnitTolerance) + ")");
  }
  return q.normalized().toRotationMatrix();
}

}  // namespace tgnav::vo::text
