// The points a tile is planned with (issue 40 items 1 and 2; src/city/survey.h; DECISIONS #96): its own and,
// in a survey of several tiles, its neighbours' within the tile margin; of those, when the file says its
// ground (class 2) and building (class 6) points, only the points the plan reads.
//
// A tile is streamed (io.h read_point_chunks), not held: a first pass counts its points by class, takes their
// bounding box (the local origin read_points would choose) and, without footprints, the plan cells holding a
// building point; a second pass keeps, per point, its local position and class only, and of a classified
// region only the building points and the ground points near a building (KeepMask: each footprint's box, or
// each building point's cell, grown by the first ground ring and a slack). Everything else is counted
// (SurveyRegion::left_out) and dropped as it streams. A building whose ground ring had to widen past what was
// kept gets its wider surroundings in one more pass. The plan (src/city/city.h) reads exactly the points and
// does exactly the arithmetic it did on the whole tile: the same buildings, points, ground heights and bytes.
// Without both classes in the file (or --classes filter) every point is kept (SMRF and the building rule read
// them all), with its class and return count only.
#pragma once

#include "city/city.h"
#include "city/survey.h"
#include "core/footprint.h"
#include "core/types.h"
#include "io/io.h"

#include <cstdint>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

namespace hsr::city {

/// Every tile's extent in file coordinates (io.h read_extent: a LAS/LAZ/COPC header; other formats read
/// whole), in the given order.
std::vector<BBox> survey_extents(const std::vector<std::string>& tiles);

/// Plan cells (file coordinates) whose ground and building points a plan reads.
class KeepMask {
 public:
  /// A mask over `area` (file coordinates) in square cells of `cell` file units; nothing marked.
  KeepMask(const BBox& area, double cell);
  /// Marks every cell meeting the rectangle [x0, x1] x [y0, y1] (clipped to the area).
  void mark(double x0, double y0, double x1, double y1);
  /// Marks every cell holding a point inside `footprint` or within `reach` (file units) of its rings: the cells
  /// whose centre lies inside or within reach + half a cell's diagonal. Why not its box grown by reach: a
  /// footprint turned from the axes leaves twice the ground of its ring in the corners of its box.
  void mark_near(const Footprint& footprint, double reach);
  /// Marks every cell within `reach` (file units, per axis) of a cell of `cells` (KeepMask::key of each).
  void mark_around(const std::unordered_set<std::uint64_t>& cells, double reach);
  bool contains(double x, double y) const;
  /// The part cell (RegionReader::kPartCells mask cells a side, anchored at 0) holding the mask cell of (x, y):
  /// the census records which part cells a part of a file has points in.
  static std::uint64_t part_key(double x, double y);
  /// The part cells (part_key) holding at least one marked cell: a part of a file none of whose points lies in
  /// one of them holds no point contains() keeps. Only for masks of RegionReader::kCell cells.
  std::unordered_set<std::uint64_t> marked_part_cells() const;
  /// The key of the cell holding (x, y) in a grid of `cell` units anchored at 0 (any position).
  static std::uint64_t key(double x, double y, double cell);

 private:
  double cell_;
  std::int64_t i0_ = 0, j0_ = 0, nx_ = 0, ny_ = 0;
  std::vector<char> marked_;
};

/// What a run over the tiles of a survey remembers of each file it decoded whole (issue 40 item 1: "indexes their
/// extents (headers; LAZ chunks ... where that saves reading)"; DECISIONS #142): its points' bounding box, its CRS
/// and, per part of the file (io.h point_parts: a LAZ chunk, COPC node, 65,536 LAS records), the part cells
/// (KeepMask::part_key, 25 m) holding any of its points. A LAS header gives the file's extent only, so a
/// neighbour's census (RegionReader pass 1) decoded the whole neighbour to count the points of a 50 m margin:
/// an inner tile of a survey decoded its eight neighbours whole, each file up to nine times in a run. With the
/// index, a file decoded once is read again only in the parts with a point in a cell meeting the margin.
/// Held by run_city for the run; a file's entry is dropped once no tile still to be planned reads it.
class SurveyIndex {
 public:
  struct File {
    BBox box;          ///< file coordinates: the bounding box of every point of the file
    std::string crs;   ///< the file's CRS (PointCloud::crs)
    /// Per part (point_parts order), the part cells of all its points (any class), sorted, unique.
    std::vector<std::vector<std::uint64_t>> cells;
  };
  /// The file of tile `tile` (index into the run's tiles) when it was decoded whole, else null.
  const File* find(int tile) const;
  void remember(int tile, File file);
  /// The survey's tile extents and the margin (file units) each tile is planned with (RegionReader::add_neighbours).
  void set_survey(const std::vector<BBox>& extents, double margin);
  /// Drops the files no tile after `planned` (in the run's order) reads: neither that tile's own file nor a
  /// neighbour's whose extent meets its extent grown by the margin. Why: the index is per file of the survey, and
  /// memory must not grow with the survey (about 150 KB a 20 M-point file).
  void forget_after(int planned);
  std::size_t files() const { return files_.size(); }  ///< files held
  std::size_t bytes() const;                           ///< of the cells held, about

 private:
  std::unordered_map<int, File> files_;
  std::vector<BBox> extents_;
  double margin_ = 0;
};

/// Whether part cell `key` (KeepMask::part_key: RegionReader::kPartCells mask cells a side, anchored at 0, its
/// west and south sides closed, east and north open) meets the closed plan rectangle `rect` (file coordinates):
/// false only when no position of the cell can lie in the rectangle.
bool part_cell_meets(std::uint64_t key, const BBox& rect);

/// The first mask of a classified region's plan (RegionReader::read): with footprints, the cells within
/// max(ring_outer, buffer) + kSlack of each footprint the tile plans (RegionReader::plans) and of no other: in
/// a survey, a neighbour's footprint in the margin is planned by the neighbour, so its points are not read
/// (DECISIONS #103; they were 10-21 % more points than the tile's own). Without footprints, the cells within
/// that + 2 component cells of every building point's cell of the region (a group's owner is known only once
/// its cells are joined).
class RegionReader;
KeepMask first_keep_mask(const RegionReader& reader, const std::vector<FootprintFeature>* footprints, const CityParams& params);

/// Reads the cloud a tile is planned with: its own points, then (a survey) every neighbour's within the
/// margin, as DECISIONS #91 reads them, streamed (see the header comment).
class RegionReader {
 public:
  /// Plan cells of the census and of the mask (KeepMask::key), file units: a mask reaches at most a cell
  /// past what it must hold.
  static constexpr double kCell = 1.0;
  /// The mask is tested on file positions, the plan measures on local ones (shifted by the origin): a slack of
  /// a hundredth of a file unit covers their rounding (about 1e-10 units) many times over. File units.
  static constexpr double kSlack = 0.01;

  /// Side of the census's count cells (class 2 and 6 points per cell), file units: a block's read reserves
  /// the points of the cells its window meets, not the tile's (DECISIONS #124).
  static constexpr double kCountCell = 50.0;

  /// Side of the cells the census knows each part of a file by (io.h point_parts: a LAZ chunk, 65,536 LAS
  /// records), in mask cells (kCell): per part, the cells holding its class 2 and 6 points. A read with a mask
  /// decodes only the parts with a point in a cell holding a marked mask cell; the others hold no point it
  /// keeps (DECISIONS #133). Coarser: fewer cells to keep per part, more parts read for nothing. 25 cells
  /// (25 m): a part of a LAZ file's 50,000 points along a scan line 2 km long keeps about 160 cells.
  static constexpr int kPartCells = 25;
  /// The tile `tiles[self]` (a survey when tiles.size() > 1); its own points are counted now (pass 1).
  /// `group_cells`: the census keeps the cells holding a building point (building_cells(); only a plan without
  /// footprints reads them: on a large tile they are many).
  /// `index` (a run over a survey; null: none): the files decoded whole are remembered there, and a neighbour it
  /// knows is decoded only in the parts with a point in a cell meeting the margin (SurveyIndex, DECISIONS #142).
  RegionReader(const std::vector<std::string>& tiles, int self, bool group_cells = true, SurveyIndex* index = nullptr);
  const std::string& crs() const { return crs_; }  ///< the tile's CRS (PointCloud::crs)
  const std::string& source() const { return tiles_[static_cast<std::size_t>(self_)]; }
  /// A survey: counts the neighbours' points within `margin` (file units) of the tile's extent (pass 1);
  /// fills the region's extents, self and loaded rectangle. Call once, before read(); nothing for one tile.
  void add_neighbours(double margin);
  /// True when the region's file classes give its ground and building points (both classes present and
  /// `classes` not Filter): then the plan reads no other point, and read() may leave points out.
  bool classified(ClassSource classes) const;
  /// The rectangle (file coordinates) every point of the region lies in; a block's: its part of the window.
  BBox area() const;
  /// Whether the tile's plan plans this footprint (file coordinates): city.h tile_plans_footprint in the frame
  /// read() gives the plan (its origin, its own points' box, the survey's extents). After add_neighbours.
  bool plans(const Footprint& footprint) const;
  /// A rectangle (file coordinates) that the plan box of every footprint the plan reads meets: those it plans
  /// (their centre on the tile, within SurveyRegion::edge_tolerance of its extent) and those holding a point
  /// of the region (city.h step 2: a point inside another footprint is not taken by the buffer). A footprint
  /// whose box misses it changes nothing in the plan but the count of footprints off the tile.
  BBox footprint_reach() const;
  /// Cells (KeepMask::key at kCell) holding a building point of the region (class 6); empty without group_cells.
  const std::unordered_set<std::uint64_t>& building_cells() const { return building_cells_; }
  /// File coordinates: the bounding box of the tile's own points; read()'s local origin.
  const BBox& own_box() const { return own_box_; }
  const Vec3& origin() const { return sources_.front().origin; }
  std::size_t own_building_points() const { return own_building_; }  ///< the tile's own points of class 6

  /// Plans block `block` of `blocks` only (DECISIONS #124; -1: the whole tile again): plans(), area(),
  /// footprint_reach() and read() then see the block's buildings and the points within `window` (file
  /// coordinates: every point the block's plan reads lies in it), the others counted as left out.
  void set_block(const TileBlocks& blocks, int block, const BBox& window);

  /// The parts of the region's files that read() decoded and that it had, over every read() so far (a
  /// block's: its own), for the log and the tests.
  std::size_t parts_read() const { return parts_read_; }
  std::size_t parts_total() const { return parts_total_; }
  /// The parts of the region's files the census (pass 1: the tile's and its neighbours') decoded, and that they
  /// had (DECISIONS #142: a neighbour the SurveyIndex knows is decoded only where it meets the margin).
  std::size_t census_parts_read() const { return census_parts_read_; }
  std::size_t census_parts_total() const { return census_parts_total_; }
  /// The points the census decoded (every point of every part it decoded), for the log and the benchmark.
  std::size_t census_points_decoded() const { return census_points_decoded_; }
  /// true: read() decodes every part, not only those a mask may keep a point of (the same cloud; for tests).
  void set_every_part(bool every) { every_part_ = every; }

  /// Pass 2: the cloud, in the tile's local coordinates (read_points' origin), with its classes (and return
  /// counts when `keep` is null); `keep` non-null: of class 2 and 6 only the points in it, of the others none,
  /// the rest counted in region.left_out. Fills `region` (survey.h). `own_building`: receives, per point of
  /// the cloud, its rank among the tile's own class 6 points in file order (kNotOwnBuilding for the others), so
  /// that the blocks of a tile count the building points no building took once (DECISIONS #124).
  static constexpr std::uint32_t kNotOwnBuilding = 0xFFFFFFFFu;
  PointCloud read(const KeepMask* keep, SurveyRegion& region, std::vector<std::uint32_t>* own_building = nullptr) const;

 private:
  /// What the census saw of one part of a file (of its points in the region only).
  struct PartCensus {
    std::size_t ground = 0, building = 0, other = 0;  ///< points of class 2, 6 and any other
    std::vector<std::uint64_t> cells;                 ///< KeepMask::part_key of its class 2 and 6 points, sorted
  };
  struct Source {
    int tile = 0;
    Vec3 origin = Vec3::Zero();  ///< read_points' local origin of the tile
    std::size_t points = 0, ground = 0, building = 0;  ///< its points in the region: all, class 2, class 6
    std::vector<PointPart> parts;                      ///< io.h point_parts of its file
    std::vector<PartCensus> census;                    ///< per part
  };
  /// Per part of `src`: whether a point of it may lie in a marked cell (one of its part cells is in `marked`,
  /// KeepMask::marked_part_cells). Why per part and not per point: a part not wanted is not decoded at all.
  static std::vector<char> wanted_parts(const Source& src, const std::unordered_set<std::uint64_t>& marked);
  /// The class 2 and 6 points of the region in the count cells meeting `window` (at least those inside it).
  std::size_t class_points_in(const BBox& window) const;
  /// Pass 1 over tile t: its bounding box and origin; of its points in the region, the classes and cells.
  void count_tile(int t);

  std::vector<std::string> tiles_;
  int self_ = 0;
  std::string crs_;
  std::vector<BBox> extents_;     ///< a survey: every tile's header extent
  BBox loaded_;                   ///< a survey: the tile's extent grown by the margin
  BBox own_box_, area_;           ///< file coordinates: the tile's own points; every point of the region
  std::vector<Source> sources_;   ///< the tile, then the neighbours read, in order
  std::size_t region_points_ = 0;           ///< points of the region (the tile's and its neighbours' taken)
  std::size_t ground_ = 0, building_ = 0;  ///< points of class 2 / 6 in the region
  std::size_t own_building_ = 0;           ///< the tile's own points of class 6
  bool exact_ = true;  ///< every tile's shift to its origin is exact (file position = local + origin)
  bool group_cells_ = true;
  std::unordered_set<std::uint64_t> building_cells_;
  std::unordered_map<std::uint64_t, std::size_t> class_counts_;  ///< class 2 and 6 points of the region per kCountCell cell
  TileBlocks blocks_;
  mutable std::size_t parts_read_ = 0, parts_total_ = 0;
  std::size_t census_parts_read_ = 0, census_parts_total_ = 0, census_points_decoded_ = 0;
  SurveyIndex* index_ = nullptr;
  bool every_part_ = false;
  int block_ = -1;
  BBox window_;  ///< a block's: the points it reads
};

}  // namespace hsr::city
