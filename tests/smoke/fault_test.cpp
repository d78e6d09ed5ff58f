// Faults while results are written, through the `tgnav` program: the disk fills (simulated per
// process with a file-size limit, RLIMIT_FSIZE: with SIGXFSZ ignored a write fails with EFBIG as
// it would with ENOSPC; with SIGXFSZ's default action the process dies mid-write), a map-cache
// build is killed with -9, and two sweeps race for one map. In every case a result is either
// complete and valid under its name, or absent with a message: never a truncated file that looks
// complete. Smoke scene at 320x240; about 2 minutes on two cores.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "../harness/test_util.h"

namespace tgnav {
namespace {

namespace fs = std::filesystem;

const fs::path kSource = TGNAV_SOURCE_DIR;
const std::string kBin = TGNAV_BIN;

std::string readText(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// How the child meets the file-size limit.
enum class OnLimit { kNone, kWriteFails, kKilled };

struct Outcome {
  int exit_code = -1;  // when it exited
  int signal = 0;      // when a signal ended it
  std::string stderr_text;
};

pid_t spawn(const std::vector<std::string>& args, OnLimit on_limit, rlim_t limit_bytes, const fs::path& err_file) {
  const pid_t pid = fork();
  if (pid != 0) return pid;
  const int fd = ::open(err_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd >= 0) {
    ::dup2(fd, STDOUT_FILENO);
    ::dup2(fd, STDERR_FILENO);
  }
  if (on_limit != OnLimit::kNone) {
    const rlimit r{limit_bytes, limit_bytes};
    ::setrlimit(RLIMIT_FSIZE, &r);
    ::signal(SIGXFSZ, on_limit == OnLimit::kWriteFails ? SIG_IGN : SIG_DFL);
  }
  std::vector<char*> argv;
  argv.push_back(const_cast<char*>(kBin.c_str()));
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  ::execv(kBin.c_str(), argv.data());
  ::_exit(127);
}

Outcome wait(pid_t pid, const fs::path& err_file) {
  int status = 0;
  ::waitpid(pid, &status, 0);
  Outcome o;
  if (WIFEXITED(status)) o.exit_code = WEXITSTATUS(status);
  if (WIFSIGNALED(status)) o.signal = WTERMSIG(status);
  o.stderr_text = readText(err_file);
  return o;
}

Outcome run(const fs::path& dir, const std::vector<std::string>& args, OnLimit on_limit = OnLimit::kNone,
            rlim_t limit_bytes = RLIM_INFINITY) {
  static int n = 0;
  const fs::path err = dir / ("run" + std::to_string(n++) + ".log");
  return wait(spawn(args, on_limit, limit_bytes, err), err);
}

// A file that ends as its format says it must: JSON parses, a PNG ends in its IEND chunk, text
// ends at a line end, and nothing is empty.
::testing::AssertionResult looksComplete(const fs::path& file) {
  const std::string text = readText(file);
  if (text.empty()) return ::testing::AssertionFailure() << file << " is empty";
  const std::string ext = file.extension().string();
  if (ext == ".json" && !nlohmann::json::accept(text)) return ::testing::AssertionFailure() << file << ": bad JSON";
  if (ext == ".png" && (text.size() < 12 || text.compare(text.size() - 8, 4, "IEND") != 0)) {
    return ::testing::AssertionFailure() << file << ": the PNG does not end in IEND";
  }
  if ((ext == ".csv" || ext == ".tum" || ext == ".yaml" || ext == ".txt") && text.back() != '\n') {
    return ::testing::AssertionFailure() << file << ": the text stops mid-line";
  }
  return ::testing::AssertionSuccess();
}

// Every file under `dir` looks complete, and none is a temporary or staging leftover.
void expectCompleteFolder(const fs::path& dir) {
  ASSERT_TRUE(fs::is_directory(dir)) << dir;
  int files = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (!e.is_regular_file()) continue;
    ++files;
    EXPECT_TRUE(looksComplete(e.path()));
    EXPECT_NE(e.path().extension(), ".tmp") << e.path();
  }
  EXPECT_GT(files, 0) << dir;
}

// The entries of `dir` that are not staging leftovers (StagedDir), by name.
std::vector<std::string> visibleEntries(const fs::path& dir) {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (!harness::isStagingName(name)) names.push_back(name);
  }
  std::sort(names.begin(), names.end());
  return names;
}

// The one line the CLI prints for an error it reports.
void expectOneLineError(const Outcome& o, const std::string& must_contain) {
  EXPECT_NE(o.exit_code, 0) << o.stderr_text;
  EXPECT_EQ(o.signal, 0) << o.stderr_text;
  EXPECT_NE(o.stderr_text.find("tgnav: error: "), std::string::npos) << o.stderr_text;
  EXPECT_EQ(o.stderr_text.find("internal error"), std::string::npos) << o.stderr_text;
  EXPECT_NE(o.stderr_text.find(must_contain), std::string::npos) << o.stderr_text;
}

std::vector<std::string> smokeTrial(const fs::path& out, const std::vector<std::string>& map_args) {
  std::vector<std::string> args = {"trial",
                                   "--scenario",
                                   (kSource / "configs/scenarios/smoke.yaml").string(),
                                   "--planner",
                                   "agnostic",
                                   "--seed",
                                   "1",
                                   "--set",
                                   "camera.width_px=320",
                                   "--set",
                                   "camera.height_px=240",
                                   "--out",
                                   out.string()};
  args.insert(args.end(), map_args.begin(), map_args.end());
  return args;
}

// The smoke scene's feature map, from the tests' shared cache (built on first use; the cache
// is safe for concurrent tests, as the racing-sweeps test shows).
std::string smokeMap() {
  const harness::SceneConfig scene = harness::loadSceneConfig(kSource / "configs/scenes/smoke.yaml");
  return harness::cachedFeatureMap(scene, harness::MapBuildConfig{}, TGNAV_TEST_CACHE).dir.string();
}

// Each test in a folder of its own (CTest runs them in parallel).
class Faults : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::tempDir(); }
  fs::path dir_;
};

TEST_F(Faults, DiskFullDuringATrialLeavesNoResultsFolderAndSaysWhichFileFailed) {
  // 4 KiB: the first file written fails; 100 KiB: the small files are written, a large one fails.
  for (const rlim_t limit : {rlim_t{4} << 10, rlim_t{100} << 10}) {
    SCOPED_TRACE("limit " + std::to_string(limit));
    const fs::path out = dir_ / ("trial_full_" + std::to_string(limit));
    const Outcome o = run(dir_, smokeTrial(out, {"--map", smokeMap()}), OnLimit::kWriteFails, limit);
    expectOneLineError(o, "File too large");
    EXPECT_FALSE(fs::exists(out));
    EXPECT_EQ(test::stagingLeftIn(dir_), 0) << "a failed write must remove its staging folder";
  }
}

TEST_F(Faults, ATrialKilledMidWriteLeavesOnlyAHiddenStagingFolder) {
  const fs::path out = dir_ / "trial_killed";
  const Outcome o = run(dir_, smokeTrial(out, {"--map", smokeMap()}), OnLimit::kKilled, 100 << 10);
  EXPECT_EQ(o.signal, SIGXFSZ) << o.stderr_text;
  EXPECT_FALSE(fs::exists(out));
  // Without a limit the same trial completes, and every file is whole.
  const Outcome ok = run(dir_, smokeTrial(out, {"--map", smokeMap()}));
  ASSERT_EQ(ok.exit_code, 0) << ok.stderr_text;
  expectCompleteFolder(out);
}

TEST_F(Faults, DiskFullDuringAMapBuildWritesNoMap) {
  const fs::path out = dir_ / "map_full";
  const Outcome o =
      run(dir_, {"map", "--scene", (kSource / "configs/scenes/smoke.yaml").string(), "--out", out.string()},
          OnLimit::kWriteFails, 256 << 10);
  expectOneLineError(o, "File too large");
  EXPECT_FALSE(fs::exists(out));
}

TEST_F(Faults, MapCacheBuildThatFailsOrIsKilledLeavesNoMapThatLooksComplete) {
  const fs::path cache = dir_ / "cache_killed";
  // Disk full while the cache entry is written (landmarks.csv is several MB).
  const Outcome full =
      run(dir_, smokeTrial(dir_ / "t_cache_full", {"--map-cache", cache.string()}), OnLimit::kWriteFails, 1 << 20);
  expectOneLineError(full, "File too large");
  EXPECT_TRUE(visibleEntries(cache / "maps").empty());
  EXPECT_FALSE(fs::exists(dir_ / "t_cache_full"));

  // kill -9 while the entry is being written: the moment its staging folder appears.
  const fs::path err = dir_ / "killed.log";
  const pid_t pid =
      spawn(smokeTrial(dir_ / "t_cache_killed", {"--map-cache", cache.string()}), OnLimit::kNone, RLIM_INFINITY, err);
  bool staged = false;
  for (int i = 0; i < 120000 && !staged; ++i) {  // up to 2 min
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(cache / "maps", ec)) {
      staged = staged || harness::isStagingName(e.path().filename().string());
    }
    if (!staged) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ::kill(pid, SIGKILL);
  const Outcome killed = wait(pid, err);
  ASSERT_TRUE(staged) << "the map was never staged: " << killed.stderr_text;
  EXPECT_EQ(killed.signal, SIGKILL);
  for (const std::string& name : visibleEntries(cache / "maps")) {
    // The kill may land after the rename: then the entry must be whole.
    expectCompleteFolder(cache / "maps" / name);
  }

  // The next run builds (or reuses) a whole map and flies. The dead run's hidden staging folder
  // stays (on a cache shared between hosts, a pid that looks dead here may be alive elsewhere);
  // the cache ignores it.
  const Outcome ok = run(dir_, smokeTrial(dir_ / "t_cache_ok", {"--map-cache", cache.string()}));
  ASSERT_EQ(ok.exit_code, 0) << ok.stderr_text;
  const std::vector<std::string> entries = visibleEntries(cache / "maps");
  ASSERT_EQ(entries.size(), 1u);
  expectCompleteFolder(cache / "maps" / entries[0]);
}

std::string sweepFile(const fs::path& dir) {
  return test::writeFile(dir / "sweep.yaml",
                         "set: {camera.width_px: 320, camera.height_px: 240}\nruns:\n  - {scenario: " +
                             (kSource / "configs/scenarios/smoke.yaml").string() + ", planner: agnostic, seeds: [1]}\n")
      .string();
}

TEST_F(Faults, TwoSweepsRacingForOneMapBothSucceedAndShareOneWholeMap) {
  const fs::path cache = dir_ / "cache_race";
  const std::string sweep = sweepFile(dir_);
  std::vector<pid_t> pids;
  for (const char* name : {"race_a", "race_b"}) {
    pids.push_back(spawn({"sweep", "--sweep", sweep, "--out", (dir_ / name).string(), "--map-cache", cache.string()},
                         OnLimit::kNone, RLIM_INFINITY, dir_ / (std::string(name) + ".log")));
  }
  for (std::size_t i = 0; i < pids.size(); ++i) {
    const std::string name = i == 0 ? "race_a" : "race_b";
    const Outcome o = wait(pids[i], dir_ / (name + ".log"));
    EXPECT_EQ(o.exit_code, 0) << o.stderr_text;
    const std::string index = readText(dir_ / name / "index.csv");
    EXPECT_NE(index.find(",success,"), std::string::npos) << index;
    expectCompleteFolder(dir_ / name / "trials");
  }
  const std::vector<std::string> entries = visibleEntries(cache / "maps");
  ASSERT_EQ(entries.size(), 1u) << "one scene, one map";
  expectCompleteFolder(cache / "maps" / entries[0]);
  EXPECT_EQ(test::stagingLeftIn(cache / "maps"), 0);
}

TEST_F(Faults, DiskFullWhileASweepIndexIsWrittenKeepsTheOldIndex) {
  const std::string sweep = sweepFile(dir_);
  const fs::path out = dir_ / "sweep_index";
  const std::vector<std::string> args = {"sweep",      "--sweep",     sweep,           "--out",
                                         out.string(), "--map-cache", TGNAV_TEST_CACHE};
  const Outcome first = run(dir_, args);
  ASSERT_EQ(first.exit_code, 0) << first.stderr_text;
  const std::string index = readText(out / "index.csv");
  ASSERT_TRUE(looksComplete(out / "index.csv"));
  // Resuming a finished sweep only rewrites its index: with room for less than the index, the
  // write fails (or the process dies) and the old index stays whole.
  const Outcome full = run(dir_, args, OnLimit::kWriteFails, index.size() / 2);
  expectOneLineError(full, "File too large");
  EXPECT_EQ(readText(out / "index.csv"), index);
  const Outcome killed = run(dir_, args, OnLimit::kKilled, index.size() / 2);
  EXPECT_EQ(killed.signal, SIGXFSZ) << killed.stderr_text;
  EXPECT_EQ(readText(out / "index.csv"), index);
  // What the killed write leaves is its temporary file, under a name no reader takes for the index
  // (the next write replaces it), beside the sweep's hidden lock files.
  std::vector<std::string> names;
  for (const std::string& name : visibleEntries(out)) {
    if (name[0] != '.' && fs::path(name).extension() != ".tmp") names.push_back(name);
  }
  EXPECT_EQ(names, (std::vector<std::string>{"commands.txt", "index.csv", "logs", "scenarios", "sweep.yaml", "trials",
                                             "trials.csv"}));
}

}  // namespace
}  // namespace tgnav
