// The report's statistics against values computed independently: Wilson intervals and McNemar's
// exact p from scipy 1.10 (scipy.stats.binomtest(k, n).proportion_ci(method="wilson"),
// binomtest(b, b + c, 0.5).pvalue), the bootstrap against normal theory, and the pairing of trials.
#include "harness/experiments/statistics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>
#include <vector>

namespace tgnav::harness {
namespace {

TEST(Statistics, WilsonIntervalMatchesScipy) {
  const struct {
    int k, n;
    double lo, hi;
  } cases[] = {
      {3, 3, 0.4385029682449546, 1.0},
      {0, 10, 0.0, 0.27753279986288926},
      {5, 10, 0.236593090512564, 0.7634069094874361},
      {2, 2, 0.34238022750665303, 1.0},
      {1, 1, 0.20654931437723745, 1.0},
      {0, 1, 0.0, 0.7934506856227626},
      {42, 48, 0.7529954171361317, 0.9414294856142802},
      {7, 9, 0.4525889691069889, 0.9367748928821533},
  };
  for (const auto& c : cases) {
    const Interval w = wilsonInterval(c.k, c.n);
    EXPECT_NEAR(w.lo, c.lo, 1e-12) << c.k << "/" << c.n;
    EXPECT_NEAR(w.hi, c.hi, 1e-12) << c.k << "/" << c.n;
  }
  EXPECT_EQ(formatSuccessInterval(42, 48), "42/48 (75–94%)");
  EXPECT_EQ(formatSuccessInterval(3, 3), "3/3 (44–100%)");
  EXPECT_THROW(wilsonInterval(1, 0), std::invalid_argument);
  EXPECT_THROW(wilsonInterval(4, 3), std::invalid_argument);
  EXPECT_THROW(wilsonInterval(-1, 3), std::invalid_argument);
}

TEST(Statistics, McNemarExactMatchesScipy) {
  EXPECT_DOUBLE_EQ(mcnemarExactP(6, 0), 0.03125);  // 10 seeds: 6 discordant pairs all one way
  EXPECT_DOUBLE_EQ(mcnemarExactP(0, 6), 0.03125);
  EXPECT_DOUBLE_EQ(mcnemarExactP(3, 0), 0.25);  // 3 seeds can never differ significantly
  EXPECT_DOUBLE_EQ(mcnemarExactP(5, 2), 0.453125);
  EXPECT_DOUBLE_EQ(mcnemarExactP(10, 10), 1.0);
  EXPECT_DOUBLE_EQ(mcnemarExactP(1, 0), 1.0);
  EXPECT_NEAR(mcnemarExactP(20, 5), 0.004077315330505371, 1e-14);
  EXPECT_DOUBLE_EQ(mcnemarExactP(0, 0), 1.0);
  // Beyond 2^-1074 (log space): 600 against 500.
  EXPECT_NEAR(mcnemarExactP(600, 500), 0.002819544991436429, 1e-9);
  EXPECT_THROW(mcnemarExactP(-1, 2), std::invalid_argument);
}

TEST(Statistics, BootstrapIntervalIsSeededAndAgreesWithNormalTheory) {
  std::vector<double> values(100);
  std::iota(values.begin(), values.end(), 0.0);  // mean 49.5, standard error 29.01 / 10
  const auto a = bootstrapMeanInterval(values, 10000, 1);
  const auto again = bootstrapMeanInterval(values, 10000, 1);
  ASSERT_TRUE(a && again);
  EXPECT_EQ(a->lo, again->lo);  // the same seed, the same interval
  EXPECT_EQ(a->hi, again->hi);
  const double se = std::sqrt(833.25 / 100.0);  // the population sd of 0..99 (the bootstrap's), over sqrt(n)
  EXPECT_NEAR(a->lo, 49.5 - kZ95 * se, 0.3);
  EXPECT_NEAR(a->hi, 49.5 + kZ95 * se, 0.3);
  const auto other = bootstrapMeanInterval(values, 10000, 2);
  EXPECT_TRUE(other->lo != a->lo || other->hi != a->hi);
  const auto constant = bootstrapMeanInterval({0.25, 0.25, 0.25}, 100, 1);
  EXPECT_EQ(constant->lo, 0.25);
  EXPECT_EQ(constant->hi, 0.25);
  EXPECT_FALSE(bootstrapMeanInterval({}, 100, 1));
  EXPECT_THROW(bootstrapMeanInterval(values, 0, 1), std::invalid_argument);
}

IndexRow trial(const std::string& scene, const std::string& planner, std::uint64_t seed, const std::string& status,
               std::optional<double> goal = std::nullopt) {
  IndexRow r;
  r.id = scene + "-" + planner + "-" + std::to_string(seed);
  r.scene = scene;
  r.planner = planner;
  r.seed = seed;
  r.status = status;
  r.goal_error_m = goal;
  return r;
}

// Pairs are (scene, seed) flown by both; McNemar counts the pairs where only one succeeded; goal
// errors pair where both tracked to the goal (a drifted trial did too).
TEST(Statistics, PairedComparisonsPairBySceneAndSeed) {
  std::vector<IndexRow> rows;
  // Proposed: success on seeds 1-6 of two scenes, one drifted (it tracked to the goal too).
  for (const std::string scene : {"a", "b"}) {
    for (std::uint64_t s = 1; s <= 6; ++s) {
      const bool drift = scene == "b" && s == 5;
      rows.push_back(trial(scene, "proposed", s, drift ? "drifted" : "success", 0.1 * static_cast<double>(s)));
    }
  }
  // AP: lost on scene a, success on b seeds 1-5 with goal errors 0.05 below the proposed's; seed 7
  // of scene b flown by AP only.
  for (std::uint64_t s = 1; s <= 6; ++s) rows.push_back(trial("a", "agnostic", s, "vo_lost"));
  for (std::uint64_t s = 1; s <= 5; ++s) {
    rows.push_back(trial("b", "agnostic", s, "success", 0.1 * static_cast<double>(s) - 0.05));
  }
  rows.push_back(trial("b", "agnostic", 7, "success", 0.2));
  std::vector<PairedComparison> c = pairedComparisons(rows, groupTrials(rows));
  ASSERT_EQ(c.size(), 1u);
  EXPECT_EQ(c[0].first, "Proposed");
  EXPECT_EQ(c[0].second, "AP");
  EXPECT_EQ(c[0].pairs, 11);      // a: 6, b: seeds 1-5
  EXPECT_EQ(c[0].first_only, 6);  // scene a; b's drifted seed 5 is no success, AP's is
  EXPECT_EQ(c[0].second_only, 1);
  EXPECT_DOUBLE_EQ(c[0].success_p, 0.125);  // scipy binomtest(1, 7, 0.5)
  EXPECT_FALSE(c[0].success_significant());
  EXPECT_EQ(c[0].goal_pairs, 5);
  ASSERT_TRUE(c[0].goal_difference_m);
  EXPECT_NEAR(*c[0].goal_difference_m, 0.05, 1e-12);
  // Every difference is 0.05: the interval is that point, and excludes 0.
  EXPECT_NEAR(c[0].goal_difference_interval_m->lo, 0.05, 1e-12);
  EXPECT_NEAR(c[0].goal_difference_interval_m->hi, 0.05, 1e-12);
  EXPECT_TRUE(c[0].goal_significant());

  const std::string md = comparisonsMarkdown(c);
  EXPECT_NE(md.find("| Proposed | AP     |    11 |"), std::string::npos) << md;
  EXPECT_NE(md.find("**goal error**"), std::string::npos) << md;
  const std::string csv = comparisonsCsv(c);
  EXPECT_NE(csv.find("\nProposed,AP,11,6,1,0.125,0,5,"), std::string::npos) << csv;

  // Four goal pairs: an interval, but too few to call the difference significant.
  rows.erase(rows.begin() + 12 + 6 + 4);  // AP's scene b seed 5
  c = pairedComparisons(rows, groupTrials(rows));
  EXPECT_EQ(c[0].goal_pairs, 4);
  EXPECT_TRUE(c[0].goal_difference_interval_m);
  EXPECT_FALSE(c[0].goal_significant());
  EXPECT_EQ(formatP(0.03125), "0.0312");  // printf rounds the exact tie to even
  EXPECT_EQ(formatP(0.0004), "< 0.001");
  EXPECT_NE(comparisonsMarkdown({}).find("No two planners were flown on the same scene and seed."), std::string::npos);
}

}  // namespace
}  // namespace tgnav::harness
