#pragma once
// Reading a whole text file, the one way the harness does it.
#include <filesystem>
#include <string>

namespace tgnav::harness {

// The file's bytes; InputError "<file>: cannot read" when it cannot be opened or read.
std::string readTextFile(const std::filesystem::path& file);

}  // namespace tgnav::harness
