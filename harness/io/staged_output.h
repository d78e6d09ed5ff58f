#pragma once
// Results are written whole or not at all. A file is written to a temporary sibling and renamed
// (writeFileAtomic); a folder is filled in a hidden staging sibling and renamed into place when
// complete (StagedDir). Every command that writes a folder or a file set goes through these, so a
// folder that exists under its final name is complete, and a killed run leaves at most a hidden
// staging folder `.<name>.tmp-<pid>` behind.
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>

namespace tgnav::harness {

// Creates `dir` (and parents); InputError naming it when that is impossible.
void makeOutputDir(const std::filesystem::path& dir);
void writeFileAtomic(const std::filesystem::path& file, const std::string& content);
// Encodes by extension (.png: 8-bit or 16-bit).
void writeImageAtomic(const std::filesystem::path& file, const cv::Mat& image);

// The absolute path of a folder that `command` (e.g. "tgnav vo") is to create: InputError naming
// --out when `requested` is no name for a new folder ("..", "/") or already exists (such commands
// never overwrite). Nothing is created: StagedDir does that once the results are complete.
std::filesystem::path newOutputDir(const std::filesystem::path& requested, const std::string& command);

// The staging folder of `target` for this process: `<parent>/.<name>.tmp-<pid>`.
std::filesystem::path stagingPathFor(const std::filesystem::path& target);
// True for the name of a staging folder or of a replaced folder awaiting removal
// (`.<name>.tmp-<pid>`, `.<name>.old-<pid>`), which a killed run may leave behind.
bool isStagingName(const std::string& file_name);

// What commit() does when the target exists by then.
enum class OnExisting {
  kRefuse,   // InputError "<target>: appeared while ...; the results are left in <staging>"
  kReplace,  // the old target is moved aside, the staging folder renamed in, the old one removed
  kKeep,     // another writer finished first (a shared cache): keep theirs, drop ours
  kMerge,    // a file set: each staged file is renamed into the target folder, replacing its
             // namesake; other files there stay (for commands that write into a user's folder)
};

class StagedDir {
 public:
  // `target` is normalised ("dir/" is "dir"); `what` names it in errors (e.g. "--out"). Creates
  // the parents and an empty staging folder (a leftover of this pid's earlier run is removed).
  explicit StagedDir(const std::filesystem::path& target, std::string what = "--out");
  ~StagedDir();  // removes the staging folder unless it was committed or kept
  StagedDir(const StagedDir&) = delete;
  StagedDir& operator=(const StagedDir&) = delete;
  StagedDir(StagedDir&&) = delete;  // owns the staging folder
  StagedDir& operator=(StagedDir&&) = delete;

  const std::filesystem::path& staging() const { return staging_; }  // write here
  const std::filesystem::path& target() const { return target_; }

  // Renames the staging folder onto the target. Returns false when kKeep kept another writer's
  // folder. `doing` completes the kRefuse message ("recording", "running the odometry").
  bool commit(OnExisting on_existing, const std::string& doing = "writing");

 private:
  void mergeInto();

  std::filesystem::path target_;
  std::filesystem::path staging_;
  std::string what_;
  bool done_ = false;  // committed, or kept for the user
};

}  // namespace tgnav::harness
