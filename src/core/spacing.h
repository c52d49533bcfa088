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

}  // namespace hsr
