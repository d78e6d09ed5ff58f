// Replays every fuzz target's committed corpus, its crash regressions and the inputs made from the
// repository's own files, in the normal build: a parser that crashes, trips a sanitizer (in the
// TGNAV_SANITIZE build) or lets an undocumented exception escape on any of them fails here.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "tests/fuzz/fuzz_targets.h"

namespace fs = std::filesystem;
using tgnav::fuzz::Outcome;

namespace {

const fs::path kFuzzDir = fs::path(TGNAV_SOURCE_DIR) / "tests" / "fuzz";

std::string readText(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<fs::path> filesIn(const fs::path& dir) {
  std::vector<fs::path> files;
  if (!fs::is_directory(dir)) return files;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.is_regular_file() && e.path().filename() != ".gitkeep") files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

class FuzzReplay : public ::testing::TestWithParam<std::string> {};

TEST_P(FuzzReplay, CommittedInputsAndRegressionsEndInAcceptOrDocumentedError) {
  const std::string name = GetParam();
  int accepted = 0;
  int replayed = 0;
  for (const char* kind : {"corpus", "regressions"}) {
    for (const fs::path& f : filesIn(kFuzzDir / kind / name)) {
      Outcome outcome = Outcome::kRejected;
      EXPECT_NO_THROW(outcome = tgnav::fuzz::run(name, readText(f))) << f;
      accepted += outcome == Outcome::kAccepted;
      ++replayed;
    }
  }
  const std::vector<std::string> repo = tgnav::fuzz::repositorySeeds(name, TGNAV_SOURCE_DIR);
  for (std::size_t i = 0; i < repo.size(); ++i) {
    Outcome outcome = Outcome::kRejected;
    std::string why;
    EXPECT_NO_THROW(outcome = tgnav::fuzz::run(name, repo[i], &why)) << "repository seed " << i;
    // The repository's own files are valid input: a rejected one means the seed's paths were not
    // rewritten to the scratch layout, and the fuzzer would start from nothing it accepts.
    EXPECT_EQ(outcome, Outcome::kAccepted) << name << " repository seed " << i << ": " << why;
    accepted += outcome == Outcome::kAccepted;
    ++replayed;
  }
  EXPECT_GT(replayed, 0) << "no seed for fuzz target " << name;
  EXPECT_GT(accepted, 0) << "no seed of fuzz target " << name << " is valid input";
}

std::vector<std::string> targetNames() {
  std::vector<std::string> names;
  for (const auto& t : tgnav::fuzz::targets()) names.push_back(t.name);
  return names;
}

INSTANTIATE_TEST_SUITE_P(Targets, FuzzReplay, ::testing::ValuesIn(targetNames()),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

TEST(FuzzSections, CutsAtMarkLinesOnly) {
  using tgnav::fuzz::sections;
  EXPECT_EQ(sections("a\n--8<--\nb\n", 3), (std::vector<std::string>{"a\n", "b\n"}));
  EXPECT_EQ(sections("a\n--8<--\nb\n--8<--\nc", 2), (std::vector<std::string>{"a\n", "b\n--8<--\nc"}));
  EXPECT_EQ(sections("a --8<--\n", 3), (std::vector<std::string>{"a --8<--\n"}));
  EXPECT_EQ(sections("", 3), (std::vector<std::string>{""}));
}

TEST(FuzzTargets, TheExecutablesBuiltAreTheTargetsListed) {
  std::string names;
  for (const auto& t : tgnav::fuzz::targets()) names += (names.empty() ? "" : ",") + t.name;
  EXPECT_EQ(names, TGNAV_FUZZ_TARGETS) << "tests/fuzz/CMakeLists.txt's TGNAV_FUZZ_TARGETS and fuzz::targets() differ";
}

TEST(FuzzTargets, BadInputIsRejectedNotAccepted) {
  EXPECT_EQ(tgnav::fuzz::run("tum", std::string("0 1 2\n")), Outcome::kRejected);
  EXPECT_EQ(tgnav::fuzz::run("movingai_map", std::string("type octile\nheight 1\nwidth 2\nmap\n.x\n")),
            Outcome::kRejected);
  EXPECT_EQ(tgnav::fuzz::run("scene", std::string("mjcf: ../fuzz.xml\n")), Outcome::kRejected);
  EXPECT_THROW(tgnav::fuzz::run("no_such_target", std::string()), std::out_of_range);
}

}  // namespace
