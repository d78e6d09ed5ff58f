#include "harness/io/grid_io.h"

#include <cctype>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "harness/base/errors.h"
#include "harness/base/files.h"
#include "harness/config/yaml_util.h"
#include "harness/io/staged_output.h"
#include "harness/io/text_fields.h"

namespace tgnav::harness {

namespace {

// MovingAI's terrain letters (movingai.com/benchmarks/formats): ground '.', 'G' and swamp 'S' are
// passable; out of bounds '@', 'O', trees 'T' and water 'W' are not, as the benchmark's optimal
// lengths assume. Any other letter is an error, never a silent obstacle.
constexpr const char* kMovingAiTerrain = ".GS@OTW";
bool movingAiPassable(char c) { return c == '.' || c == 'G' || c == 'S'; }

// "" for a row of terrain letters, else what is wrong with it.
std::string terrainError(const std::string& row) {
  const std::size_t bad = row.find_first_not_of(kMovingAiTerrain);
  if (bad == std::string::npos) return "";
  return "column " + std::to_string(bad) + ": terrain " + shown(row.substr(bad, 1)) + " is not one of '" +
         kMovingAiTerrain + "'";
}

std::string readBinaryFile(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string() + ": cannot open file");
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// A decoded PGM; pixels in image order (row 0 at the top).
struct Pgm {
  int width = 0;
  int height = 0;
  int maxval = 0;
  std::vector<std::uint8_t> pixels;
};

// Splits a PGM into whitespace-separated tokens, skipping '#' comments to the end of the line.
class PgmTokens {
 public:
  explicit PgmTokens(const std::string& data) : data_(data) {}
  // The next token, or "" at the end of the data.
  std::string next() {
    while (pos_ < data_.size()) {
      if (data_[pos_] == '#') {
        while (pos_ < data_.size() && data_[pos_] != '\n' && data_[pos_] != '\r') ++pos_;
      } else if (std::isspace(static_cast<unsigned char>(data_[pos_]))) {
        ++pos_;
      } else {
        break;
      }
    }
    const std::size_t start = pos_;
    while (pos_ < data_.size() && data_[pos_] != '#' && !std::isspace(static_cast<unsigned char>(data_[pos_]))) {
      ++pos_;
    }
    return data_.substr(start, pos_ - start);
  }
  std::size_t pos() const { return pos_; }

 private:
  const std::string& data_;
  std::size_t pos_ = 0;
};

Pgm readPgm(const std::filesystem::path& file) {
  const std::string data = readBinaryFile(file);
  const std::string name = file.string();
  auto fail = [&](const std::string& what) -> void { throw InputError(name + ": " + what); };

  PgmTokens tokens(data);
  const std::string magic = tokens.next();
  if (magic != "P5" && magic != "P2") {
    fail("bad PGM magic " + shown(magic) + ", expected 'P5' (binary) or 'P2' (ASCII) PGM");
  }
  Pgm pgm;
  const auto header = [&](const char* field, int hi, int& out) {
    const std::string token = tokens.next();
    if (!parseInt(token, 1, hi, out)) {
      fail(std::string("PGM header field '") + field + "' has value " + shown(token) + ", expected an integer in 1.." +
           std::to_string(hi));
    }
  };
  header("width", kMaxGridSide, pgm.width);
  header("height", kMaxGridSide, pgm.height);
  header("maxval", 255, pgm.maxval);

  const std::size_t count = static_cast<std::size_t>(pgm.width) * pgm.height;
  if (magic == "P5") {
    // Exactly one whitespace byte separates maxval from the raster.
    const std::size_t start = tokens.pos() + 1;
    const std::size_t available = data.size() > start ? data.size() - start : 0;
    if (available < count) {
      fail("truncated pixel data: " + std::to_string(available) + " of " + std::to_string(count) + " bytes for " +
           std::to_string(pgm.width) + "x" + std::to_string(pgm.height));
    }
    pgm.pixels.assign(data.begin() + start, data.begin() + start + count);
  } else {
    // Grown as values arrive, so a header claiming a huge image cannot force a huge allocation.
    for (std::size_t i = 0; i < count; ++i) {
      const std::string token = tokens.next();
      if (token.empty()) {
        fail("truncated pixel data: " + std::to_string(i) + " of " + std::to_string(count) + " values for " +
             std::to_string(pgm.width) + "x" + std::to_string(pgm.height));
      }
      int value = 0;
      if (!parseInt(token, 0, 255, value)) {
        fail("pixel " + std::to_string(i) + " has value " + shown(token) + ", expected an integer in 0.." +
             std::to_string(pgm.maxval));
      }
      pgm.pixels.push_back(static_cast<std::uint8_t>(value));
    }
  }
  for (std::size_t i = 0; i < count; ++i) {
    if (pgm.pixels[i] > pgm.maxval) {
      fail("pixel " + std::to_string(i) + " (row " + std::to_string(i / pgm.width) + ", column " +
           std::to_string(i % pgm.width) + ") has value '" + std::to_string(pgm.pixels[i]) + "' > maxval " +
           std::to_string(pgm.maxval));
    }
  }
  return pgm;
}

}  // namespace

planner::OccupancyGrid2D loadRosMap(const std::filesystem::path& yaml) {
  const YamlDoc doc = YamlDoc::load(yaml);
  const YAML::Node& root = doc.root();
  doc.requireKeys(root, {"image", "resolution", "origin", "occupied_thresh", "free_thresh", "negate", "mode"}, "");
  const auto bad = [&](const std::string& key, const std::string& expected) {
    doc.fail(root[key], "key '" + key + "' has value " + shown(root[key].Scalar()) + ", expected " + expected);
  };

  const double resolution = doc.number(root, "resolution", "");
  if (resolution <= 0.0) bad("resolution", "a number > 0");
  const std::vector<double> origin = doc.numbers(root, "origin", 3, "");
  if (origin[2] != 0.0) {
    doc.fail(root["origin"], "key 'origin' has yaw " + shown(root["origin"][2].Scalar()) +
                                 ", expected 0 (rotated maps are not supported)");
  }
  // occupied_thresh only separates occupied from unknown, which are stored alike; it is still
  // validated so that a map the ROS stack would reject is rejected here too.
  const double occupied_thresh = doc.number(root, "occupied_thresh", "");
  const double free_thresh = doc.number(root, "free_thresh", "");
  if (occupied_thresh < 0.0 || occupied_thresh > 1.0) bad("occupied_thresh", "a number in [0, 1]");
  if (free_thresh < 0.0 || free_thresh > 1.0) bad("free_thresh", "a number in [0, 1]");
  if (free_thresh >= occupied_thresh) {
    bad("free_thresh", "less than occupied_thresh (" + root["occupied_thresh"].Scalar() + ")");
  }
  const double negate = doc.number(root, "negate", "");
  if (negate != 0.0 && negate != 1.0) bad("negate", "0 or 1");
  if (root["mode"] && doc.string(root, "mode", "") != "trinary") {
    bad("mode", "'trinary' (the only supported mode)");
  }

  std::filesystem::path image = doc.string(root, "image", "");
  if (image.is_relative()) image = yaml.parent_path() / image;
  if (!isRegularFile(image)) {
    bad("image", "an existing PGM file (looked for " + image.string() + ")");
  }
  const Pgm pgm = readPgm(image);

  planner::OccupancyGrid2D grid(pgm.width, pgm.height, resolution, Eigen::Vector2d(origin[0], origin[1]));
  for (int row = 0; row < pgm.height; ++row) {
    for (int ix = 0; ix < pgm.width; ++ix) {
      const int pixel = pgm.pixels[static_cast<std::size_t>(row) * pgm.width + ix];
      const double occ = (negate != 0.0 ? pixel : pgm.maxval - pixel) / static_cast<double>(pgm.maxval);
      grid.set(ix, pgm.height - 1 - row, !(occ < free_thresh));
    }
  }
  return grid;
}

planner::OccupancyGrid2D loadMovingAiMap(const std::filesystem::path& file, double resolution_m) {
  const std::string name = file.string();
  if (!(resolution_m > 0.0) || !std::isfinite(resolution_m)) {
    std::ostringstream value;
    value << resolution_m;
    throw InputError(name + ": MovingAI map resolution has value '" + value.str() + "', expected a finite number > 0");
  }
  TextLines text(file);
  const auto fail = [&](const std::string& what) { text.fail(what); };
  const auto nextLine = [&](std::string& line) { return text.next(line); };
  std::string line;
  const auto header = [&](const std::string& key) {
    std::string value;
    std::string extra;
    std::istringstream fields(nextLine(line) ? line : "");
    if (!(fields >> value) || value != key || !(fields >> value) || (fields >> extra)) {
      fail("expected '" + key + " <value>', got " + shown(line));
    }
    return value;
  };
  const auto side = [&](const std::string& key) {
    const std::string value = header(key);
    int n = 0;
    if (!parseInt(value, 1, kMaxGridSide, n)) {
      fail("'" + key + "' has value " + shown(value) + ", expected an integer in 1.." + std::to_string(kMaxGridSide));
    }
    return n;
  };

  const std::string type = header("type");
  if (type != "octile") fail("'type' has value " + shown(type) + ", expected 'octile'");
  const int height = side("height");
  const int width = side("width");
  if (!nextLine(line) || line != "map") fail("expected 'map', got " + shown(line));

  // Rows are collected before the grid is allocated, so memory follows the file, not the header.
  std::vector<std::string> rows;
  while (static_cast<int>(rows.size()) < height) {
    if (!nextLine(line)) {
      fail("too few rows: found " + std::to_string(rows.size()) + " of " + std::to_string(height));
    }
    if (static_cast<int>(line.size()) != width) {
      fail("row " + std::to_string(rows.size()) + " " + shown(line) + " has " + std::to_string(line.size()) +
           " characters, expected " + std::to_string(width));
    }
    if (const std::string bad = terrainError(line); !bad.empty()) fail(bad);
    rows.push_back(line);
  }
  while (nextLine(line)) {
    if (line.find_first_not_of(" \t") != std::string::npos) {
      fail("unexpected " + shown(line) + " after the " + std::to_string(height) + " map rows");
    }
  }

  planner::OccupancyGrid2D grid(width, height, resolution_m, Eigen::Vector2d::Zero());
  for (int row = 0; row < height; ++row) {
    for (int ix = 0; ix < width; ++ix) {
      grid.set(ix, height - 1 - row, !movingAiPassable(rows[row][ix]));
    }
  }
  return grid;
}

void writeRosMap(const planner::OccupancyGrid2D& grid, const std::filesystem::path& yaml,
                 const std::filesystem::path& pgm) {
  std::string image = "P5\n" + std::to_string(grid.width) + " " + std::to_string(grid.height) + "\n255\n";
  image.reserve(image.size() + grid.occupied.size());
  for (int row = 0; row < grid.height; ++row) {
    for (int ix = 0; ix < grid.width; ++ix) {
      image += static_cast<char>(grid.isOccupied(ix, grid.height - 1 - row) ? 0 : 254);
    }
  }
  writeFileAtomic(pgm, image);
  std::ostringstream y;
  y.precision(17);
  y << "image: " << pgm.filename().string() << "\nresolution: " << grid.resolution_m << "\norigin: ["
    << grid.origin_m.x() << ", " << grid.origin_m.y() << ", 0.0]\nnegate: 0\noccupied_thresh: 0.65\n"
    << "free_thresh: 0.196\n";
  writeFileAtomic(yaml, y.str());
}

planner::OccupancyGrid2D loadGridMap(const std::filesystem::path& file, double movingai_resolution_m) {
  const std::string ext = file.extension().string();
  if (ext == ".yaml" || ext == ".yml") return loadRosMap(file);
  if (ext == ".map") return loadMovingAiMap(file, movingai_resolution_m);
  throw InputError(file.string() + ": unknown grid map type " + shown(ext) +
                   " (expected .yaml/.yml for a ROS map_server map or .map for a MovingAI map)");
}

}  // namespace tgnav::harness
