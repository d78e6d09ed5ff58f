#pragma once
// The `tgnav eval` job: the error of any estimated trajectory against a reference, both TUM, KITTI
// or EuRoC files (vo/trajectory_formats.h), with evo's definitions (vo/metrics.h): association by
// time (by line for KITTI), an alignment, ATE statistics and RPE. With an output folder it writes
// eval.json (settings, pairs, alignment, ATE and RPE statistics, the reference's path length),
// eval_pairs.csv (one row per pair: t, the reference and aligned estimate positions, the error and
// the distance along the reference) and the figure eval.<format>, into a new folder, whole or not
// at all.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "harness/io/figures.h"

namespace tgnav::harness {

struct EvalJob {
  std::filesystem::path ref;   // reference (ground-truth) trajectory file
  std::filesystem::path est;   // estimated trajectory file, in the same format
  std::string format = "tum";  // tum | kitti | euroc
  std::string align = "se3";   // se3 | sim3 | posyaw | origin | none
  double rpe_delta = 1.0;      // in rpe_unit
  std::string rpe_unit = "m";  // m | frames
  double max_dt_s = 0.02;      // association tolerance (KITTI files are paired by line instead)
  std::filesystem::path out;   // a new folder; empty: nothing is written
  FigureFormat figure_format = FigureFormat::kPng;
};

// False positive: clang-tidy 14 takes the implicit default constructor for noexcept (it is not: json's can throw).
// NOLINTNEXTLINE(bugprone-exception-escape)
struct EvalResult {
  nlohmann::ordered_json summary;  // eval.json's content (also without an output folder)
  std::filesystem::path out;       // the folder written; empty when none was asked for
  FigureFormat figure_format = FigureFormat::kPng;
  FigureOutcome figures;
  std::vector<std::string> warnings;  // lines for stderr: timestamps that repeat or go back
};

// InputError, one line naming the option, or the file and line, for: an unknown --format,
// --align or --rpe-unit; a --rpe-delta that is not > 0 (a whole number of frames for frames); a
// negative --max-dt; an --out that exists; a missing file, an empty one, a malformed line (wrong
// count of numbers: a file of another format; non-finite values; a non-unit quaternion; a KITTI
// rotation that is not one); KITTI files of different lengths; no pair within --max-dt. Nothing is
// written then. Timestamps that repeat or go back are paired by evo's rule (vo::associate), with a
// warning that counts them.
EvalResult runEval(const EvalJob& job);

// The one line `tgnav eval` prints.
std::string evalSummaryLine(const EvalResult& result);

}  // namespace tgnav::harness
