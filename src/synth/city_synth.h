// A synthetic survey tile with its truth (`hsr synth city`, issue 27; README "City scale"): buildings of the
// six aerial families (synth.h) on sloping ground with trees, scanned by the airborne line scanner of the
// aerial models over the whole tile, written as a classified LAS, the same points unclassified, the
// footprints as GeoJSON (GDAL) and the truth of every building.
//
// The tile: plots on a square grid of `plot` metres (about sqrt(N) columns), building i of family i mod 6
// (aerial_flat, _gable, _hip, _shed, _dormer, _mixed) with its own seed (seed * 1000 + i), turned as its
// family draws it and centred on its plot within +-2 m. Ground: a plane rising `slope` (rise over run) in a
// seeded direction, plus a gentle undulation (0.5 m, wavelengths 90 and 130 m). Each building stands on a
// level plot, as built: the ground within plot_flat (4 m) of its footprint is at the terrain's height under
// the footprint's centre, and blends into the terrain over the next 5 m (smoothstep); that level is the
// building's true ground (the truth's bottom face). Trees (crowns 2-4 m wide, 2-7 m above the ground) stand
// at least 2 m clear of every footprint's bounding box. `terraced` of the N buildings are attached to the one
// before them instead of having a plot: a block (flat or gable roof, its own height) on the outside of that
// building's longest free footprint edge, sharing the wall (a terraced neighbour).
// Scanner: the aerial models' (synth.h): two flight lines in opposite directions, 1000 m above the ground,
// each sampling the tile at half the density on a jittered grid, off nadir up to about 17 degrees at the
// tile's edges, first hit, range noise. A ray crossing a crown returns from its foliage for 70 % of the rays
// (return 1), and half of those also from the surface behind (return 2 of 2). Classes: 2 ground, 6
// building, 5 tree (the copy without: 0, never classified). Local coordinates (the tile's local origin at
// 0); the files add `origin` (an RD New-like position) and carry the CRS.
#pragma once

#include "core/types.h"
#include "core/footprint.h"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace hsr {

struct SynthCityParams {
  int buildings = 50;          ///< N, buildings on the tile (terraced ones included)
  std::uint64_t seed = 1;
  int terraced = 0;            ///< of the N, attached to the building before them (sharing a wall)
  double density = 10.0;       ///< points per m² on horizontal surfaces
  double range_noise = 0.03;   ///< standard deviation along the ray, m
  double slope = 0.04;         ///< terrain gradient, rise over run
  int trees = -1;              ///< tree crowns; -1: one per building
  double plot = 55.0;          ///< grid spacing of the plots, m
  double plot_flat = 4.0;      ///< the plot is level this far around the footprint, m
  /// The survey is also written cut into tiles x tiles tiles of equal size over the points' plan extent
  /// (DIR/tiles/, DIR/tiles_unclassified/: rRcC.las, row R from the south, column C from the west), cut
  /// through whatever buildings the lines cross; 1: the one tile only.
  int tiles = 1;
  /// A survey (`--size`, issue 40 item 2): the side of a square survey, m; 0: the one tile of `buildings`.
  /// Plots of `plot` metres fill it from its south-west corner (floor(size / plot) per side, `buildings`
  /// ignored) and it is written tile by tile (write_synth_survey), never held whole.
  double survey_size = 0;
  static constexpr double kMaxSurveySize = 100000.0;  ///< m: 100 km a side
  double tile_size = 1000.0;       ///< survey: the side of its tiles, m (the last row and column may be narrower)
  bool unclassified_tiles = false;  ///< survey: also write each tile without classes (DIR/tiles_unclassified/)
  Vec3 origin = Vec3(155000, 463000, 0);  ///< file coordinates of the local origin
  std::string crs = "EPSG:28992";         ///< written into the files
};

struct SynthCityBuilding {
  std::string id;           ///< "B0001", ...
  std::string family;       ///< aerial_* or terraced_flat / terraced_gable
  std::uint64_t seed = 0;
  std::string attached_to;  ///< terraced: the id of the building it shares a wall with
  PolygonMesh truth;        ///< closed, outward, local coordinates, standing on ground_z (origin = the tile's)
  Footprint footprint;      ///< local x, y: the truth's bottom outline (outer ring counter-clockwise)
  double ground_z = 0;      ///< local: the true ground (the truth's bottom)
  std::size_t points = 0;   ///< scan points on it
};

struct SynthCity {
  SynthCityParams params;
  PointCloud cloud;                  ///< local; origin = params.origin; attributes: classification, returns
  std::vector<int> point_building;   ///< per point: index into `buildings`, -1 ground or tree
  std::vector<SynthCityBuilding> buildings;
};

/// Builds and scans the tile. Deterministic. Throws Error(BadInput, "synth") for N < 1, terraced < 0 or >= N,
/// density <= 0 or a negative noise.
SynthCity run_synth_city(const SynthCityParams& params);

/// Writes DIR/tile.las (classified), DIR/tile_unclassified.las, DIR/footprints.geojson (id, family, seed,
/// truth_ground_z, attached_to), DIR/truth/ID.obj per building and DIR/truth.json (parameters; per building its id,
/// family, seed, ground_z and footprint in file coordinates, points), and with params.tiles > 1 the tiles (see
/// SynthCityParams::tiles). Creates DIR; each file atomic.
void write_synth_city(const SynthCity& city, const std::string& dir);

// ------------------------------------------------------------------------------------------ a survey

/// A survey's layout (SynthCityParams::survey_size > 0): every building with its truth and footprint, the
/// trees, the terrain and the flight, but no point. The buildings stand on a grid of plots filling the
/// survey; the tiles' edges fall where they fall, so some cut through buildings. Deterministic.
///
/// The scanner flies strips: the flight lines of the one tile (two passes in opposite directions, each at
/// half the density on a jittered grid over the whole survey, 1000 m above the ground) with the sensor over
/// the centre of its strip (kStripWidth across: off nadir up to about 17 degrees, as the one tile's scanner
/// at its edges), each strip pitched on its own. Every ray takes its random numbers from its own counter
/// (seed, pass, row, column), not from a stream: a tile scans only the rays aimed within kScanMargin of it
/// and keeps the points that land on it, and gets exactly the points the whole survey scanned at once would
/// put there (test SynthSurvey.TwoByTwoTilesAreTheOneTileCut).
struct SynthSurvey {
  static constexpr double kStripWidth = 600.0;  ///< m across a flight strip
  /// m: a point lands within this of where its ray was aimed (buildings under 40 m at 21 degrees off
  /// nadir: 16 m; a crown under 12 m: 5 m), so a tile needs the rays aimed this far around it and the
  /// scene (buildings, terrain, trees) this far around it.
  static constexpr double kScanMargin = 30.0;
  SynthCityParams params;
  std::vector<SynthCityBuilding> buildings;  ///< `points` filled by write_synth_survey
  int tiles_per_side = 1;
  struct Scene;                          ///< the terrain, trees and flight (city_survey_synth.cpp)
  std::shared_ptr<const Scene> scene;
  /// Tile (row from the south, col from the west): [col, col + 1) x [row, row + 1) times tile_size, the
  /// last row and column closed at the survey's side; a point off the survey goes to the nearest tile.
  BBox tile_box(int row, int col) const;
};

/// The survey's layout. Throws Error(BadInput, "synth") for a bad size, tile size, `tiles` > 1 or terraced.
SynthSurvey plan_synth_survey(const SynthCityParams& params);

/// Tile (row, col)'s points, in ray order (pass, row and column of the ray): a SynthCity whose cloud and
/// point_building (indices into survey.buildings) hold the tile's points only, `buildings` empty.
SynthCity scan_survey_tile(const SynthSurvey& survey, int row, int col);

/// Writes the survey tile by tile, one tile's points in memory at a time: DIR/tiles/rRcC.las (classified;
/// with unclassified_tiles also DIR/tiles_unclassified/rRcC.las), then DIR/footprints.geojson (every
/// building), DIR/truth/ID.obj and DIR/truth.json (as write_synth_city, plus the survey's size, tile size and
/// per tile its file, extent and points). A tile without points is not written. Returns the points written.
std::size_t write_synth_survey(SynthSurvey& survey, const std::string& dir);

}  // namespace hsr
