#pragma once
// Small helpers shared by the line-oriented file parsers (MovingAI .map and .scen, PGM headers):
// offending values quoted for one-line messages, and strict integers.
#include <cctype>
#include <climits>
#include <filesystem>
#include <fstream>
#include <string>

#include "harness/base/errors.h"

namespace tgnav::harness {

// Larger map sides are corrupt headers, not maps: refusing them keeps allocations bounded.
constexpr int kMaxGridSide = 20000;

// `text` quoted for a one-line message: control bytes masked, long values cut.
inline std::string shown(const std::string& text) {
  constexpr std::size_t kMaxShown = 40;
  std::string out = "'";
  for (std::size_t i = 0; i < text.size() && i < kMaxShown; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    out += std::isprint(c) ? static_cast<char>(c) : '?';
  }
  return out + (text.size() > kMaxShown ? "...'" : "'");
}

// A decimal integer in [lo, hi], or false (digits only: no sign, no overflow).
inline bool parseInt(const std::string& text, int lo, int hi, int& out) {
  if (text.empty() || text.size() > 9) return false;
  for (char c : text) {
    if (!std::isdigit(static_cast<unsigned char>(c))) return false;
  }
  out = std::stoi(text);
  return out >= lo && out <= hi;
}

// A text file read line by line, for messages "FILE:LINE: what" (CRLF line ends accepted).
class TextLines {
 public:
  explicit TextLines(const std::filesystem::path& file) : name_(file.string()), in_(file, std::ios::binary) {
    if (!std::filesystem::is_regular_file(file) || !in_) throw InputError(name_ + ": cannot open file");
  }
  // The next line without its end-of-line, or false at the end of the file.
  bool next(std::string& line) {
    if (line_no_ == INT_MAX) fail("too many lines");
    ++line_no_;
    if (!std::getline(in_, line)) {
      line.clear();
      return false;
    }
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return true;
  }
  int lineNo() const { return line_no_; }
  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(name_ + ":" + std::to_string(line_no_) + ": " + what);
  }

 private:
  std::string name_;
  std::ifstream in_;
  int line_no_ = 0;
};

}  // namespace tgnav::harness
