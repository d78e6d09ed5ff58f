// fuzz_seeds OUT: writes the seed corpus of every fuzz target into OUT/<target>/: the committed
// corpus (tests/fuzz/corpus/<target>/), the crash regressions (tests/fuzz/regressions/<target>/)
// and the inputs made from the repository's own files (fuzz::repositorySeeds). scripts/fuzz.sh
// runs it before fuzzing.
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "tests/fuzz/fuzz_targets.h"

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: fuzz_seeds OUT\n");
    return 2;
  }
  const fs::path out = argv[1];
  const fs::path source = TGNAV_SOURCE_DIR;
  for (const tgnav::fuzz::Target& t : tgnav::fuzz::targets()) {
    const fs::path dir = out / t.name;
    fs::create_directories(dir);
    int n = 0;
    for (const char* kind : {"corpus", "regressions"}) {
      const fs::path from = source / "tests" / "fuzz" / kind / t.name;
      if (!fs::is_directory(from)) continue;
      for (const auto& e : fs::directory_iterator(from)) {
        fs::copy_file(e.path(), dir / (std::string(kind) + "-" + e.path().filename().string()),
                      fs::copy_options::overwrite_existing);
        ++n;
      }
    }
    int i = 0;
    for (const std::string& seed : tgnav::fuzz::repositorySeeds(t.name, source)) {
      std::ofstream(dir / ("repo-" + std::to_string(i++)), std::ios::binary) << seed;
      ++n;
    }
    std::printf("%s: %d seeds\n", t.name.c_str(), n);
  }
  return 0;
}
