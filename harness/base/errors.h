#pragma once
// Error policy (docs/ARCHITECTURE.md): bad user input throws InputError, whose one-line message
// names the file, key and offending value; the CLI prints it and exits 2. Programmer bugs are
// assertions; expected runtime outcomes (no path, VO lost, crash) are values, not exceptions.
#include <stdexcept>
#include <string>

namespace tgnav {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A message on one line: trailing newlines and spaces dropped, inner newlines become "; " (library
// and tool messages may span several).
inline std::string oneLine(std::string text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  for (std::size_t i = text.find('\n'); i != std::string::npos; i = text.find('\n', i)) text.replace(i, 1, "; ");
  return text;
}

// A library's "line N: what" about a file as "FILE:N: what"; any other message as "FILE: what".
inline std::string inFile(const std::string& file, const std::string& message) {
  if (message.rfind("line ", 0) == 0) {
    const auto colon = message.find(':');
    if (colon != std::string::npos) return file + ":" + message.substr(5, colon - 5) + message.substr(colon);
  }
  return file + ": " + message;
}

}  // namespace tgnav
