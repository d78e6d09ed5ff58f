#include "harness/io/figures.h"

#include <cstdio>
#include <cstdlib>

#include "harness/base/errors.h"
#include "harness/base/shell.h"

namespace tgnav::harness {

namespace {
// The module's exit status when matplotlib or numpy cannot be imported.
constexpr int kSkippedStatus = 3;

std::string lastLine(const std::string& text) {
  std::string t = text;
  while (!t.empty() && (t.back() == '\n' || t.back() == ' ')) t.pop_back();
  const std::size_t nl = t.rfind('\n');
  return nl == std::string::npos ? t : t.substr(nl + 1);
}

std::string fromEnv(const char* name, const std::string& fallback) {
  const char* v = std::getenv(name);
  return v != nullptr && *v != '\0' ? std::string(v) : fallback;
}
}  // namespace

FigureFormat parseFigureFormat(const std::string& text, const std::string& option) {
  if (text == "png") return FigureFormat::kPng;
  if (text == "pdf") return FigureFormat::kPdf;
  if (text == "svg") return FigureFormat::kSvg;
  throw InputError(option + ": '" + text + "' is not a figure format; expected png, pdf or svg");
}

const char* toString(FigureFormat format) {
  switch (format) {
    case FigureFormat::kPng:
      return "png";
    case FigureFormat::kPdf:
      return "pdf";
    case FigureFormat::kSvg:
      return "svg";
  }
  return "?";
}

FigureOutcome drawFigures(const std::string& kind, const std::filesystem::path& dir, FigureFormat format,
                          const std::filesystem::path& out) {
  const std::string python = fromEnv("TGNAV_PYTHON", "/usr/bin/python3");
  const std::filesystem::path script =
      std::filesystem::path(fromEnv("TGNAV_SCRIPTS_DIR", TGNAV_SOURCE_DIR "/scripts")) / "tgnav_plots.py";
  std::error_code ec;
  if (std::filesystem::path(python).is_absolute() && !std::filesystem::exists(python, ec)) {
    return {FigureOutcome::Status::kSkipped, python + " not found (set TGNAV_PYTHON to a python3 with matplotlib)"};
  }
  if (!std::filesystem::exists(script, ec)) {
    return {FigureOutcome::Status::kSkipped, script.string() + " not found (set TGNAV_SCRIPTS_DIR)"};
  }
  std::string command = shellWord(python) + " " + shellWord(script.string()) + " " + kind + " " +
                        shellWord(dir.string()) + " --format " + toString(format);
  if (!out.empty()) command += " --out " + shellWord(out.string());
  const CommandResult r = runCommand(command);
  if (r.rc == 0) return {};
  const std::string why = lastLine(r.output);
  if (r.rc == kSkippedStatus) {
    const std::string prefix = "tgnav_plots.py: figures skipped: ";
    return {FigureOutcome::Status::kSkipped, why.rfind(prefix, 0) == 0 ? why.substr(prefix.size()) : why};
  }
  return {FigureOutcome::Status::kFailed,
          why.empty() ? "tgnav_plots.py exited with status " + std::to_string(r.rc) : why};
}

void reportFigures(const std::string& command, const FigureOutcome& outcome) {
  if (outcome.status == FigureOutcome::Status::kDrawn) return;
  const char* what = outcome.status == FigureOutcome::Status::kSkipped ? "skipped" : "failed";
  std::fprintf(stderr, "%s: figures %s: %s\n", command.c_str(), what, outcome.message.c_str());
}

}  // namespace tgnav::harness
