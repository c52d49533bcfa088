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

/// The spacing of points spread over a surface, seen in plan: sqrt(the area of their convex hull in plan / their
/// count), 1 / sqrt(density); 0 for fewer than 3 points or no area. Why: a roof's rows lie this far apart on
/// average, where average_spacing's six neighbours reach across a small scan (Vaihingen_00026 at half density:
/// 9 points, r = 1.55 m, this 0.62 m).
double plan_spacing(const std::vector<Vec2>& xy);

/// How far a surface's true edge lies beyond its outermost sample, in a scan of spacing `spacing` in plan
/// (plan_spacing): `factor` spacings (0 when `factor` or `spacing` is not positive; RecoveryParams::
/// wall_beyond_points, BuildingParams::outline_prism_beyond_hull, DECISIONS #219). Why: an airborne scan samples
/// a roof about a spacing apart, and the roof's edge falls anywhere between the last sample on it and the next
/// one (off the roof), uniformly, so half a spacing beyond the outermost point on average: a wall or outline
/// through the outermost points stands that much inside the building, the more the sparser the scan. A sampling
/// bias, not a fit to anyone's model.
double edge_beyond_outermost_points(double spacing, double factor);

}  // namespace hsr
