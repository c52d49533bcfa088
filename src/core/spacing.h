// Average point spacing r: the scale every distance parameter of hsr is relative to (DESIGN.md "Scale").
#pragma once

#include "core/kd_tree.h"
#include "core/types.h"

namespace hsr {

/// Mean distance from each point to its k nearest neighbours (k = 6 by default), averaged over all
/// points (or over an evenly strided subset of at most `max_samples` points, for speed; deterministic).
/// Returns 0 for fewer than 2 points.
double average_spacing(const std::vector<Vec3>& points, int k = 6, std::size_t max_samples = 20000);

/// The same on a kd-tree already built over `points` (the caller's; not rebuilt).
double average_spacing(const std::vector<Vec3>& points, const KdTree& tree, int k = 6,
                       std::size_t max_samples = 20000);

/// The same from a kNN graph's rows (`rows`: each point's `row_k` nearest other points, nearest first, as
/// KdTree::neighbour_rows gives them; row_k at least min(k, points - 1)): the distances of the same
/// neighbours summed in the same order, so the same value to the last bit, without a query. Why: the
/// detection builds that graph anyway, and the spacing's own queries were 2 % of a city's CPU.
double average_spacing_of_rows(const std::vector<Vec3>& points, const std::vector<int>& rows, int row_k, int k = 6,
                               std::size_t max_samples = 20000);

}  // namespace hsr
