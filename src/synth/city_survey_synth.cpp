// A synthetic survey written tile by tile (city_synth.h SynthSurvey; issue 40 item 2): the layout of the whole
// survey is drawn once (buildings, trees, terrain, flight), the points of one tile at a time.
#include "core/error.h"
#include "core/log.h"
#include "core/memory.h"
#include "io/las_writer.h"
#include "synth/city_synth.h"
#include "synth/city_synth_internal.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <utility>

namespace hsr {

using synth_detail::CityScanScene;
using synth_detail::CityTerrain;
using synth_detail::Crown;

struct SynthSurvey::Scene {
  CityTerrain terrain;
  std::vector<Crown> trees;
  Vec2 centre = Vec2::Zero(), along = Vec2::UnitX(), across = Vec2::UnitY();
  double half_along = 0, half_across = 0;  ///< the survey's half extents along and across the flight, m
  double spacing = 1;                      ///< the jittered grid's step of one pass, m
  std::int64_t nu = 0, nv = 0;             ///< rays of one pass along and across
};

namespace {

constexpr const char* kSurveyStage = "synth";
constexpr double kSurveyFlightHeight = 1000.0;  ///< m above the local origin (as the one tile's scanner)
constexpr double kSurveyMaxPitch = 4.0;         ///< degrees: each strip's pitch is drawn in +-this (as the one tile's)
constexpr double kSurveySecondReturnShare = 0.5;  ///< of the crown echoes, the share with a second return (the one tile's)
/// m: a crown a ray crosses has its centre this close to where the ray was aimed in plan (2 m of crown radius,
/// and 28 m of height between the crown and the aimed-at ground at 21 degrees off nadir), so a tile looks
/// only at the crowns in the cells this far around.
constexpr double kCrownReach = 12.0;
constexpr int kRowsPerBlock = 16;  ///< rays' rows (along the flight) per parallel block

/// A ray's own random numbers: splitmix64 from a counter made of the seed, the pass and the ray's row and
/// column, so the same ray draws the same numbers whichever tile scans it (a stream would depend on the rays
/// drawn before). Uniforms as synth_detail::uniform01 (53 bits, in (0, 1]).
class RayDraws {
 public:
  RayDraws(std::uint64_t seed, std::uint64_t pass, std::int64_t row, std::int64_t col) {
    state_ = mix(seed * 0x9E3779B97F4A7C15ull + 40);
    state_ = mix(state_ ^ (pass + 0x632BE59BD9B4E019ull));
    state_ = mix(state_ ^ static_cast<std::uint64_t>(row));
    state_ = mix(state_ + static_cast<std::uint64_t>(col) * 0xD1B54A32D192ED03ull);
  }
  double uniform01() { return (static_cast<double>(next() >> 11) + 1.0) * 0x1.0p-53; }
  double gaussian() {
    const double u1 = uniform01(), u2 = uniform01();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
  }

 private:
  static std::uint64_t mix(std::uint64_t z) {
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  std::uint64_t next() { return mix(state_ += 0x9E3779B97F4A7C15ull); }
  std::uint64_t state_ = 0;
};

/// A tile's index along one axis for a coordinate: the tile holding it, the nearest one off the survey.
int tile_index(double x, double tile_size, int tiles) {
  return std::clamp(static_cast<int>(std::floor(x / tile_size)), 0, tiles - 1);
}

/// The points of one block of rays, appended in ray order.
struct PointRun {
  std::vector<Vec3> points;
  std::vector<std::uint8_t> classification, return_number, number_of_returns;
  std::vector<int> building;
};

/// The crowns near a tile, by plan cell of kCrownReach, for the few a ray may cross.
class CrownGrid {
 public:
  CrownGrid(const std::vector<Crown>& crowns, const BBox& area) : crowns_(crowns), area_(area) {
    nx_ = std::max<std::int64_t>(1, static_cast<std::int64_t>(std::ceil((area.max.x() - area.min.x()) / kCrownReach)));
    ny_ = std::max<std::int64_t>(1, static_cast<std::int64_t>(std::ceil((area.max.y() - area.min.y()) / kCrownReach)));
    cells_.resize(static_cast<std::size_t>(nx_ * ny_));
    for (std::size_t t = 0; t < crowns.size(); ++t) {
      const Vec3& c = crowns[t].centre;
      if (c.x() < area.min.x() || c.x() > area.max.x() || c.y() < area.min.y() || c.y() > area.max.y()) continue;
      cells_[static_cast<std::size_t>(cell(c.y(), area.min.y(), ny_) * nx_ + cell(c.x(), area.min.x(), nx_))].push_back(static_cast<int>(t));
    }
  }
  /// The nearest entry (t, and the crown's exit) of the ray into a crown before `before`, among the crowns
  /// whose centre lies in the cells around `aim` (ties: the first crown of the survey).
  std::optional<std::pair<double, double>> first_crossing(const Vec3& sensor, const Vec3& ray, const Vec2& aim, double before) const {
    std::optional<std::pair<double, double>> best;
    int best_index = -1;
    const std::int64_t i = cell(aim.x(), area_.min.x(), nx_), j = cell(aim.y(), area_.min.y(), ny_);
    for (std::int64_t jj = std::max<std::int64_t>(0, j - 1); jj <= std::min(ny_ - 1, j + 1); ++jj)
      for (std::int64_t ii = std::max<std::int64_t>(0, i - 1); ii <= std::min(nx_ - 1, i + 1); ++ii)
        for (int t : cells_[static_cast<std::size_t>(jj * nx_ + ii)]) {
          const auto cross = crowns_[static_cast<std::size_t>(t)].crossing(sensor, ray);
          if (!cross || !(cross->first < before)) continue;
          if (!best || cross->first < best->first || (cross->first == best->first && t < best_index)) {
            best = cross;
            best_index = t;
          }
        }
    return best;
  }

 private:
  static std::int64_t cell(double x, double min, std::int64_t n) {
    return std::clamp<std::int64_t>(static_cast<std::int64_t>(std::floor((x - min) / kCrownReach)), 0, n - 1);
  }
  const std::vector<Crown>& crowns_;
  BBox area_;
  std::int64_t nx_ = 1, ny_ = 1;
  std::vector<std::vector<int>> cells_;
};

BBox grown(const BBox& b, double by) {
  BBox g = b;
  g.min -= Vec3(by, by, 0);
  g.max += Vec3(by, by, 0);
  return g;
}

bool in_plan(const BBox& b, const Vec2& p) {
  return p.x() >= b.min.x() && p.x() <= b.max.x() && p.y() >= b.min.y() && p.y() <= b.max.y();
}

}  // namespace

BBox SynthSurvey::tile_box(int row, int col) const {
  const double t = params.tile_size, s = params.survey_size;
  BBox b;
  b.extend(Vec3(col * t, row * t, 0));
  b.extend(Vec3(std::min(s, (col + 1) * t), std::min(s, (row + 1) * t), 0));
  return b;
}

SynthSurvey plan_synth_survey(const SynthCityParams& params) {
  if (!(params.survey_size > 0)) throw Error(Status::BadInput, kSurveyStage, "city: a survey needs --size > 0");
  synth_detail::check_city_params(params);
  SynthSurvey survey;
  survey.params = params;
  const double size = params.survey_size;
  survey.tiles_per_side = static_cast<int>(std::ceil(size / params.tile_size));
  auto scene = std::make_shared<SynthSurvey::Scene>();
  std::mt19937_64 rng(params.seed * 0x9E3779B97F4A7C15ull + 27);
  scene->terrain = synth_detail::draw_city_terrain(params, rng);
  const int n = synth_detail::survey_plots_per_side(params);
  std::vector<Vec2> centres;
  for (int i = 0; i < n * n; ++i) centres.emplace_back((i % n + 0.5) * params.plot, (i / n + 0.5) * params.plot);
  survey.buildings = synth_detail::place_city_buildings(params, centres, scene->terrain, rng);
  BBox area;
  area.extend(Vec3(0, 0, 0));
  area.extend(Vec3(size, size, 0));
  const int tree_count = params.trees < 0 ? static_cast<int>(survey.buildings.size()) : params.trees;
  scene->trees = synth_detail::place_city_trees(tree_count, area, survey.buildings, scene->terrain, params.plot_flat, rng);
  const double heading = M_PI * synth_detail::uniform01(rng);
  scene->centre = Vec2(0.5 * size, 0.5 * size);
  scene->along = Vec2(std::cos(heading), std::sin(heading));
  scene->across = Vec2(-scene->along.y(), scene->along.x());
  for (double x : {0.0, size})
    for (double y : {0.0, size}) {
      scene->half_along = std::max(scene->half_along, std::abs((Vec2(x, y) - scene->centre).dot(scene->along)));
      scene->half_across = std::max(scene->half_across, std::abs((Vec2(x, y) - scene->centre).dot(scene->across)));
    }
  scene->spacing = 1.0 / std::sqrt(params.density / 2.0);
  scene->nu = static_cast<std::int64_t>(std::ceil(2 * scene->half_along / scene->spacing));
  scene->nv = static_cast<std::int64_t>(std::ceil(2 * scene->half_across / scene->spacing));
  for (SynthCityBuilding& b : survey.buildings) b.truth.origin = params.origin;
  log::verbose("synth: city: " + std::to_string(survey.buildings.size()) + " buildings and " + std::to_string(scene->trees.size()) +
               " trees laid out; peak memory so far " + std::to_string(static_cast<int>(log::peak_memory_mb())) + " MB");
  survey.scene = std::move(scene);
  return survey;
}

namespace {

/// The points of tile (row, col): every ray aimed within kScanMargin of it cast into the scene around it (its
/// buildings, terrain and crowns), the points landing on it kept; a run per block of rows and pass, in ray order.
std::vector<PointRun> cast_tile_rays(const SynthSurvey& survey, int row, int col) {
  const SynthCityParams& p = survey.params;
  const SynthSurvey::Scene& s = *survey.scene;
  const int n = survey.tiles_per_side;
  const BBox own = survey.tile_box(row, col);
  const BBox reach = grown(own, SynthSurvey::kScanMargin);  // the rays aimed here, and the scene they may meet
  BBox ground;  // the terrain's height field: whole metres, so every tile's vertices are the same
  ground.extend(Vec3(std::floor(reach.min.x()), std::floor(reach.min.y()), 0));
  ground.extend(Vec3(std::ceil(reach.max.x()), std::ceil(reach.max.y()), 0));
  // Every building whose levelled plot reaches the height field, in the survey's order (the heights' sums).
  const BBox levelled = grown(ground, p.plot_flat + synth_detail::kCityPlotBlend + 1.0);
  std::vector<SynthCityBuilding> near;
  std::vector<int> index;
  for (std::size_t b = 0; b < survey.buildings.size(); ++b) {
    const BBox box = synth_detail::plan_box_of(survey.buildings[b].footprint);
    if (box.max.x() < levelled.min.x() || box.min.x() > levelled.max.x() || box.max.y() < levelled.min.y() || box.min.y() > levelled.max.y())
      continue;
    near.push_back(survey.buildings[b]);
    index.push_back(static_cast<int>(b));
  }
  CityScanScene scene;
  synth_detail::add_city_buildings(scene, near, index);
  synth_detail::append_city_terrain(scene, ground, s.terrain, near, p.plot_flat);
  const synth_detail::RayCaster caster(scene.mesh, scene.planes);
  const CrownGrid crowns(s.trees, grown(reach, kCrownReach));

  // The rays aimed within reach: their rows and columns (a superset: each ray is tested).
  double u0 = INFINITY, u1 = -INFINITY, v0 = INFINITY, v1 = -INFINITY;
  for (double x : {reach.min.x(), reach.max.x()})
    for (double y : {reach.min.y(), reach.max.y()}) {
      const Vec2 d = Vec2(x, y) - s.centre;
      u0 = std::min(u0, d.dot(s.along)), u1 = std::max(u1, d.dot(s.along));
      v0 = std::min(v0, d.dot(s.across)), v1 = std::max(v1, d.dot(s.across));
    }
  auto first_index = [&](double v, double half, std::int64_t count) {
    return std::clamp<std::int64_t>(static_cast<std::int64_t>(std::floor((v + half) / s.spacing)) - 1, 0, count);
  };
  auto last_index = [&](double v, double half, std::int64_t count) {
    return std::clamp<std::int64_t>(static_cast<std::int64_t>(std::ceil((v + half) / s.spacing)) + 1, 0, count);
  };
  const std::int64_t iu0 = first_index(u0, s.half_along, s.nu), iu1 = last_index(u1, s.half_along, s.nu);
  const std::int64_t iv0 = first_index(v0, s.half_across, s.nv), iv1 = last_index(v1, s.half_across, s.nv);
  const std::int64_t blocks = (iu1 - iu0 + kRowsPerBlock - 1) / kRowsPerBlock;
  std::vector<PointRun> runs(static_cast<std::size_t>(2 * std::max<std::int64_t>(0, blocks)));
  const double strip = SynthSurvey::kStripWidth;

  auto scan_block = [&](int pass, std::int64_t block, PointRun& out) {
    const Vec2 dir = pass == 0 ? s.along : Vec2(-s.along);
    const double shift = pass == 0 ? 0.0 : 0.5 * strip;  // the second pass's strips lie half a strip over
    for (std::int64_t iu = iu0 + block * kRowsPerBlock; iu < std::min(iu1, iu0 + (block + 1) * kRowsPerBlock); ++iu)
      for (std::int64_t iv = iv0; iv < iv1; ++iv) {
        RayDraws draws(p.seed, static_cast<std::uint64_t>(pass), iu, iv);
        const double u = -s.half_along + (static_cast<double>(iu) + draws.uniform01()) * s.spacing;
        const double v = -s.half_across + (static_cast<double>(iv) + draws.uniform01()) * s.spacing;
        const Vec2 aim = s.centre + u * s.along + v * s.across;
        if (aim.x() < 0 || aim.x() > p.survey_size || aim.y() < 0 || aim.y() > p.survey_size || !in_plan(reach, aim)) continue;
        const std::int64_t k = static_cast<std::int64_t>(std::floor((v + s.half_across + shift) / strip));
        RayDraws strip_draws(p.seed ^ 0x5157A1B2C3D4E5F6ull, static_cast<std::uint64_t>(pass), k, 0);
        const double pitch = (-kSurveyMaxPitch + 2 * kSurveyMaxPitch * strip_draws.uniform01()) * M_PI / 180.0;
        const double offset = (static_cast<double>(k) + 0.5) * strip - shift - s.half_across;
        const Vec2 sensor2 = s.centre + offset * s.across + u * s.along - kSurveyFlightHeight * std::tan(pitch) * dir;
        const Vec3 sensor(sensor2.x(), sensor2.y(), kSurveyFlightHeight);
        const Vec3 ray = (Vec3(aim.x(), aim.y(), s.terrain.natural(aim.x(), aim.y())) - sensor).normalized();
        auto hit = caster.first_hit(sensor, ray);
        if (hit && std::abs(scene.planes[static_cast<std::size_t>(hit->face)].normal.dot(ray)) < 0.02) hit.reset();
        const double surface_t = hit ? hit->t : INFINITY;
        // Every ray draws the same numbers in the same order, whatever it meets.
        const double echo = draws.uniform01(), depth = draws.uniform01(), second_draw = draws.uniform01();
        std::optional<double> crown_t;
        if (auto cross = crowns.first_crossing(sensor, ray, aim, surface_t); cross && echo < synth_detail::kCrownEchoShare)
          crown_t = cross->first + 0.4 * depth * (std::min(cross->second, surface_t) - cross->first);
        const bool second = crown_t && hit && second_draw < kSurveySecondReturnShare;
        auto emit = [&](double t, std::uint8_t cls, int building, std::uint8_t ret, std::uint8_t of) {
          const Vec3 q = sensor + (t + p.range_noise * draws.gaussian()) * ray;
          if (tile_index(q.x(), p.tile_size, n) != col || tile_index(q.y(), p.tile_size, n) != row) return;
          out.points.push_back(q);
          out.classification.push_back(cls);
          out.return_number.push_back(ret);
          out.number_of_returns.push_back(of);
          out.building.push_back(building);
        };
        if (crown_t) emit(*crown_t, 5, -1, 1, second ? 2 : 1);
        if (hit && (!crown_t || second)) {
          const int b = scene.face_building[static_cast<std::size_t>(hit->face)];
          emit(hit->t, b >= 0 ? 6 : 2, b, crown_t ? 2 : 1, crown_t ? 2 : 1);
        }
      }
  };
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, runs.size()), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t k = r.begin(); k != r.end(); ++k)
      scan_block(static_cast<int>(k / static_cast<std::size_t>(blocks)), static_cast<std::int64_t>(k % static_cast<std::size_t>(blocks)), runs[k]);
  });
  return runs;
}

}  // namespace


SynthCity scan_survey_tile(const SynthSurvey& survey, int row, int col) {
  const SynthCityParams& p = survey.params;
  const int n = survey.tiles_per_side;
  if (row < 0 || col < 0 || row >= n || col >= n)
    throw Error(Status::BadInput, kSurveyStage, "city: no tile r" + std::to_string(row) + "c" + std::to_string(col) + " in the survey");
  std::vector<PointRun> runs = cast_tile_rays(survey, row, col);  // the scene is gone before the points are gathered
  SynthCity tile;
  tile.params = p;
  std::size_t total = 0;
  for (const PointRun& r : runs) total += r.points.size();
  PointCloud& c = tile.cloud;
  auto& a = c.attributes;
  c.points.reserve(total);
  a.classification.reserve(total);
  a.return_number.reserve(total);
  a.number_of_returns.reserve(total);
  tile.point_building.reserve(total);
  for (PointRun& r : runs) {  // in ray order; each run freed once copied
    c.points.insert(c.points.end(), r.points.begin(), r.points.end());
    a.classification.insert(a.classification.end(), r.classification.begin(), r.classification.end());
    a.return_number.insert(a.return_number.end(), r.return_number.begin(), r.return_number.end());
    a.number_of_returns.insert(a.number_of_returns.end(), r.number_of_returns.begin(), r.number_of_returns.end());
    tile.point_building.insert(tile.point_building.end(), r.building.begin(), r.building.end());
    r = PointRun{};
  }
  c.origin = p.origin;
  c.crs = p.crs;
  c.source = "synth:city";
  return tile;
}

std::size_t write_synth_survey(SynthSurvey& survey, const std::string& dir) {
  namespace fs = std::filesystem;
  const fs::path root(dir);
  const SynthCityParams& p = survey.params;
  synth_detail::create_folder(root / "truth");
  synth_detail::create_folder(root / "tiles");
  if (p.unclassified_tiles) synth_detail::create_folder(root / "tiles_unclassified");
  for (SynthCityBuilding& b : survey.buildings) b.points = 0;
  const int n = survey.tiles_per_side;
  std::size_t points = 0;
  nlohmann::json tiles = nlohmann::json::array();
  for (int row = 0; row < n; ++row)
    for (int col = 0; col < n; ++col) {
      SynthCity tile = scan_survey_tile(survey, row, col);
      const std::string name = "r" + std::to_string(row) + "c" + std::to_string(col) + ".las";
      log::info("synth: city: tile " + std::to_string(row * n + col + 1) + " of " + std::to_string(n * n) + ", " + name + ": " +
                std::to_string(tile.cloud.size()) + " points");
      if (tile.cloud.empty()) continue;
      for (int b : tile.point_building)
        if (b >= 0) ++survey.buildings[static_cast<std::size_t>(b)].points;
      tile.point_building = {};
      write_las((root / "tiles" / name).string(), tile.cloud);
      if (p.unclassified_tiles) {
        std::fill(tile.cloud.attributes.classification.begin(), tile.cloud.attributes.classification.end(), 0);
        write_las((root / "tiles_unclassified" / name).string(), tile.cloud);
      }
      const BBox box = survey.tile_box(row, col);
      const Vec3& o = p.origin;
      tiles.push_back({{"file", "tiles/" + name}, {"row", row}, {"col", col}, {"points", tile.cloud.size()},
                       {"extent", {box.min.x() + o.x(), box.min.y() + o.y(), box.max.x() + o.x(), box.max.y() + o.y()}}});
      points += tile.cloud.size();
      tile = SynthCity{};
      release_free_memory();  // the next tile's peak does not sit on this one's leftovers
    }
  synth_detail::write_city_truth(p, survey.buildings, points, root,
                                 {{"survey", {{"size", p.survey_size}, {"tile_size", p.tile_size}, {"tiles", tiles}}}});
  return points;
}

}  // namespace hsr
