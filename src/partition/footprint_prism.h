// A building's footprint as a hard bound of its solid (issue 27, README "City scale"; DESIGN.md §4 "From a
// tile to a city"): the solid stays inside the vertical prism over the footprint, so neighbours that share a
// wall stay separate solids that do not overlap (roofer's rule: the footprint's edges are walls of the
// partition and cells outside it are outside).
//
// Two steps around the partition (pipeline.cpp, building mode with PipelineParams::footprint):
//   1. footprint_wall_polygons(): one vertical rectangle per footprint edge, reaching above and below the
//      partition box; the partition inserts them after its partitioner (PartitionInput::cuts, bsp-style: each
//      splits every cell its interior crosses). Afterwards no cell's interior meets the prism's boundary
//      (every rectangle is covered by facets), so every cell lies wholly inside or wholly outside the prism.
//   2. keep_cells_in_prism(): the cells outside are removed from the complex; their facets with kept cells
//      border the outside (cell -1), like the box's sides. The extraction then cannot put them inside: the
//      solid is bounded by the prism, exactly (the test is exact on the complex's rational vertices).
// The walls' facets are vertical data planes for the extraction (wall faces, the building energy's wall
// weight); their plane ids start after the structure's and the recovered planes' (the caller's first_id).
#pragma once

#include "partition/cell_complex.h"

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

/// One vertical rectangle per edge of every ring (zero-length edges skipped), from z_lo to z_hi, on the
/// plane through the edge (normal horizontal; edges on one line, within 1e-9 of the footprint's extent, share
/// the first one's plane exactly), level 1, speed 1, plane ids first_id, first_id + 1, ...
std::vector<ConvexPolygon> footprint_wall_polygons(const Footprint& footprint, double z_lo, double z_hi, int first_id);

/// The complex without the cells whose interior lies outside the footprint's prism (decided exactly at the
/// average of each cell's vertices, an interior point of the convex cell); a facet between a kept and a
/// removed cell borders the outside (-1), facets between removed cells are dropped. Vertices, planes and
/// the box are kept. Valid as the extraction's input; not a partition of the box any more (validate() no
/// longer applies). `removed` (optional) receives the number of cells removed.
CellComplex keep_cells_in_prism(const CellComplex& complex, const Footprint& footprint, std::size_t* removed = nullptr);

}  // namespace hsr
