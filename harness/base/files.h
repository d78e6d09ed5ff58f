#pragma once
// Reading a whole text file, the one way the harness does it.
#include <filesystem>
#include <string>

namespace tgnav::harness {

// The file's bytes; InputError "<file>: cannot read" when it cannot be opened or read.
std::string readTextFile(const std::filesystem::path& file);

// Whether `file` is a regular file; false (never an exception) for a path the system cannot
// even look up, e.g. a name too long, so that a user's bad path ends in the caller's
// "not found" error.
bool isRegularFile(const std::filesystem::path& file) noexcept;

}  // namespace tgnav::harness
