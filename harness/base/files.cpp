#include "harness/base/files.h"

#include <fstream>
#include <iterator>
#include <system_error>

#include "harness/base/errors.h"

namespace tgnav::harness {

std::string readTextFile(const std::filesystem::path& file) {
  std::error_code ec;
  // A folder opens as a stream whose reading throws; say what it is instead.
  if (std::filesystem::is_directory(file, ec)) throw InputError(file.string() + ": cannot read: it is a directory");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string() + ": cannot read");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw InputError(file.string() + ": cannot read");
  return text;
}

bool isRegularFile(const std::filesystem::path& file) noexcept {
  std::error_code ec;
  return std::filesystem::is_regular_file(file, ec);
}

}  // namespace tgnav::harness
