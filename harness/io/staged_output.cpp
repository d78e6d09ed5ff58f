#include "harness/io/staged_output.h"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <system_error>
#include <vector>

#include "harness/base/errors.h"

namespace tgnav::harness {

void makeOutputDir(const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir)) {
    throw InputError(dir.string() + ": cannot create output directory" + (ec ? ": " + ec.message() : std::string()));
  }
}

void writeFileAtomic(const std::filesystem::path& file, const std::string& content) {
  const std::filesystem::path tmp = file.string() + ".tmp";
  // POSIX calls, so that a failure says why (a full disk: "No space left on device").
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw InputError(file.string() + ": cannot write file: " + std::strerror(errno));
  const char* p = content.data();
  std::size_t left = content.size();
  int error = 0;
  while (left > 0 && error == 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) error = errno;
    if (n > 0) {
      p += n;
      left -= static_cast<std::size_t>(n);
    }
  }
  if (::close(fd) != 0 && error == 0) error = errno;
  if (error != 0) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw InputError(file.string() + ": cannot write file: " + std::strerror(error));
  }
  std::error_code ec;
  std::filesystem::rename(tmp, file, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw InputError(file.string() + ": cannot write file: " + ec.message());
  }
}

void writeImageAtomic(const std::filesystem::path& file, const cv::Mat& image) {
  std::vector<unsigned char> bytes;
  if (!cv::imencode(file.extension().string(), image, bytes)) {
    throw std::runtime_error(file.string() + ": image encoding failed");
  }
  writeFileAtomic(file, std::string(bytes.begin(), bytes.end()));
}

std::filesystem::path newOutputDir(const std::filesystem::path& requested, const std::string& command) {
  std::filesystem::path out = std::filesystem::absolute(requested).lexically_normal();
  if (!out.has_filename()) out = out.parent_path();  // "out/" is "out"
  if (!out.has_filename() || out.filename() == "..") {
    throw InputError("--out: '" + requested.string() + "' is not a name for a new directory");
  }
  std::error_code ec;
  if (std::filesystem::exists(out, ec)) {
    throw InputError("--out: " + requested.string() + " already exists; " + command +
                     " writes a new directory and never overwrites");
  }
  return out;
}

std::filesystem::path stagingPathFor(const std::filesystem::path& target) {
  return target.parent_path() / ("." + target.filename().string() + ".tmp-" + std::to_string(getpid()));
}

bool isStagingName(const std::string& name) {
  return name.size() > 1 && name[0] == '.' &&
         (name.find(".tmp-") != std::string::npos || name.find(".old-") != std::string::npos);
}

namespace {
std::filesystem::path normalised(const std::filesystem::path& target) {
  std::filesystem::path p = std::filesystem::absolute(target).lexically_normal();
  if (!p.has_filename()) p = p.parent_path();  // "dir/" is "dir"
  return p;
}
}  // namespace

StagedDir::StagedDir(const std::filesystem::path& target, std::string what)
    : target_(normalised(target)), staging_(stagingPathFor(target_)), what_(std::move(what)) {
  std::error_code ec;
  std::filesystem::create_directories(target_.parent_path(), ec);
  if (ec) throw InputError(what_ + ": cannot create " + target_.parent_path().string() + ": " + ec.message());
  std::filesystem::remove_all(staging_, ec);
  if (!std::filesystem::create_directory(staging_, ec)) {
    throw InputError(what_ + ": cannot write into " + target_.parent_path().string() +
                     (ec ? ": " + ec.message() : std::string()));
  }
}

StagedDir::~StagedDir() {
  if (done_) return;
  std::error_code ignored;
  std::filesystem::remove_all(staging_, ignored);
}

bool StagedDir::commit(OnExisting on_existing, const std::string& doing) {
  if (done_) throw std::logic_error("StagedDir::commit twice");
  std::error_code ec;
  if (on_existing == OnExisting::kMerge && std::filesystem::is_directory(target_, ec)) {
    mergeInto();
    return true;
  }
  std::filesystem::path old;
  if (std::filesystem::exists(target_, ec)) {
    if (on_existing == OnExisting::kRefuse) {
      done_ = true;  // the results stay where the message says
      throw InputError(what_ + ": " + target_.string() + " appeared while " + doing + "; the results are left in " +
                       staging_.string());
    }
    if (on_existing == OnExisting::kReplace) {
      old = target_.parent_path() / ("." + target_.filename().string() + ".old-" + std::to_string(getpid()));
      std::filesystem::remove_all(old, ec);
      std::filesystem::rename(target_, old);
    }
  }
  std::filesystem::rename(staging_, target_, ec);
  if (ec) {
    if (on_existing == OnExisting::kKeep && std::filesystem::exists(target_)) return false;  // theirs won
    throw std::runtime_error(target_.string() + ": cannot rename " + staging_.string() + " to it: " + ec.message());
  }
  done_ = true;
  if (!old.empty()) std::filesystem::remove_all(old, ec);
  return true;
}

void StagedDir::mergeInto() {
  for (const auto& entry : std::filesystem::directory_iterator(staging_)) {
    std::error_code ec;
    std::filesystem::rename(entry.path(), target_ / entry.path().filename(), ec);
    if (ec) {
      throw std::runtime_error((target_ / entry.path().filename()).string() + ": cannot write: " + ec.message());
    }
  }
  done_ = true;
  std::error_code ignored;
  std::filesystem::remove(staging_, ignored);
}

}  // namespace tgnav::harness
