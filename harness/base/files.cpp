#include "harness/base/files.h"

#include <fstream>
#include <iterator>

#include "harness/base/errors.h"

namespace tgnav::harness {

std::string readTextFile(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string() + ": cannot read");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw InputError(file.string() + ": cannot read");
  return text;
}

}  // namespace tgnav::harness
