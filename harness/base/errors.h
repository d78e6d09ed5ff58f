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

}  // namespace tgnav
