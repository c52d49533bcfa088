// core/min_cut: known minima on tiny problems, checked against brute force, and the tie rule.
#include "core/error.h"
#include "core/min_cut.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <random>

namespace hsr {
namespace {

double brute_force_minimum(const MinCutProblem& p) {
  const std::size_t n = p.cost0.size();
  double best = std::numeric_limits<double>::infinity();
  for (std::uint32_t mask = 0; mask < (1u << n); ++mask) {
    std::vector<bool> x(n);
    for (std::size_t i = 0; i < n; ++i) x[i] = (mask >> i) & 1u;
    best = std::min(best, min_cut_energy(p, x));
  }
  return best;
}

TEST(MinCut, UnaryOnlyTakesTheCheaperLabel) {
  MinCutProblem p;
  p.cost0 = {1.0, 0.0, 0.3};
  p.cost1 = {0.0, 1.0, 0.7};
  EXPECT_EQ(min_cut_labels(p), (std::vector<bool>{true, false, false}));
}

TEST(MinCut, PottsEdgePullsAWeakNodeAlong) {
  MinCutProblem p;
  p.cost0 = {5.0, 0.4};  // node 0 wants 1 strongly, node 1 wants 0 weakly
  p.cost1 = {0.0, 0.6};
  p.edges.push_back({0, 1, 1.0, 1.0});
  EXPECT_EQ(min_cut_labels(p), (std::vector<bool>{true, true}));
  p.edges[0] = {0, 1, 0.1, 0.1};  // a weak edge does not
  EXPECT_EQ(min_cut_labels(p), (std::vector<bool>{true, false}));
}

TEST(MinCut, DirectedEdgeForbidsOnlyOneOrder) {
  // cap_ab: "a = 1, b = 0" costs 10; "a = 0, b = 1" is free.
  MinCutProblem p;
  p.cost0 = {1.0, 0.0};
  p.cost1 = {0.0, 0.5};  // a wants 1, b wants 0 (weakly)
  p.edges.push_back({0, 1, 10.0, 0.0});
  EXPECT_EQ(min_cut_labels(p), (std::vector<bool>{true, true}));
  p.cost0 = {0.0, 1.0};  // a wants 0, b wants 1: the free order
  p.cost1 = {0.5, 0.0};
  EXPECT_EQ(min_cut_labels(p), (std::vector<bool>{false, true}));
}

TEST(MinCut, TiesGoToLabelZero) {
  MinCutProblem p;
  p.cost0 = {0.5, 0.5};
  p.cost1 = {0.5, 0.5};
  p.edges.push_back({0, 1, 1.0, 1.0});
  EXPECT_EQ(min_cut_labels(p), (std::vector<bool>{false, false}));
}

TEST(MinCut, ResidualToleranceDecidesNearTies) {
  MinCutProblem p;
  p.cost0 = {1e-13};  // label 1 is better by 1e-13
  p.cost1 = {0.0};
  EXPECT_EQ(min_cut_labels(p), (std::vector<bool>{true}));
  p.residual_tolerance = 1e-12;  // within the tolerance: a tie, sent to label 0
  EXPECT_EQ(min_cut_labels(p), (std::vector<bool>{false}));
}

TEST(MinCut, MatchesBruteForceOnRandomSubmodularProblems) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    MinCutProblem p;
    const int n = 2 + trial % 8;
    for (int i = 0; i < n; ++i) {
      p.cost0.push_back(u(rng));
      p.cost1.push_back(u(rng));
    }
    for (int k = 0; k < 2 * n; ++k) {
      const int a = static_cast<int>(rng() % n), b = static_cast<int>(rng() % n);
      if (a == b) continue;
      p.edges.push_back({a, b, u(rng), u(rng) < 0.5 ? 0.0 : u(rng)});
    }
    const std::vector<bool> x = min_cut_labels(p);
    EXPECT_NEAR(min_cut_energy(p, x), brute_force_minimum(p), 1e-9) << "trial " << trial;
  }
}

TEST(MinCut, RejectsNegativeCapacities) {
  MinCutProblem p;
  p.cost0 = {0.0, 0.0};
  p.cost1 = {0.0, 0.0};
  p.edges.push_back({0, 1, -1.0, 0.0});
  EXPECT_THROW(min_cut_labels(p), Error);
  p.edges[0] = {0, 2, 1.0, 1.0};
  EXPECT_THROW(min_cut_labels(p), Error);
}

}  // namespace
}  // namespace hsr
