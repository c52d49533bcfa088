// A building's footprint in plan, as plain data (issue 27, README "City scale"; DESIGN.md §4 "From a tile to a
// city"; DECISIONS #45): the polygons `hsr city`, the synthetic city, the pipeline and the CLI pass around, and
// the plain tests on them. The partition's prism over a footprint (its walls, the cells inside) is
// partition/footprint_prism.h.
#pragma once

#include "core/types.h"

#include <cstddef>
#include <vector>

namespace hsr {

/// One polygon of a footprint in plan: its outer ring and its holes (each ring >= 3 vertices, not repeating
/// the first at the end, either orientation; x, y in the cloud's local frame).
struct FootprintPolygon {
  std::vector<Vec2> outer;
  std::vector<std::vector<Vec2>> holes;
};
/// A footprint: one or more polygons (a multipolygon) that do not overlap. Empty: no footprint.
using Footprint = std::vector<FootprintPolygon>;

/// True when (x, y) is inside the footprint: even-odd over every ring of every polygon (inside an outer ring
/// and not inside one of its holes, for polygons that do not overlap). T is double or Rational (exact: the
/// rings' doubles are exact rationals); a point on a ring may go either way.
template <class T>
bool inside_footprint(const T& x, const T& y, const Footprint& footprint) {
  bool inside = false;
  auto cross_ring = [&](const std::vector<Vec2>& ring) {
    const std::size_t n = ring.size();
    for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
      const T xi(ring[i].x()), yi(ring[i].y()), xj(ring[j].x()), yj(ring[j].y());
      if ((yi > y) == (yj > y)) continue;
      // x of the edge at height y, compared without dividing: (x - xi)(yj - yi) < (xj - xi)(y - yi), sign-aware.
      const T lhs = (x - xi) * (yj - yi), rhs = (xj - xi) * (y - yi);
      if ((yj > yi) ? lhs < rhs : lhs > rhs) inside = !inside;
    }
  };
  for (const FootprintPolygon& p : footprint) {
    cross_ring(p.outer);
    for (const auto& h : p.holes) cross_ring(h);
  }
  return inside;
}

/// Twice the signed area of a ring (shoelace): positive counter-clockwise.
double twice_ring_area(const std::vector<Vec2>& ring);

/// Throws Error(BadInput, "partition") for a ring with fewer than 3 vertices, a non-finite coordinate, or a
/// ring without area.
void check_footprint(const Footprint& footprint);

}  // namespace hsr
