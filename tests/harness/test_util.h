#pragma once
// Helpers shared by the harness tests.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "harness/errors.h"

namespace tgnav::test {

inline std::filesystem::path sourceDir() { return TGNAV_SOURCE_DIR; }

// A fresh directory under the system temp dir, unique per test.
inline std::filesystem::path tempDir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  auto dir = std::filesystem::temp_directory_path() /
             ("tgnav_" + std::string(info->test_suite_name()) + "_" + info->name());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

inline std::filesystem::path writeFile(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path) << text;
  return path;
}

// The message of the InputError that `fn` throws ("" when it throws none).
template <typename Fn>
std::string inputError(Fn fn) {
  try {
    fn();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace tgnav::test
