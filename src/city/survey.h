// Tiles of one survey (issue 40 item 1; DESIGN.md §4 "From a tile to a city"). Surveys are published in tiles
// cut along a grid, through buildings. `hsr city` plans each tile with its neighbours' points within
// `tile_margin` around it (src/driver/city_survey.cpp reads them), so that a building on an edge gets all its
// points and its ground ring, and each building is planned by exactly one tile: the one that owns the centre
// of its footprint's (or its group's) bounding box (owning_tile).
#pragma once

#include "city/footprints.h"
#include "core/types.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace hsr {

/// Points of the planned region that the cloud lacks: `hsr city` streams a tile whose file says its ground
/// (class 2) and building (class 6) points and keeps only the points the plan reads (src/driver/city_survey.h);
/// the stage counts these as if they were in the cloud. Only for ClassSource Auto/File and a region with
/// points of both classes (then split_classes reads no other point).
struct PointsLeftOut {
  bool ground_class = false, building_class = false;  ///< the region has points of class 2 / 6, kept or not
  std::size_t ground = 0, building = 0, other = 0;    ///< points left out, by class: 2, 6, any other
  std::size_t own_building = 0;  ///< of `building`, the tile's own (they lie in no building: unused)
  /// Local coordinates: the bounding box of all the tile's own points, kept or not (a tile on its own: the
  /// footprints whose centre lies in it are its own); empty (not valid): the cloud's.
  BBox extent;
  bool any() const { return ground + building + other > 0; }
};

/// A tile cut into blocks planned one after the other (virtual tiles; issue 40 item 2, DECISIONS #124): a grid of
/// nx x ny equal rectangles over the tile's own points' bounding box (file coordinates). A block plans the
/// buildings whose centre it owns (of()), so that one large file is planned in the memory of about one block's
/// kept points, and every building once, with the same points and bytes as the whole tile's plan.
struct TileBlocks {
  double x0 = 0, y0 = 0;           ///< south-west corner, file units
  double width = 0, height = 0;    ///< of one block, file units
  int nx = 1, ny = 1;
  /// A grid of blocks of about `block` file units a side over `box` (a side's blocks: its length over `block`,
  /// rounded, at least 1): a tile of 1.4 blocks stays one, so that a standard tile is not cut into slivers.
  static TileBlocks over(const BBox& box, double block);
  int count() const { return nx * ny; }
  /// The block owning plan position p (file coordinates): the one whose rectangle holds it, clamped to the
  /// grid (positions off the grid go to the nearest block); a block's west and south sides are its own.
  int of(const Vec2& p) const;
};

/// Where the cloud run_city_tile plans lies in a survey of several tiles. The default (no extents) is a tile
/// on its own: every footprint whose centre lies in the cloud's bounding box and every group are its own.
struct SurveyRegion {
  /// Every tile's extent in file coordinates (the LAS header's bounds), in the order the tiles were given.
  std::vector<BBox> extents;
  int self = -1;  ///< the planned tile's index into `extents`
  /// File coordinates: the plan rectangle whose points the cloud holds (the tile's extent grown by the margin).
  BBox loaded;
  /// The cloud's first `own_points` points are the tile's own (the rest its neighbours' within the margin).
  std::size_t own_points = 0;
  /// Tiles whose extents are this far apart still meet (the gap a grid of tiles leaves between the last
  /// point of one and the first of the next: about a point spacing), file units.
  double edge_tolerance = 1.0;
  /// What the reader left out of the cloud (a tile on its own too).
  PointsLeftOut left_out;
  /// A tile planned block by block (DECISIONS #124): the plan plans only the buildings whose centre block
  /// `block` of `blocks` owns (TileBlocks::of), besides the rules above; -1: the whole tile.
  TileBlocks blocks;
  int block = -1;

  bool several() const { return extents.size() > 1 && self >= 0; }
};

/// The tile that owns plan position p (file coordinates): of the tiles whose extent, grown by
/// `edge_tolerance`, holds p, the one whose extent is nearest to p (0 inside), the first of them on a tie;
/// -1 when none holds it. Why: neighbouring tiles' extents leave a gap of about a point spacing or overlap
/// a little; every tile must give the same answer for the same footprint, so that it is planned once.
int owning_tile(const Vec2& p, const std::vector<BBox>& extents, double edge_tolerance);

/// The tiles (indices, ascending, `self` excluded) whose extents meet the rectangle `box` (plan only).
std::vector<int> tiles_meeting(const BBox& box, const std::vector<BBox>& extents, int self);

/// True when the plan side `side` (0 west, 1 east, 2 south, 3 north) of `loaded` has survey beyond it: a
/// strip of width `strip` outside it meets some tile's extent. A group that reaches such a side may go on
/// past the points loaded.
bool survey_beyond(const BBox& loaded, int side, double strip, const std::vector<BBox>& extents);

/// A survey's footprints read once and indexed by their plan bounding boxes on a grid (issue 40 item 2;
/// DECISIONS #103): a run over many tiles reads the footprint file once, not once per tile, and each tile's plan
/// gets only the footprints near it, so that what a plan builds from its footprints (their local copies, their
/// index) grows with the tile, not with the survey. Held for the whole run: under 1 KB a footprint (rings, id,
/// fields; the synthetic survey's: 9 vertices, 5 fields), so it grows with the survey's footprints, not its points.
class FootprintGrid {
 public:
  /// Side of a grid cell, file units: a 1 km tile and its margin meet about 150 cells of 100 m, and a building
  /// (tens of metres) one to four.
  static constexpr double kCell = 100.0;

  explicit FootprintGrid(FootprintSet set);
  const FootprintSet& set() const { return set_; }
  /// The indices (ascending: file order) of the features whose plan bounding box meets the rectangle `rect`
  /// (file coordinates, plan only; closed).
  std::vector<std::size_t> meeting(const BBox& rect) const;

 private:
  FootprintSet set_;
  std::vector<BBox> boxes_;  ///< each feature's plan bounding box (invalid: no point)
  std::int64_t i0_ = 0, j0_ = 0, nx_ = 0, ny_ = 0;
  std::vector<std::vector<std::uint32_t>> cells_;  ///< per cell, the features whose box meets it, ascending
};

}  // namespace hsr
