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
// footprint_wall_points() gives them the facade points no data plane holds (the extraction's votes).
// The footprint itself (its types, inside_footprint, check_footprint) is plain data: core/footprint.h.
#pragma once

#include "core/footprint.h"
#include "partition/cell_complex.h"

#include <vector>

namespace hsr {

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

/// Which walls stand for a footprint edge (issue 43 item 4: the plan on the footprint where one is given).
/// Polygon i is such a wall when it is vertical (normal z 0: building mode makes walls exactly vertical) and
/// for one edge of the footprint (any ring): its normal is within `max_angle_deg` of the edge's, each of its
/// vertices lies within `max_offset` of the edge's line and projects onto the edge grown by `max_offset`,
/// and fewer than `min_points` of `points` (the building's points above the ground, plan x y) lie in the strip
/// between the wall and the edge farther than `band` from the wall. Why: without a roof between them, the wall is the
/// scan's estimate of the edge the footprint gives exactly (the outermost points stop a little inside it, a
/// cadastre and a scan differ by decimetres); kept, it cuts a strip off the footprint. With a roof part
/// between them (a lower annex), it is the step between two roofs and stays. Lengths in the points' units.
std::vector<bool> walls_standing_for_footprint(const std::vector<ConvexPolygon>& polygons, const Footprint& footprint,
                                               const std::vector<Vec2>& points, double max_offset,
                                               double max_angle_deg, double band, std::size_t min_points);

/// The points that vote for a footprint edge's wall in the extraction (BuildingParams::footprint_wall_points,
/// DECISIONS #170): a point whose plane has no facet in the partition (`point_plane[i]` < 0, or an id that is not
/// true in `in_complex`: on no plane, or on a wall that gave way to the footprint), more than `distance` above
/// `ground_z` and within `distance` of a footprint edge in plan (its projection strictly inside the edge), gets
/// the nearest such edge's wall: `point_plane[i]` its id (footprint_wall_polygons' ids from `first_id`, in its
/// order) and `normals[i]` the edge's outward side in plan. Returns how many points were given to a wall. Why:
/// the min-cut weighs data planes' points only; a facade on the footprint that no plane holds had no say, and
/// the plan left the footprint there. Lengths in the points' units.
std::size_t footprint_wall_points(const std::vector<Vec3>& points, const Footprint& footprint, int first_id,
                                  const std::vector<bool>& in_complex, double distance, double ground_z,
                                  std::vector<int>& point_plane, std::vector<Vec3>& normals);

}  // namespace hsr
