#include "harness/io/movingai_scen.h"

#include <cctype>
#include <charconv>
#include <climits>
#include <cmath>
#include <fstream>
#include <string>
#include <system_error>
#include <vector>

#include "harness/base/errors.h"
#include "harness/io/text_fields.h"

namespace tgnav::harness {

namespace {

constexpr int kMaxBucket = 999999999;
constexpr int kFieldCount = 9;
constexpr const char* kFieldNames[kFieldCount] = {"bucket",  "map",    "map_width", "map_height",    "start_x",
                                                  "start_y", "goal_x", "goal_y",    "optimal_length"};

bool isDigit(char c) { return c >= '0' && c <= '9'; }

// A plain decimal number >= 0 ("12", "14.485", ".5", "1e3"): no sign, no "nan"/"inf", no hex, and
// finite once parsed; or false.
bool parseLength(const std::string& text, double& out) {
  std::size_t i = 0;
  std::size_t digits = 0;
  for (; i < text.size() && isDigit(text[i]); ++i) ++digits;
  if (i < text.size() && text[i] == '.') {
    for (++i; i < text.size() && isDigit(text[i]); ++i) ++digits;
  }
  if (digits == 0) return false;
  if (i < text.size() && (text[i] == 'e' || text[i] == 'E')) {
    ++i;
    if (i < text.size() && (text[i] == '+' || text[i] == '-')) ++i;
    const std::size_t exponent = i;
    while (i < text.size() && isDigit(text[i])) ++i;
    if (i == exponent) return false;
  }
  if (i != text.size()) return false;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), out);
  return ec == std::errc() && end == text.data() + text.size() && std::isfinite(out) && out >= 0.0;
}

// The fields of a line split on spaces and tabs.
std::vector<std::string> fieldsOf(const std::string& line) {
  std::vector<std::string> fields;
  std::size_t pos = 0;
  while (true) {
    const std::size_t start = line.find_first_not_of(" \t", pos);
    if (start == std::string::npos) break;
    pos = line.find_first_of(" \t", start);
    fields.push_back(line.substr(start, pos == std::string::npos ? std::string::npos : pos - start));
    if (pos == std::string::npos) break;
  }
  return fields;
}

bool hasControlByte(const std::string& text) {
  for (char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if (c < 0x20 || c == 0x7f) return true;
  }
  return false;
}

}  // namespace

std::vector<ScenRow> loadMovingAiScen(const std::filesystem::path& file) {
  const std::string name = file.string();
  TextLines text(file);
  const auto fail = [&](const std::string& what) { text.fail(what); };
  const auto nextLine = [&](std::string& line) { return text.next(line); };

  std::string line;
  if (!nextLine(line)) fail("empty file, expected 'version 1' on the first line");
  const std::vector<std::string> version = fieldsOf(line);
  if (version.size() != 2 || version[0] != "version" || (version[1] != "1" && version[1] != "1.0")) {
    fail("expected 'version 1' or 'version 1.0' on the first line, got " + shown(line));
  }

  std::vector<ScenRow> rows;
  while (nextLine(line)) {
    const std::vector<std::string> fields = fieldsOf(line);
    if (fields.empty()) continue;  // blank line
    if (static_cast<int>(fields.size()) != kFieldCount) {
      fail("expected " + std::to_string(kFieldCount) +
           " fields 'bucket map map_width map_height start_x start_y goal_x goal_y optimal_length', got " +
           std::to_string(fields.size()) + " in " + shown(line));
    }
    const auto bad = [&](int field, const std::string& expected) {
      fail("field " + std::to_string(field + 1) + " (" + kFieldNames[field] + ") has value " + shown(fields[field]) +
           ", expected " + expected);
    };
    const auto integer = [&](int field, int lo, int hi, const std::string& why) {
      int value = 0;
      if (!parseInt(fields[field], lo, hi, value)) {
        bad(field, "an integer in " + std::to_string(lo) + ".." + std::to_string(hi) + why);
      }
      return value;
    };

    ScenRow row;
    row.line = text.lineNo();
    row.bucket = integer(0, 0, kMaxBucket, "");
    row.map = fields[1];
    if (hasControlByte(row.map)) bad(1, "a file name without control characters");
    row.map_width = integer(2, 1, kMaxGridSide, "");
    row.map_height = integer(3, 1, kMaxGridSide, "");
    const std::string in_width = " (inside map_width " + fields[2] + ")";
    const std::string in_height = " (inside map_height " + fields[3] + ")";
    row.start_x = integer(4, 0, row.map_width - 1, in_width);
    row.start_y = integer(5, 0, row.map_height - 1, in_height);
    row.goal_x = integer(6, 0, row.map_width - 1, in_width);
    row.goal_y = integer(7, 0, row.map_height - 1, in_height);
    if (!parseLength(fields[8], row.optimal_length)) bad(8, "a finite decimal number >= 0");
    rows.push_back(row);
  }
  if (rows.empty()) throw InputError(name + ": no scenarios after the version line");
  return rows;
}

void checkScenAgainstMap(const std::filesystem::path& scen_file, const std::vector<ScenRow>& rows, int map_width,
                         int map_height) {
  const std::string name = scen_file.string();
  for (const ScenRow& row : rows) {
    const auto fail = [&](const std::string& what) {
      throw InputError(name + ":" + std::to_string(row.line) + ": " + what);
    };
    if (row.map_width != map_width || row.map_height != map_height) {
      const bool width = row.map_width != map_width;
      fail(std::string(width ? "map_width" : "map_height") + " has value '" +
           std::to_string(width ? row.map_width : row.map_height) + "', expected the map's " +
           (width ? "width " + std::to_string(map_width) : "height " + std::to_string(map_height)) + " (the map is " +
           std::to_string(map_width) + "x" + std::to_string(map_height) + "; scaled scenarios are not supported)");
    }
    const auto inside = [&](const char* field, int value, int size, const char* side) {
      if (value < 0 || value >= size) {
        fail(std::string(field) + " has value '" + std::to_string(value) + "', outside the map (expected 0.." +
             std::to_string(size - 1) + " for map " + side + " " + std::to_string(size) + ")");
      }
    };
    inside("start_x", row.start_x, map_width, "width");
    inside("start_y", row.start_y, map_height, "height");
    inside("goal_x", row.goal_x, map_width, "width");
    inside("goal_y", row.goal_y, map_height, "height");
  }
}

Eigen::Vector2d scenCellCentre(int x, int y, int map_height, double resolution_m) {
  return Eigen::Vector2d((x + 0.5) * resolution_m, (map_height - 1 - y + 0.5) * resolution_m);
}

}  // namespace tgnav::harness
