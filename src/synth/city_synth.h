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

}  // namespace hsr
