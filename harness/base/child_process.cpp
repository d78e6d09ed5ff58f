#include "harness/base/child_process.h"

#include <fcntl.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <thread>

namespace tgnav::harness {

namespace {

constexpr int kSliceMs = 50;  // how often a wait looks at `interrupt`

int msUntil(ChildProcess::Clock::time_point deadline) {
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - ChildProcess::Clock::now());
  return static_cast<int>(std::clamp<long long>(left.count(), 0, kSliceMs));
}

bool raised(const std::atomic<bool>* interrupt) { return interrupt != nullptr && interrupt->load(); }

std::string signalName(int sig) {
  const char* name = sigabbrev_np(sig);
  return std::to_string(sig) + (name ? std::string(", SIG") + name : std::string());
}

std::string describe(int status) {
  if (WIFEXITED(status)) {
    const int code = WEXITSTATUS(status);
    std::string text = "exited with status " + std::to_string(code);
    // The shell reports a command killed by signal S as 128 + S.
    if (code > 128 && code < 128 + 65) text += " (its command was killed by signal " + signalName(code - 128) + ")";
    return text;
  }
  if (WIFSIGNALED(status)) return "killed by signal " + signalName(WTERMSIG(status));
  return "ended with status " + std::to_string(status);
}

[[noreturn]] void systemError(const std::string& what) {
  throw std::runtime_error("cannot start the process: " + what + ": " + std::strerror(errno));
}

}  // namespace

ChildProcess::ChildProcess(const std::string& command, const std::filesystem::path& dir,
                           const std::filesystem::path& stderr_file) {
  int in[2];
  int out[2];
  if (pipe2(in, O_CLOEXEC) != 0) systemError("pipe");
  if (pipe2(out, O_CLOEXEC) != 0) {
    ::close(in[0]);
    ::close(in[1]);
    systemError("pipe");
  }
  const int err = ::open(stderr_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (err < 0) {
    for (int fd : {in[0], in[1], out[0], out[1]}) ::close(fd);
    systemError(stderr_file.string());
  }
  const std::string dir_text = dir.string();
  // Everything the child needs, made before fork(): after it, only async-signal-safe calls.
  std::string sh = "sh";
  std::string dash_c = "-c";
  std::string cmd = command;
  char* argv[] = {sh.data(), dash_c.data(), cmd.data(), nullptr};
  const pid_t pid = fork();
  if (pid == 0) {  // the child: async-signal-safe calls only, up to exec
    setpgid(0, 0);
    dup2(in[0], STDIN_FILENO);
    dup2(out[1], STDOUT_FILENO);
    dup2(err, STDERR_FILENO);
    close_range(3, ~0U, 0);
    signal(SIGPIPE, SIG_DFL);
    if (chdir(dir_text.c_str()) != 0) {
      static const char kMsg[] = "tgnav: cannot enter the planner's working directory\n";
      (void)!::write(STDERR_FILENO, kMsg, sizeof kMsg - 1);
      _exit(126);
    }
    execve("/bin/sh", argv, environ);
    _exit(127);
  }
  const int fork_errno = errno;
  ::close(in[0]);
  ::close(out[1]);
  ::close(err);
  if (pid < 0) {
    ::close(in[1]);
    ::close(out[0]);
    errno = fork_errno;
    systemError("fork");
  }
  setpgid(pid, pid);  // also here: whichever runs first
  pid_ = pid;
  stdin_fd_ = in[1];
  stdout_fd_ = out[0];
  fcntl(stdin_fd_, F_SETFL, fcntl(stdin_fd_, F_GETFL) | O_NONBLOCK);
  fcntl(stdout_fd_, F_SETFL, fcntl(stdout_fd_, F_GETFL) | O_NONBLOCK);
}

ChildProcess::~ChildProcess() {
  stop(0.0);
  if (stdout_fd_ >= 0) ::close(stdout_fd_);
}

ChildProcess::Io ChildProcess::write(const std::string& text, Clock::time_point deadline,
                                     const std::atomic<bool>* interrupt) {
  if (stdin_fd_ < 0) return Io::kClosed;
  sigset_t pipe_set;
  sigset_t old;
  sigemptyset(&pipe_set);
  sigaddset(&pipe_set, SIGPIPE);
  pthread_sigmask(SIG_BLOCK, &pipe_set, &old);
  std::size_t done = 0;
  Io result = Io::kOk;
  while (done < text.size()) {
    if (raised(interrupt)) {
      result = Io::kInterrupted;
      break;
    }
    const ssize_t n = ::write(stdin_fd_, text.data() + done, text.size() - done);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno == EPIPE) {
      const timespec zero{0, 0};
      sigtimedwait(&pipe_set, nullptr, &zero);  // the SIGPIPE it raised, pending while blocked
      result = Io::kClosed;
      break;
    }
    if (n < 0 && errno != EAGAIN && errno != EINTR) {
      result = Io::kClosed;
      break;
    }
    if (Clock::now() >= deadline) {
      result = Io::kTimeout;
      break;
    }
    pollfd p{stdin_fd_, POLLOUT, 0};
    poll(&p, 1, msUntil(deadline));
  }
  pthread_sigmask(SIG_SETMASK, &old, nullptr);
  return result;
}

ChildProcess::Io ChildProcess::readLine(std::string* line, Clock::time_point deadline, std::size_t max_bytes,
                                        const std::atomic<bool>* interrupt) {
  std::size_t scanned = 0;
  char chunk[65536];
  for (;;) {
    const std::size_t nl = buffer_.find('\n', scanned);
    if (nl != std::string::npos) {
      if (nl > max_bytes) return Io::kTooLong;
      line->assign(buffer_, 0, nl);
      buffer_.erase(0, nl + 1);
      return Io::kOk;
    }
    scanned = buffer_.size();
    if (buffer_.size() > max_bytes) return Io::kTooLong;
    if (stdout_fd_ < 0) return Io::kClosed;
    const ssize_t n = ::read(stdout_fd_, chunk, sizeof chunk);
    if (n > 0) {
      buffer_.append(chunk, static_cast<std::size_t>(n));
      continue;
    }
    if (n == 0 || (errno != EAGAIN && errno != EINTR)) return Io::kClosed;
    if (raised(interrupt)) return Io::kInterrupted;
    if (Clock::now() >= deadline) return Io::kTimeout;
    pollfd p{stdout_fd_, POLLIN, 0};
    poll(&p, 1, msUntil(deadline));
  }
}

void ChildProcess::closeStdin() {
  if (stdin_fd_ >= 0) ::close(stdin_fd_);
  stdin_fd_ = -1;
}

std::string ChildProcess::waitExit(double wait_s) {
  if (reaped_) return ended_;
  const auto deadline =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(wait_s));
  for (;;) {
    siginfo_t info{};
    // WNOWAIT: the child stays a zombie, so its process group id cannot be reused before reap().
    if (waitid(P_PID, static_cast<id_t>(pid_), &info, WEXITED | WNOHANG | WNOWAIT) == 0 && info.si_pid == pid_) {
      reap();
      return ended_;
    }
    if (Clock::now() >= deadline) return "";
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

void ChildProcess::reap() {
  if (reaped_) return;
  kill(-pid_, SIGKILL);  // what the shell left running
  int status = 0;
  while (waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
  }
  reaped_ = true;
  ended_ = describe(status);
}

std::string ChildProcess::stop(double grace_s) {
  if (pid_ < 0) return ended_;
  closeStdin();
  if (!reaped_ && waitExit(grace_s).empty()) reap();
  return ended_;
}

std::string fileTail(const std::filesystem::path& file, std::size_t max_lines, std::size_t max_bytes) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return "";
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  const std::streamoff from = std::max<std::streamoff>(0, size - static_cast<std::streamoff>(max_bytes));
  in.seekg(from);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::size_t pos = text.size();
  if (pos > 0 && text[pos - 1] == '\n') --pos;
  for (std::size_t lines = 0; pos > 0; --pos) {
    if (text[pos - 1] == '\n' && ++lines == max_lines) break;
  }
  return text.substr(pos);
}

}  // namespace tgnav::harness
