// Folders appear whole or not at all: StagedDir writes into a hidden sibling and renames it into
// place; what happens when the target exists by then is the caller's choice.
#include "harness/io/staged_output.h"

#include <gtest/gtest.h>

#include <fstream>

#include "harness/base/errors.h"
#include "test_util.h"

namespace tgnav::harness {
namespace {

namespace fs = std::filesystem;

std::string read(const fs::path& file) {
  std::ifstream in(file);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

TEST(StagedDir, AppearsOnlyWhenCommitted) {
  const fs::path root = test::tempDir();
  {
    StagedDir staged(root / "out");
    EXPECT_EQ(staged.staging(), stagingPathFor(root / "out"));
    EXPECT_TRUE(isStagingName(staged.staging().filename()));
    writeFileAtomic(staged.staging() / "a.txt", "a\n");
    EXPECT_FALSE(fs::exists(root / "out"));
    EXPECT_TRUE(staged.commit(OnExisting::kRefuse));
  }
  EXPECT_EQ(read(root / "out/a.txt"), "a\n");
  EXPECT_EQ(test::stagingLeftIn(root), 0);
}

TEST(StagedDir, AbandonedStagingIsRemoved) {
  const fs::path root = test::tempDir();
  {
    StagedDir staged(root / "out/");  // "out/" is "out"
    EXPECT_EQ(staged.target(), root / "out");
    writeFileAtomic(staged.staging() / "a.txt", "a\n");
  }
  EXPECT_FALSE(fs::exists(root / "out"));
  EXPECT_EQ(test::stagingLeftIn(root), 0);
}

TEST(StagedDir, RefuseKeepsTheResultsAndSaysWhere) {
  const fs::path root = test::tempDir();
  StagedDir staged(root / "out");
  writeFileAtomic(staged.staging() / "a.txt", "mine\n");
  fs::create_directory(root / "out");
  try {
    staged.commit(OnExisting::kRefuse, "recording");
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("appeared while recording"), std::string::npos) << what;
    EXPECT_NE(what.find(staged.staging().string()), std::string::npos) << what;
  }
  EXPECT_EQ(read(staged.staging() / "a.txt"), "mine\n");
}

TEST(StagedDir, ReplaceSwapsTheFolderWhole) {
  const fs::path root = test::tempDir();
  fs::create_directory(root / "out");
  test::writeFile(root / "out/old.txt", "old\n");
  StagedDir staged(root / "out");
  writeFileAtomic(staged.staging() / "new.txt", "new\n");
  EXPECT_TRUE(staged.commit(OnExisting::kReplace));
  EXPECT_FALSE(fs::exists(root / "out/old.txt"));
  EXPECT_EQ(read(root / "out/new.txt"), "new\n");
  EXPECT_EQ(test::stagingLeftIn(root), 0);
}

TEST(StagedDir, KeepLeavesAnotherWritersFolder) {
  const fs::path root = test::tempDir();
  StagedDir staged(root / "cache");
  writeFileAtomic(staged.staging() / "summary.json", "ours\n");
  fs::create_directory(root / "cache");
  test::writeFile(root / "cache/summary.json", "theirs\n");
  EXPECT_FALSE(staged.commit(OnExisting::kKeep));
  EXPECT_EQ(read(root / "cache/summary.json"), "theirs\n");
}

TEST(StagedDir, MergeMovesEachFileIntoAUsersFolder) {
  const fs::path root = test::tempDir();
  fs::create_directory(root / "mine");
  test::writeFile(root / "mine/notes.txt", "keep me\n");
  test::writeFile(root / "mine/plan.json", "old\n");
  StagedDir staged(root / "mine");
  writeFileAtomic(staged.staging() / "plan.json", "new\n");
  EXPECT_TRUE(staged.commit(OnExisting::kMerge));
  EXPECT_EQ(read(root / "mine/notes.txt"), "keep me\n");
  EXPECT_EQ(read(root / "mine/plan.json"), "new\n");
  EXPECT_EQ(test::stagingLeftIn(root), 0);
  // A new folder is created whole.
  StagedDir fresh(root / "fresh");
  writeFileAtomic(fresh.staging() / "plan.json", "x\n");
  EXPECT_TRUE(fresh.commit(OnExisting::kMerge));
  EXPECT_EQ(read(root / "fresh/plan.json"), "x\n");
}

TEST(StagedDir, AnUnwritableParentIsAnInputError) {
  EXPECT_THROW(StagedDir("/proc/tgnav-cannot-write/out"), InputError);
}

}  // namespace
}  // namespace tgnav::harness
