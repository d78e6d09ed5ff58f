#pragma once
// Running shell commands (sbatch, squeue, the plot script) and quoting their arguments.
#include <string>

namespace tgnav::harness {

// A word for a POSIX shell: bare when safe, else single-quoted.
std::string shellWord(const std::string& s);

struct CommandResult {
  int rc = -1;         // the exit status; -1 when it could not start or ended on a signal
  std::string output;  // stdout and stderr, as printed
};
// Runs `command` with /bin/sh, its stderr merged into its stdout.
CommandResult runCommand(const std::string& command);

}  // namespace tgnav::harness
