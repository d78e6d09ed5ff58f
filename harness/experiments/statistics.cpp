#include "harness/experiments/statistics.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace tgnav::harness {
namespace {

bool trackedToGoal(const IndexRow& r) { return (r.status == "success" || r.status == "drifted") && r.goal_error_m; }

// The sorted values' element at quantile q, nearest rank: index ceil(q n) - 1, within [0, n - 1].
double nearestRank(const std::vector<double>& sorted, double q) {
  const auto n = static_cast<double>(sorted.size());
  const double rank = std::ceil(q * n) - 1.0;
  return sorted[static_cast<std::size_t>(std::clamp(rank, 0.0, n - 1.0))];
}

}  // namespace

Interval wilsonInterval(int k, int n, double z) {
  if (n < 1 || k < 0 || k > n) {
    throw std::invalid_argument("wilsonInterval: need 0 <= k <= n and n >= 1, got k = " + std::to_string(k) +
                                ", n = " + std::to_string(n));
  }
  const double nn = n;
  const double p = k / nn;
  const double z2 = z * z;
  const double centre = p + z2 / (2.0 * nn);
  const double half = z * std::sqrt(p * (1.0 - p) / nn + z2 / (4.0 * nn * nn));
  const double scale = 1.0 + z2 / nn;
  return {std::clamp((centre - half) / scale, 0.0, 1.0), std::clamp((centre + half) / scale, 0.0, 1.0)};
}

double mcnemarExactP(int b, int c) {
  if (b < 0 || c < 0) {
    throw std::invalid_argument("mcnemarExactP: counts must be >= 0, got " + std::to_string(b) + " and " +
                                std::to_string(c));
  }
  const int n = b + c;
  if (n == 0) return 1.0;
  // P(X <= min(b, c)): C(n, i) / 2^n term by term (exact for small n), in log space where 2^-n
  // would underflow.
  double tail = 0.0;
  if (n <= 1000) {
    double term = std::ldexp(1.0, -n);
    for (int i = 0; i <= std::min(b, c); ++i) {
      tail += term;
      term = term * (n - i) / (i + 1);
    }
  } else {
    for (int i = 0; i <= std::min(b, c); ++i) {
      tail += std::exp(std::lgamma(n + 1.0) - std::lgamma(i + 1.0) - std::lgamma(n - i + 1.0) - n * std::log(2.0));
    }
  }
  return std::min(1.0, 2.0 * tail);
}

std::optional<Interval> bootstrapMeanInterval(const std::vector<double>& values, int resamples, std::uint64_t seed,
                                              double level) {
  if (values.empty()) return std::nullopt;
  if (resamples < 1 || !(level > 0.0 && level < 1.0)) {
    throw std::invalid_argument("bootstrapMeanInterval: need resamples >= 1 and level in (0, 1)");
  }
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<std::size_t> pick(0, values.size() - 1);
  std::vector<double> means(static_cast<std::size_t>(resamples));
  for (double& m : means) {
    double sum = 0.0;
    for (std::size_t i = 0; i < values.size(); ++i) sum += values[pick(rng)];
    m = sum / static_cast<double>(values.size());
  }
  std::sort(means.begin(), means.end());
  return Interval{nearestRank(means, 0.5 * (1.0 - level)), nearestRank(means, 0.5 * (1.0 + level))};
}

std::vector<PairedComparison> pairedComparisons(const std::vector<IndexRow>& rows,
                                                const std::vector<ReportGroup>& groups) {
  // label -> (scene, seed) -> its first row.
  std::vector<std::string> labels;
  std::map<std::string, std::map<std::pair<std::string, std::uint64_t>, std::size_t>> trials;
  for (const ReportGroup& g : groups) {
    if (std::find(labels.begin(), labels.end(), g.label) == labels.end()) labels.push_back(g.label);
    auto& by_key = trials[g.label];
    for (const std::size_t i : g.trials) by_key.emplace(std::make_pair(rows[i].scene, rows[i].seed), i);
  }
  std::vector<PairedComparison> out;
  for (std::size_t a = 0; a < labels.size(); ++a) {
    for (std::size_t b = a + 1; b < labels.size(); ++b) {
      PairedComparison c;
      c.first = labels[a];
      c.second = labels[b];
      const auto& second = trials[c.second];
      std::vector<double> differences;
      for (const auto& [key, i] : trials[c.first]) {
        const auto it = second.find(key);
        if (it == second.end()) continue;
        const IndexRow& x = rows[i];
        const IndexRow& y = rows[it->second];
        ++c.pairs;
        const bool xs = x.status == "success";
        const bool ys = y.status == "success";
        if (xs && !ys) ++c.first_only;
        if (ys && !xs) ++c.second_only;
        if (trackedToGoal(x) && trackedToGoal(y)) differences.push_back(*x.goal_error_m - *y.goal_error_m);
      }
      if (c.pairs == 0) continue;
      c.success_p = mcnemarExactP(c.first_only, c.second_only);
      c.goal_pairs = static_cast<int>(differences.size());
      if (!differences.empty()) {
        double sum = 0.0;
        for (const double d : differences) sum += d;
        c.goal_difference_m = sum / static_cast<double>(differences.size());
        c.goal_difference_interval_m = bootstrapMeanInterval(differences, kBootstrapResamples, kBootstrapSeed);
      }
      out.push_back(c);
    }
  }
  return out;
}

bool PairedComparison::goal_significant() const {
  return goal_pairs >= kMinBootstrapPairs && goal_difference_interval_m &&
         (goal_difference_interval_m->lo > 0.0 || goal_difference_interval_m->hi < 0.0);
}

std::string formatP(double p) { return p < 0.001 ? "< 0.001" : formatSig3(p); }

std::string formatSuccessInterval(int k, int n) {
  const Interval w = wilsonInterval(k, n);
  return std::to_string(k) + "/" + std::to_string(n) + " (" + std::to_string(std::lround(100.0 * w.lo)) + "–" +
         std::to_string(std::lround(100.0 * w.hi)) + "%)";
}

std::string comparisonsMarkdown(const std::vector<PairedComparison>& comparisons) {
  std::ostringstream out;
  out << "\n## Paired comparisons\n\n";
  if (comparisons.empty()) {
    out << "No two planners were flown on the same scene and seed.\n";
    return out.str();
  }
  const std::vector<std::string> header = {"First",
                                           "Second",
                                           "Pairs",
                                           "Success: first only / second only",
                                           "McNemar p",
                                           "Goal pairs",
                                           "Goal error first − second (m), 95 % interval",
                                           "Significant at 5 %"};
  const std::vector<bool> right = {false, false, true, true, true, true, true, false};
  std::vector<std::vector<std::string>> cells;
  for (const PairedComparison& c : comparisons) {
    std::string goal = "–";
    if (c.goal_difference_m) {
      goal = formatSig3(*c.goal_difference_m) + " [" + formatSig3(c.goal_difference_interval_m->lo) + ", " +
             formatSig3(c.goal_difference_interval_m->hi) + "]";
    }
    std::string significant;
    if (c.success_significant()) significant = "success";
    if (c.goal_significant()) significant += std::string(significant.empty() ? "" : ", ") + "goal error";
    cells.push_back({markdownCell(c.first), markdownCell(c.second), std::to_string(c.pairs),
                     std::to_string(c.first_only) + " / " + std::to_string(c.second_only), formatP(c.success_p),
                     std::to_string(c.goal_pairs), goal, significant.empty() ? "–" : "**" + significant + "**"});
  }
  out << markdownTable(header, right, cells);
  out << "\nPairs: (scene, seed) flown by both planners. Success: McNemar's exact test (two-sided binomial of the "
         "pairs where only one planner succeeded). Goal error: the mean paired difference over the pairs where both "
         "VOs tracked to the goal, with a percentile bootstrap interval ("
      << kBootstrapResamples << " resamples, seed " << kBootstrapSeed
      << "); significant where it excludes 0 over at least " << kMinBootstrapPairs
      << " pairs. VO success above: successes/trials (95 % Wilson interval).\n";
  return out.str();
}

std::string comparisonsCsv(const std::vector<PairedComparison>& comparisons) {
  std::ostringstream out;
  out << "first,second,pairs,first_only,second_only,success_p,success_significant,goal_pairs,"
         "goal_difference_mean_m,goal_difference_lo_m,goal_difference_hi_m,goal_significant\n";
  for (const PairedComparison& c : comparisons) {
    out << c.first << ',' << c.second << ',' << c.pairs << ',' << c.first_only << ',' << c.second_only << ','
        << csvNumber(c.success_p) << ',' << (c.success_significant() ? 1 : 0) << ',' << c.goal_pairs << ',';
    if (c.goal_difference_m) {
      out << csvNumber(*c.goal_difference_m) << ',' << csvNumber(c.goal_difference_interval_m->lo) << ','
          << csvNumber(c.goal_difference_interval_m->hi);
    } else {
      out << ",,";
    }
    out << ',' << (c.goal_significant() ? 1 : 0) << '\n';
  }
  return out.str();
}

}  // namespace tgnav::harness
