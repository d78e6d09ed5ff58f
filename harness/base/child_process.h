#pragma once
// A child process that the harness talks to line by line (an external planner,
// docs/PLANNER_PROTOCOL.md): /bin/sh -c COMMAND in its own process group, its stdin and stdout
// pipes, its stderr into a file. Every wait has a deadline and can be interrupted; the child may
// hang, exit, crash or flood its output, and none of it takes the harness down (SIGPIPE is
// blocked around writes). The destructor ends the whole process group.
#include <sys/types.h>

#include <atomic>
#include <chrono>
#include <cstddef>
#include <filesystem>
#include <string>

namespace tgnav::harness {

class ChildProcess {
 public:
  using Clock = std::chrono::steady_clock;
  enum class Io {
    kOk,
    kTimeout,      // the deadline passed
    kClosed,       // the other end is closed (EOF on stdout before a newline, EPIPE on stdin)
    kTooLong,      // a line longer than the limit
    kInterrupted,  // `interrupt` was raised
  };

  // Starts `command` in `dir` with its stderr written to `stderr_file` (created or truncated).
  // std::runtime_error when the system cannot start it (no processes or pipes left); a command
  // that does not exist starts, and its shell exits with status 127.
  ChildProcess(const std::string& command, const std::filesystem::path& dir, const std::filesystem::path& stderr_file);
  ~ChildProcess();
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;
  ChildProcess(ChildProcess&&) = delete;
  ChildProcess& operator=(ChildProcess&&) = delete;

  // Writes all of `text` to the child's stdin.
  Io write(const std::string& text, Clock::time_point deadline, const std::atomic<bool>* interrupt = nullptr);
  // Reads the next line of the child's stdout into `line` (without its '\n').
  Io readLine(std::string* line, Clock::time_point deadline, std::size_t max_bytes,
              const std::atomic<bool>* interrupt = nullptr);

  // Closes its stdin, gives it `grace_s` to exit, then kills its process group. Returns how it
  // ended: "exited with status N", "killed by signal N (NAME)"; the same on a second call.
  std::string stop(double grace_s);
  // Waits up to `wait_s` for the child to exit by itself (after kClosed, say) and returns how it
  // ended, or "" if it is still running.
  std::string waitExit(double wait_s);

  pid_t pid() const { return pid_; }

 private:
  void closeStdin();
  void reap();  // kills what is left of the group and collects the child's status

  pid_t pid_ = -1;
  int stdin_fd_ = -1;
  int stdout_fd_ = -1;
  std::string buffer_;  // read past the last line returned
  bool reaped_ = false;
  std::string ended_;
};

// The last `max_lines` lines (at most `max_bytes` bytes) of a text file; "" when unreadable.
std::string fileTail(const std::filesystem::path& file, std::size_t max_lines = 20, std::size_t max_bytes = 4096);

}  // namespace tgnav::harness
