// The tile stage of `hsr city` (issue 27; DESIGN.md §4 "From a tile to a city"; README "City scale"): a survey
// tile in, the buildings on it out, each with its points, its footprint, its ground height and its id, ready
// for one building-mode run each (src/driver/city_run.h runs them and writes the CityJSONSeq).
//
// 1. Classes (split_classes). Ground: the file's class 2 when it has such points (--classes auto/file), else
//    SMRF (ground_filter.h). Buildings: the file's class 6 when it has such points, else the points that are
//      - above the ground model (class 2's, or SMRF's) by at least min_height_above_ground,
//      - not vegetation: a single return when the file records returns (a pulse with several returns went
//        through foliage; number_of_returns > 1 is vegetation), and
//      - planar: the surface variation lambda_min / (lambda_1 + lambda_2 + lambda_3) of the covariance of
//        the point and its planar_neighbours nearest candidates at most max_surface_variation. On a plane it
//        is the noise's share (0.003 for 3 cm of noise at 10 points/m²); at k = 24, points astride a ridge
//        have 0.05 (30-degree roofs) to 0.11 (45 degrees), and 95 % of points scattered through a volume
//        (foliage) have more than 0.11 (simulated; tests/city): 0.1 keeps roofs and their ridges up to
//        about 40 degrees, steeper ridges lose a strip of one neighbourhood (the pipeline intersects the
//        roof planes there anyway).
//    Every other point (other classes, vegetation) is left out. --classes filter ignores the file's classes;
//    --classes file requires class 2 or 6. The choice and its counts are printed (CityTile::classes).
// 2. Buildings. With footprints (FootprintFeature, in the points' CRS): a footprint belongs to the tile when
//    the centre of its bounding box lies in the tile's bounding box (several tiles: when the tile owns that
//    centre, survey.h, so a footprint on two tiles is done once, with the points of both); its points are the building points inside it, plus those within `buffer` outside it that lie in
//    no other footprint (walls and eaves a little outside the drawn outline; a neighbour's roof is not taken).
//    Without footprints: connected groups of building points in plan: grid cells of component_cell that hold
//    a building point, 8-connected after an opening by one cell (a link thinner than 3 cells, such as garden
//    or tree points between two rows of houses, joins nothing; the cells it removed go to the group they
//    touch first); groups under min_building_area or min_building_points are left out. Its
//    limits: buildings that touch (terraced houses, a shared wall) or are joined by points between them (a
//    tree over both, a covered passage) are one group; a building whose roof points are cut by a gap wider
//    than a cell (a courtyard roof is fine, an unscanned strip is not) is two; a bridge or a flat-topped
//    structure is a building. Ids: the footprint's; for groups "b" + a 4-digit number in the order of their
//    first cell (row by row from the tile's south-west corner): stable for a given tile and parameters.
// 3. Ground height per building: the median height of the ground points (class 2, or the filter's) lying
//    outside the footprint at a distance in [ring_inner, ring_outer] from it (for a group: from its cells);
//    with fewer than ring_min_points there, the ring's outer distance is doubled until ring_max_outer;
//    still too few: no ground height (the building pipeline then uses its own rule) and the source says so.
//    The building mode puts the solid's ground face at that height (SceneParams::ground_z).
// 4. A footprint with fewer than min_building_points points (too few for a run: a garden shed, a footprint
//    mostly off the scan) is modelled as its footprint prism (TileBuilding::footprint_prism; the outline prism
//    over the footprint, PipelineParams::footprint_prism); one with fewer than min_prism_points (none at all: a
//    demolished or not yet built building, a classification miss) gets no model and is listed as no-points
//    (TileBuilding::no_points), not a failure (DECISIONS #165). A group with fewer than min_building_points (or
//    under min_building_area) is no building (a tree's remnant, a car) and is left out.
// 5. Trees among the groups (building points by the rule only; a file's class 6 is trusted): a group whose
//    points' median surface variation (step 1's, over its neighbours among the candidates) is above
//    max_group_variation is vegetation (TileBuilding::not_building): listed, not modelled, not a failure.
//    A roof's points are flat but for the noise, its ridges and edges: median 0.001-0.004 over the synthetic
//    tiles' buildings (10 and 20 points/m²), 0.018 over autzen_trim's house, 0.000-0.031 over cgal_urban's
//    roofs and roof fragments (2 points/m²: the 24 neighbours reach across ridges); a crown's points, each let
//    through by step 1's bound, still scatter as a whole: 0.054-0.077 over autzen_trim's ten tree groups,
//    0.052 over cgal_urban's tall one. 0.04 lies between (bench/city/group_rule.py; DECISIONS #81).
// All lengths are in metres; `hsr city` converts them into the tile's units when its CRS's are others (a
// CRS in US feet: in_tile_units). Deterministic.
#pragma once

#include "city/footprints.h"
#include "city/ground_filter.h"
#include "city/survey.h"
#include "core/types.h"

#include <nlohmann/json.hpp>

#include <limits>
#include <string>
#include <vector>

namespace hsr {

enum class ClassSource {
  Auto,    ///< class 2 / class 6 where the file has such points, else SMRF / the building rule
  File,    ///< the same, but an error when the file has neither class 2 nor class 6
  Filter,  ///< the ground filter and the building rule, whatever the file says
};
const char* class_source_name(ClassSource s);  ///< "auto", "file", "filter"
ClassSource parse_class_source(const std::string& name);  ///< throws Error(BadInput, "city")

struct CityParams {
  ClassSource classes = ClassSource::Auto;
  SmrfParams smrf;                      ///< the ground filter (tiles without classes)
  double min_height_above_ground = 2.0;  ///< no classes: building points rise this far above the ground model, m
  int planar_neighbours = 24;           ///< no classes: k of the local covariance
  double max_surface_variation = 0.1;   ///< no classes: lambda_min / sum of the eigenvalues, at most this
  double buffer = 0.5;                  ///< footprints: points this close outside a footprint belong to it, m
  double component_cell = 1.0;          ///< no footprints: cell of the plan grid of building points, m
  double min_building_area = 10.0;      ///< no footprints: smaller groups (cells x cell area) are left out, m²
  /// Fewer building points: a footprint's model is its footprint prism (step 4), a group is left out. Points.
  std::size_t min_building_points = 50;
  /// Footprints: fewer building points than this get no model (step 4: listed as no-points, not a failure). 3: one
  /// or two points (a bird, a cable, a neighbour's eave within the buffer) are no roof height worth a block. Points.
  std::size_t min_prism_points = 3;
  double ring_inner = 0.5;              ///< ground ring: from this distance outside the footprint, m
  double ring_outer = 3.0;              ///< ... to this one, m
  double ring_max_outer = 24.0;         ///< ... doubled up to this while it holds too few ground points, m
  std::size_t ring_min_points = 10;     ///< ground points needed in the ring
  /// No classes, no footprints: a group whose points' median surface variation is above this is vegetation
  /// (step 5; a ratio of eigenvalues, no unit)
  double max_group_variation = 0.04;
  /// Several tiles: each tile is planned with its neighbours' points this far around it (survey.h), m. It must
  /// hold a building that crosses the edge, its buffer and its ground ring (ring_max_outer); a group of
  /// building points that reaches farther is listed as failed, naming this.
  double tile_margin = 50.0;
  /// The unit the lengths above are in, for messages ("m"; in_tile_units sets the tile's). Not a parameter.
  std::string length_unit = "m";
};

/// Every field of CityParams as JSON and back (city_params.cpp; core/params_json.h). from_json keeps fields
/// the object lacks, and throws Error(BadInput, "config") on an unknown key or a value of the wrong type.
void to_json(nlohmann::json& j, const CityParams& p);
void from_json(const nlohmann::json& j, CityParams& p);

/// One building of the tile.
struct TileBuilding {
  std::string id;
  std::vector<std::size_t> points;  ///< indices into the tile's cloud, ascending
  Footprint footprint;              ///< file coordinates (global x, y); empty for a group without footprint
  nlohmann::json attributes = nlohmann::json::object();  ///< the footprint's fields
  double area = 0;                  ///< plan area: the footprint's, or the group's cells', m²
  /// Ground height in file coordinates (global z); NaN: none found (ground_source says why).
  double ground_z = std::numeric_limits<double>::quiet_NaN();
  std::size_t ground_points = 0;    ///< ground points the median was taken over
  double ring_outer = 0;            ///< outer distance of the ring used, m
  std::string ground_source;        ///< e.g. "median of 154 ground points 0.5-3 m around the footprint"
  std::string failure;              ///< non-empty: not to be reconstructed, and why
  /// A footprint with fewer than min_building_points points: its model is the footprint prism (step 4).
  bool footprint_prism = false;
  /// Non-empty: a footprint with fewer than min_prism_points points (step 4), and why; listed, not
  /// reconstructed, not a failure.
  std::string no_points;
  /// Non-empty: a group that is not a building (step 5: vegetation), and why; listed, not reconstructed,
  /// not a failure.
  std::string not_building;
};

struct CityTile {
  std::string classes;          ///< how ground and building points were found, with counts (one line)
  std::string buildings_from;   ///< "footprints" or "connected groups of building points in plan"
  std::vector<char> ground, building;  ///< per point of the tile
  /// Per point of the tile, the surface variation step 1's rule computed (its candidates; NaN elsewhere);
  /// empty when the building points are the file's class 6.
  std::vector<float> variation;
  std::size_t ground_points = 0, building_points = 0, unused_building_points = 0;  ///< the last: in no building
  std::size_t footprints_elsewhere = 0;  ///< footprints whose centre lies off the tile
  std::size_t small_groups = 0;          ///< groups left out: under min_building_area or min_building_points
  std::size_t vegetation_groups = 0;     ///< groups listed as not buildings (step 5)
  std::size_t groups_elsewhere = 0;      ///< several tiles: groups whose centre another tile owns
  std::vector<TileBuilding> buildings;   ///< footprints in file order, or groups by id
};

/// The parameters for a tile whose coordinates are in units of `metres_per_unit` metres (a CRS in feet: 0.3048):
/// every length (and area) of `params`, given in metres, converted into those units.
CityParams in_tile_units(const CityParams& params, double metres_per_unit, const std::string& unit_name);

/// The ground and building points of the tile (step 1). Throws Error(BadInput, "city") for ClassSource::File
/// on a tile without class 2 or 6 points. `left_out`: points of the tile the cloud lacks (survey.h), counted.
void split_classes(const PointCloud& tile, const CityParams& params, CityTile& out, const PointsLeftOut& left_out = {});

/// Steps 1-5. `footprints` null: groups in plan. `region`: where the cloud lies in a survey of several tiles
/// (survey.h; default: a tile on its own); then a footprint or group is the tile's when the tile owns the
/// centre of its bounding box (owning_tile), and a group that reaches a side of the loaded region with survey
/// beyond it is listed as failed. Throws Error(BadInput, "city") on parameters out of range.
CityTile run_city_tile(const PointCloud& tile, const std::vector<FootprintFeature>* footprints, const CityParams& params = {},
                       const SurveyRegion& region = {});

/// Step 2's owner rule for one footprint (file coordinates): whether the tile whose cloud has the local origin
/// `origin` plans it. A tile on its own: the centre of the footprint's bounding box lies in `tile_box` (local:
/// the bounding box of the tile's own points); in a survey (region.several()): the tile owns that centre
/// (owning_tile). run_city_tile's arithmetic exactly (the footprint shifted to local coordinates first), so that
/// the reader of a survey keeps only the points near the footprints its tile plans (DECISIONS #103).
bool tile_plans_footprint(const Footprint& footprint, const Vec3& origin, const BBox& tile_box, const SurveyRegion& region);

/// The plan position step 2's owner rules test for a footprint (file coordinates): the centre of its bounding box
/// in local coordinates (origin `origin`) plus the origin, as tile_plans_footprint computes it (TileBlocks::of).
Vec2 footprint_plan_centre(const Footprint& footprint, const Vec3& origin);

/// Median height of the ground points around a footprint (local coordinates; step 3), for tests and for
/// run_city_tile: fills b.ground_z (local), ground_points, ring_outer, ground_source.
void ring_ground_height(const std::vector<Vec3>& ground, const Footprint& local_footprint, const CityParams& params,
                        TileBuilding& b);

/// Distance from (x, y) to the nearest edge of any ring of the footprint.
double distance_to_footprint(const Vec2& p, const Footprint& footprint);

/// Plan area of a footprint (outer rings minus holes).
double footprint_area(const Footprint& footprint);

}  // namespace hsr
