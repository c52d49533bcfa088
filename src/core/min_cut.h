// Exact minimisation of a binary submodular energy by one s-t minimum cut (Boost's Boykov–Kolmogorov
// max-flow). The one graph-cut set-up of the project: the visibility stage's MRF (paper §3.2) and the
// extraction's inside/outside labelling (§3.6) both call it.
//
// Energy over labels x_i in {0, 1}:
//   E(x) = Σ_i (x_i ? cost1[i] : cost0[i]) + Σ_edges (x_a = 1 and x_b = 0 ? cap_ab : 0)
//                                           + Σ_edges (x_a = 0 and x_b = 1 ? cap_ba : 0)
// with every cost and capacity >= 0 (finite). A symmetric Potts term w [x_a != x_b] is an edge with
// cap_ab = cap_ba = w; a directed edge (cap_ba = 0) only forbids "a = 1, b = 0" (e.g. "above inside,
// below outside"). Such an energy is submodular, so the cut is an exact minimum.
// Ties: the returned minimiser labels 1 the nodes reachable from the source in the residual graph through
// residual capacities above `residual_tolerance` (0: any positive residual, BK's own source tree; a
// tolerance sends ties within it, and rounding noise, to label 0). Deterministic.
#pragma once

#include <vector>

namespace hsr {

struct MinCutProblem {
  std::vector<double> cost0;  ///< per node: cost of label 0 (>= 0)
  std::vector<double> cost1;  ///< per node: cost of label 1 (>= 0), same size as cost0
  struct Edge {
    int a = -1, b = -1;
    double cap_ab = 0.0;  ///< paid when x_a = 1 and x_b = 0
    double cap_ba = 0.0;  ///< paid when x_a = 0 and x_b = 1
  };
  std::vector<Edge> edges;
  /// Residual capacity counted as saturated when at most this (absolute, same unit as the costs).
  double residual_tolerance = 0.0;
};

/// The labels (true = 1) of a minimiser of E. Throws hsr::Error(Internal) on a negative or non-finite
/// cost or capacity, or an edge naming a node out of range.
std::vector<bool> min_cut_labels(const MinCutProblem& problem);

/// E(x) of the given labels (for tests and reports).
double min_cut_energy(const MinCutProblem& problem, const std::vector<bool>& labels);

}  // namespace hsr
