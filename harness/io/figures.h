#pragma once
// Every figure of tgnav is drawn by one Python module, scripts/tgnav_plots.py (matplotlib), from
// the data files a run wrote; C++ never plots. This runs it on a folder. A missing interpreter or
// matplotlib is not an error: the data is complete without the figures, and the caller says so
// in one line.
#include <filesystem>
#include <string>

namespace tgnav::harness {

enum class FigureFormat { kPng, kPdf, kSvg };
// "png" | "pdf" | "svg"; InputError naming `option` otherwise.
FigureFormat parseFigureFormat(const std::string& text, const std::string& option = "--figure-format");
const char* toString(FigureFormat format);

struct FigureOutcome {
  enum class Status { kDrawn, kSkipped, kFailed } status = Status::kDrawn;
  std::string message;  // one line: why they were skipped, or what failed
};

// Runs `$TGNAV_PYTHON (default /usr/bin/python3) tgnav_plots.py KIND DIR --format F [--out OUT]`
// with the script from $TGNAV_SCRIPTS_DIR (default: the source tree's scripts/).
// KIND: trial | plan | map | report | eval (the module's docstring lists their files).
FigureOutcome drawFigures(const std::string& kind, const std::filesystem::path& dir, FigureFormat format,
                          const std::filesystem::path& out = {});

// "tgnav <command>: figures skipped: ..." or "... figures failed: ..." on stderr; nothing when drawn.
void reportFigures(const std::string& command, const FigureOutcome& outcome);

}  // namespace tgnav::harness
