#pragma once
// Uncertainty for `tgnav report`: success rates with a 95 % Wilson score interval, and paired
// comparisons of two planners flown on the same scenes and seeds, McNemar's exact test on success
// and a seeded percentile bootstrap of the mean paired difference of goal errors.
//
// A pair is one (scene, seed) flown by both planners (their report groups' labels, params
// included). Success is the `success` status. Goal errors are paired where both trials' VO tracked
// to the goal (success or drifted), as Table II's goal error; the difference is first − second.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "harness/experiments/report.h"

namespace tgnav::harness {

struct Interval {
  double lo = 0.0;
  double hi = 0.0;
};

// The 95 % normal quantile, z = Phi^-1(0.975).
constexpr double kZ95 = 1.959963984540054;

// Wilson score interval for k successes in n >= 1 trials:
// (p + z^2/2n ± z sqrt(p(1-p)/n + z^2/4n^2)) / (1 + z^2/n), p = k/n; clamped to [0, 1].
// std::invalid_argument unless 0 <= k <= n and n >= 1.
Interval wilsonInterval(int k, int n, double z = kZ95);

// McNemar's exact test: the two-sided binomial p of b discordant pairs one way and c the other
// under p = 0.5, min(1, 2 P(X <= min(b, c))), X ~ Bin(b + c, 1/2); 1 without discordant pairs.
double mcnemarExactP(int b, int c);

// Percentile bootstrap interval of the mean: `resamples` means of samples drawn with replacement
// (std::mt19937_64 from `seed`), sorted; the interval runs from the (1 - level)/2 quantile to the
// (1 + level)/2 one (nearest rank). Empty values: none.
std::optional<Interval> bootstrapMeanInterval(const std::vector<double>& values, int resamples, std::uint64_t seed,
                                              double level = 0.95);

// The report's bootstrap: resamples and seed (fixed, so a report is reproducible).
constexpr int kBootstrapResamples = 10000;
constexpr std::uint64_t kBootstrapSeed = 20261126;
// Fewer pairs than this get an interval but are never called significant: resampling 1-4 values
// cannot stand in for the sampling distribution (every interval of same-signed pairs excludes 0).
constexpr int kMinBootstrapPairs = 5;

struct PairedComparison {
  std::string first;   // planner label (report group)
  std::string second;  // planner label
  int pairs = 0;       // (scene, seed) flown by both
  int first_only = 0;  // pairs where only the first succeeded
  int second_only = 0;
  double success_p = 1.0;                   // mcnemarExactP(first_only, second_only)
  int goal_pairs = 0;                       // pairs where both tracked to the goal
  std::optional<double> goal_difference_m;  // mean of first − second
  std::optional<Interval> goal_difference_interval_m;
  bool success_significant() const { return success_p < 0.05; }
  // The interval excludes 0, over at least kMinBootstrapPairs pairs.
  bool goal_significant() const;
};

// Every pair of planner labels that share at least one (scene, seed), in order of the labels' first
// appearance in `groups`. A label with two trials of one (scene, seed) (a sweep that repeats it)
// pairs its first.
std::vector<PairedComparison> pairedComparisons(const std::vector<IndexRow>& rows,
                                                const std::vector<ReportGroup>& groups);

// "10/10 (72–100%)": successes, trials and the Wilson interval in whole percent.
std::string formatSuccessInterval(int k, int n);
// A p value to 3 significant figures, "< 0.001" below that.
std::string formatP(double p);

// The comparisons as a Markdown section (a table and how to read it) and as CSV.
std::string comparisonsMarkdown(const std::vector<PairedComparison>& comparisons);
std::string comparisonsCsv(const std::vector<PairedComparison>& comparisons);

}  // namespace tgnav::harness
