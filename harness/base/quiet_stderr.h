#pragma once
// OctoMap's readers and writers print progress (" done.", "Reading ...") on stderr; while one
// of these lives, stderr goes to /dev/null so that the program's output stays its own lines.
#include <fcntl.h>
#include <unistd.h>

namespace tgnav::harness {

class QuietStderr {
 public:
  QuietStderr() : saved_(dup(STDERR_FILENO)) {
    const int null = open("/dev/null", O_WRONLY);
    if (null >= 0) {
      dup2(null, STDERR_FILENO);
      close(null);
    }
  }
  ~QuietStderr() {
    if (saved_ >= 0) {
      dup2(saved_, STDERR_FILENO);
      close(saved_);
    }
  }
  QuietStderr(const QuietStderr&) = delete;
  QuietStderr& operator=(const QuietStderr&) = delete;
  QuietStderr(QuietStderr&&) = delete;  // owns the saved stderr fd
  QuietStderr& operator=(QuietStderr&&) = delete;

 private:
  int saved_;
};

}  // namespace tgnav::harness
