// harness/base/child_process.h: a child that answers, hangs, dies, floods its output or leaves
// children behind; every wait ends by its deadline and the harness survives writing to a child
// that is gone (SIGPIPE).
#include "harness/base/child_process.h"

#include <gtest/gtest.h>
#include <signal.h>

#include <fstream>
#include <thread>

#include "test_util.h"

namespace tgnav::harness {
namespace {

using Clock = ChildProcess::Clock;

Clock::time_point in(double s) {
  return Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
}

TEST(ChildProcess, EchoesLinesAndEndsWithItsStatus) {
  const auto dir = test::tempDir();
  ChildProcess child("while read line; do echo \"got $line\"; done; echo bye >&2; exit 4", dir, dir / "err.txt");
  EXPECT_EQ(child.write("one\ntwo\n", in(5)), ChildProcess::Io::kOk);
  std::string line;
  ASSERT_EQ(child.readLine(&line, in(5), 100), ChildProcess::Io::kOk);
  EXPECT_EQ(line, "got one");
  ASSERT_EQ(child.readLine(&line, in(5), 100), ChildProcess::Io::kOk);
  EXPECT_EQ(line, "got two");
  EXPECT_EQ(child.stop(5.0), "exited with status 4");
  EXPECT_EQ(child.stop(5.0), "exited with status 4");  // the same on a second call
  EXPECT_EQ(fileTail(dir / "err.txt"), "bye\n");
}

TEST(ChildProcess, RunsInItsFolder) {
  const auto dir = test::tempDir();
  ChildProcess child("pwd", dir, dir / "err.txt");
  std::string line;
  ASSERT_EQ(child.readLine(&line, in(5), 4096), ChildProcess::Io::kOk);
  EXPECT_EQ(std::filesystem::canonical(line), std::filesystem::canonical(dir));
}

TEST(ChildProcess, AHangEndsAtTheDeadlineAndStopKillsTheWholeGroup) {
  const auto dir = test::tempDir();
  // The shell stays the parent of sleep: both must go.
  ChildProcess child("sleep 600 & echo $! > child.pid; sleep 600", dir, dir / "err.txt");
  std::string line;
  const auto t0 = Clock::now();
  EXPECT_EQ(child.readLine(&line, in(0.3), 100), ChildProcess::Io::kTimeout);
  EXPECT_LT(Clock::now() - t0, std::chrono::seconds(3));
  EXPECT_EQ(child.stop(0.1), "killed by signal 9, SIGKILL");
  int grandchild = 0;
  std::ifstream(dir / "child.pid") >> grandchild;
  ASSERT_GT(grandchild, 0);
  // Killed with its group (a zombie until init reaps it, at most).
  bool gone = false;
  for (int i = 0; i < 100 && !gone; ++i) {
    std::ifstream stat("/proc/" + std::to_string(grandchild) + "/stat");
    std::string pid, comm, state;
    gone = !(stat >> pid >> comm >> state) || state == "Z";
    if (!gone) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_TRUE(gone);
}

TEST(ChildProcess, DeathIsClosedOutputAndNamesTheSignal) {
  const auto dir = test::tempDir();
  ChildProcess child("kill -SEGV $$", dir, dir / "err.txt");
  std::string line;
  EXPECT_EQ(child.readLine(&line, in(5), 100), ChildProcess::Io::kClosed);
  EXPECT_EQ(child.waitExit(5.0), "killed by signal 11, SIGSEGV");
  ChildProcess shell_reported("sh -c 'kill -SEGV $$'", dir, dir / "err.txt");
  EXPECT_EQ(shell_reported.readLine(&line, in(5), 100), ChildProcess::Io::kClosed);
  EXPECT_EQ(shell_reported.waitExit(5.0), "exited with status 139 (its command was killed by signal 11, SIGSEGV)");
}

TEST(ChildProcess, WritingToAChildThatIsGoneIsClosedNotSigpipe) {
  const auto dir = test::tempDir();
  ChildProcess child("exit 0", dir, dir / "err.txt");
  EXPECT_FALSE(child.waitExit(5.0).empty());
  const std::string big(1 << 20, 'x');  // more than a pipe holds
  EXPECT_EQ(child.write(big, in(5)), ChildProcess::Io::kClosed);
  sigset_t pending;
  sigpending(&pending);
  EXPECT_EQ(sigismember(&pending, SIGPIPE), 0);
}

TEST(ChildProcess, AFloodIsTooLongAndAStalledReaderTimesOut) {
  const auto dir = test::tempDir();
  ChildProcess flood("head -c 300000 /dev/zero | tr '\\0' a; sleep 600", dir, dir / "err.txt");
  std::string line;
  EXPECT_EQ(flood.readLine(&line, in(5), 100000), ChildProcess::Io::kTooLong);
  ChildProcess deaf("sleep 600", dir, dir / "err.txt");
  const std::string big(1 << 20, 'x');
  EXPECT_EQ(deaf.write(big, in(0.3)), ChildProcess::Io::kTimeout);
}

TEST(ChildProcess, InterruptEndsAWait) {
  const auto dir = test::tempDir();
  ChildProcess child("sleep 600", dir, dir / "err.txt");
  std::atomic<bool> interrupt{true};
  std::string line;
  EXPECT_EQ(child.readLine(&line, in(60), 100, &interrupt), ChildProcess::Io::kInterrupted);
}

TEST(ChildProcess, FileTailKeepsTheLastLines) {
  const auto dir = test::tempDir();
  {
    std::ofstream out(dir / "log.txt");
    for (int i = 1; i <= 50; ++i) out << "line " << i << "\n";
  }
  const std::string tail = fileTail(dir / "log.txt", 3);
  EXPECT_EQ(tail, "line 48\nline 49\nline 50\n");
  EXPECT_EQ(fileTail(dir / "missing.txt"), "");
}

}  // namespace
}  // namespace tgnav::harness
