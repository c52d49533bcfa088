// The LoDs and attributes of one `hsr city` feature (issue 40 item 3; docs/guide/batch-and-city.md "LoDs and
// attributes"; DECISIONS "Each feature carries LoD 1.2, 1.3 and 2.2").
//
// Input: the building's LoD 2.2 solid as the child wrote it (building mode: vertical walls, a horizontal
// bottom, roofs over the plan) and the building's points. Everything is read off that solid, so the three
// LoDs stand on the same plan and the same ground:
// - the plan: the LoD 2.2 GroundSurface faces (the footprint, or the group's outline, as modelled);
// - roof heights: the topmost LoD 2.2 roof face over each cell of a plan grid (`height_cell`), the cells
//   inside the plan; min, 50th, 70th percentile and max of those heights (3DBAG: on the LoD 2.2 model);
// - LoD 1.2: the plan extruded from the ground to the 70th percentile;
// - LoD 1.3: the LoD 2.2 roof split into parts, each a connected roof surface (roof faces sharing an edge),
//   parts whose levels differ by less than `lod13_min_step` joined; each part's plan (its roof faces'
//   projections) extruded to its own 70th percentile, vertical walls between parts of different levels.
//   Where the roof faces' projections do not tile the plan exactly (a solid that is not 2.5D), or the
//   stepped solid is not valid, LoD 1.3 is the LoD 1.2 block (hsr_lod13_parts says 1, hsr_lod13_note why).
// Each solid is checked with eval's check_validity (the project's exact check); volumes and RMSEs are in the
// tile's units (metres for a metric CRS). Roof surfaces: slope and azimuth from the face's normal, area.
#pragma once

#include "core/footprint.h"
#include "core/types.h"
#include "io/cityjson.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace hsr {

struct LodParams {
  /// The LoDs written per feature (`--lod`, parse_lod_list): "1.2", "1.3", "2.2" in that order of choice.
  bool lod12 = true, lod13 = true, lod22 = true;
  /// The sequence's integer step (CityJsonParams::scale), tile units: roof levels are rounded to it, so a
  /// level's faces stay on one plane after the writer's rounding.
  double grid = 0.001;
  /// Side of the plan cells of the roof heightmap (percentiles, LoD 1.3 levels), m (tile units after
  /// in_tile_units). 0.25 m: a 10 m² roof part holds 160 cells.
  double height_cell = 0.25;
  /// Roof level of LoD 1.2 and of each LoD 1.3 part: this percentile of the heights under it, percent
  /// (3DBAG's b3_h_dak_70p extrusion height).
  double roof_percentile = 70;
  /// b3_h_dak_min and b3_h_dak_max: these percentiles of the same heights, percent. roofer, the 3DBAG's
  /// engine whose names these are, writes the 2nd and the 99th percentile of its roof points as "min" and
  /// "max" (PlaneDetector.cpp), so that a sliver of a lower roof or a chimney of a few cells does not make
  /// them (DECISIONS #146: on the 56 AHN3 buildings the true minimum was up to 10 m below roofer's).
  double roof_min_percentile = 2;
  double roof_max_percentile = 99;
  /// LoD 1.3: neighbouring roof parts whose levels differ by less than this are one part, m. Below a
  /// storey (roofer's default is 3 m) so that an annex or a garage keeps its own level.
  double lod13_min_step = 1.0;
  /// A roof face sloping less than this is horizontal (b3_dak_type), degrees (roofer's 4).
  double horizontal_slope = 4.0;
  /// Horizontal roof faces whose mean heights differ by less than this are one level (b3_dak_type
  /// "horizontal" vs "multiple horizontal"), m.
  double same_level = 0.25;
  /// No-data share: the plan is cut into cells that hold this many points on average at the building's
  /// density; a cell inside the plan with no point is a gap, so chance (e^-4 ≈ 2 % of the cells) is small.
  double nodata_cell_points = 4.0;
  /// The model is doubtful (b3_reconstructie_onvolledig) when hsr_points_unexplained_share is above this
  /// (EvalParams::unexplained_warn_share, the run's own warning), share.
  double doubtful_unexplained_share = 0.05;
  /// Plan points this many grid steps apart or less (in x and in y) are one point, and a point this close
  /// to an edge lies on it: the writer rounds each coordinate by up to half a step, so where the LoD 2.2
  /// faces meet (a lower roof's edge along a higher roof's wall) their plan points are a step or so apart.
  std::int64_t plan_snap_steps = 2;
  /// A plan point this close to a roof or ground edge lies on it (it is put into the edge), m: where the
  /// LoD 2.2 faces of two roof levels end at two footprint corners a few cm apart, the step wall is not
  /// quite vertical; LoD 1.3 makes it so. Smaller than any wall worth keeping.
  double edge_snap = 0.05;
  /// Metres per tile unit: the lengths above (height_cell, lod13_min_step, same_level, edge_snap) are divided by it.
  double metres_per_unit = 1.0;
};

/// "1.2,1.3,2.2" (any non-empty subset, any order, no repeats) -> the flags of `params`. Throws
/// Error(BadInput, "city") naming the bad value.
void parse_lod_list(const std::string& list, LodParams& params);
/// The flags as a list, "1.2,1.3,2.2" order.
std::string lod_list(const LodParams& params);

/// One feature's LoD 1.2 and 1.3 solids (those asked for and made) and its attributes (the table in the
/// header comment of lods.cpp). `points` are the building's points in the mesh's frame (local to
/// lod22.origin); `run_attributes` the feature's attributes so far (hsr_points_unexplained_share).
struct BuildingLods {
  std::vector<CityJsonGeometry> solids;  ///< "1.2", "1.3" as asked for
  nlohmann::json attributes = nlohmann::json::object();
};
/// `footprint`: the building's footprint in the mesh's frame (x, y local to lod22.origin), empty for none (a group):
/// b3_puntdichtheid and b3_nodata_fractie are over it, as 3DBAG's are over the cadastre's polygon (roofer: its
/// footprint raster); without one, over the LoD 2.2 plan.
BuildingLods building_lods(const PolygonMesh& lod22, const std::vector<Vec3>& points, const nlohmann::json& run_attributes,
                           const LodParams& params, const Footprint& footprint = {});

/// A RoofSurface's semantic attributes: b3_hellingshoek (slope from horizontal, degrees), b3_azimut (the
/// compass bearing of its normal's plan direction, degrees clockwise from north = +y; null for an exactly
/// horizontal face), b3_opp (area, tile units²). Null for a face that is not a roof.
nlohmann::json roof_surface_attributes(const PolygonMesh& mesh, std::size_t face);

}  // namespace hsr
