// The tile stage of `hsr city` (city.h): classes, buildings by footprints or groups in plan, ground rings.
#include "city/city.h"

#include "city/city_internal.h"
#include "core/error.h"
#include "core/kd_tree.h"
#include "core/stats.h"
#include "core/log.h"

#include <Eigen/Eigenvalues>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <deque>
#include <functional>
#include <map>

namespace hsr {

namespace {


[[noreturn]] void bad(const std::string& what) { throw Error(Status::BadInput, kCityStage, what); }

/// Points (indices into a cloud) bucketed on a plan grid, for box queries.
class PlanIndex {
 public:
  PlanIndex(const std::vector<Vec3>& points, const std::vector<std::size_t>& ids, double cell) : points_(points), cell_(cell) {
    for (std::size_t i : ids) buckets_[key(points[i].x(), points[i].y())].push_back(i);
  }
  /// Indices of the points with x in [x0, x1] and y in [y0, y1], ascending.
  std::vector<std::size_t> query(double x0, double y0, double x1, double y1) const {
    std::vector<std::size_t> out;
    const long i0 = cell_of(x0), i1 = cell_of(x1), j0 = cell_of(y0), j1 = cell_of(y1);
    for (long i = i0; i <= i1; ++i)
      for (long j = j0; j <= j1; ++j) {
        const auto it = buckets_.find({i, j});
        if (it == buckets_.end()) continue;
        for (std::size_t k : it->second) {
          const Vec3& p = points_[k];
          if (p.x() >= x0 && p.x() <= x1 && p.y() >= y0 && p.y() <= y1) out.push_back(k);
        }
      }
    std::sort(out.begin(), out.end());
    return out;
  }

 private:
  long cell_of(double v) const { return static_cast<long>(std::floor(v / cell_)); }
  std::pair<long, long> key(double x, double y) const { return {cell_of(x), cell_of(y)}; }
  const std::vector<Vec3>& points_;
  double cell_;
  std::map<std::pair<long, long>, std::vector<std::size_t>> buckets_;
};

std::string count_text(std::size_t n) { return std::to_string(n); }


double segment_distance(const Vec2& p, const Vec2& a, const Vec2& b) {
  const Vec2 ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (p - (a + t * ab)).norm();
}

BBox plan_box(const Footprint& f) {
  BBox b;
  for (const FootprintPolygon& p : f)
    for (const Vec2& q : p.outer) b.extend(Vec3(q.x(), q.y(), 0));
  return b;
}

Footprint shifted(const Footprint& f, const Vec2& by) {
  Footprint out = f;
  for (FootprintPolygon& p : out) {
    for (Vec2& q : p.outer) q += by;
    for (auto& h : p.holes)
      for (Vec2& q : h) q += by;
  }
  return out;
}

// ------------------------------------------------------------------------------------- step 1: classes

/// lambda_min / (lambda_1 + lambda_2 + lambda_3) of each candidate's neighbourhood (itself and its k nearest
/// candidates); 1 where there are too few candidates to say.
std::vector<double> surface_variation(const std::vector<Vec3>& pts, int k) {
  std::vector<double> out(pts.size(), 1.0);
  if (pts.size() <= static_cast<std::size_t>(k)) return out;
  const KdTree tree(pts);
  const std::vector<int> rows = tree.neighbour_rows(k);
  tbb::parallel_for(std::size_t(0), pts.size(), [&](std::size_t i) {
    Vec3 mean = pts[i];
    for (int n = 0; n < k; ++n) mean += pts[static_cast<std::size_t>(rows[i * k + n])];
    mean /= (k + 1);
    Eigen::Matrix3d cov = (pts[i] - mean) * (pts[i] - mean).transpose();
    for (int n = 0; n < k; ++n) {
      const Vec3 d = pts[static_cast<std::size_t>(rows[i * k + n])] - mean;
      cov += d * d.transpose();
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov, Eigen::EigenvaluesOnly);
    const Vec3 ev = eig.eigenvalues();  // ascending
    const double sum = ev.sum();
    out[i] = sum > 0 ? std::max(0.0, ev[0]) / sum : 1.0;
  });
  return out;
}

/// Building points by the rule (city.h step 1): above the ground model, single returns, planar.
void buildings_by_rule(const PointCloud& tile, const HeightGrid& model, const CityParams& params, CityTile& out,
                       std::string& how) {
  const auto& returns = tile.attributes.number_of_returns;
  const bool has_returns = std::any_of(returns.begin(), returns.end(), [](std::uint8_t n) { return n > 1; });
  std::vector<std::size_t> candidates;
  std::size_t multiple = 0;
  for (std::size_t i = 0; i < tile.size(); ++i) {
    if (out.ground[i]) continue;
    const Vec3& p = tile.points[i];
    if (p.z() - model.sample(p.x(), p.y()) < params.min_height_above_ground) continue;
    if (has_returns && returns[i] > 1) {
      ++multiple;
      continue;
    }
    candidates.push_back(i);
  }
  std::vector<Vec3> pts;
  for (std::size_t i : candidates) pts.push_back(tile.points[i]);
  const std::vector<double> variation = surface_variation(pts, params.planar_neighbours);
  std::size_t scattered = 0;
  out.variation.assign(tile.size(), std::numeric_limits<float>::quiet_NaN());
  for (std::size_t c = 0; c < candidates.size(); ++c) {
    out.variation[candidates[c]] = static_cast<float>(variation[c]);
    if (variation[c] <= params.max_surface_variation) out.building[candidates[c]] = 1;
    else ++scattered;
  }
  out.building_points = static_cast<std::size_t>(std::count(out.building.begin(), out.building.end(), 1));
  char buf[400];
  std::snprintf(buf, sizeof buf,
                "building points by the rule: %g %s or more above the ground, %s planar (surface variation <= %g of %d "
                "neighbours): %zu (left out: %zu with several returns, %zu scattered)",
                params.min_height_above_ground, params.length_unit.c_str(), has_returns ? "single returns," : "(no multiple returns recorded)",
                params.max_surface_variation, params.planar_neighbours, out.building_points, multiple, scattered);
  how = buf;
}

// ------------------------------------------------------------------------------------- step 3: ground ring

/// The ring's median over the candidates' distances (outside the plan shape: >= 0; inside: < 0).
void ring_from_distances(const std::vector<double>& z, const std::vector<double>& distance, const CityParams& params,
                         const char* around, TileBuilding& b) {
  for (double outer = params.ring_outer;; outer *= 2) {
    outer = std::min(outer, params.ring_max_outer);
    std::vector<double> ring;
    for (std::size_t i = 0; i < z.size(); ++i)
      if (distance[i] >= params.ring_inner && distance[i] <= outer) ring.push_back(z[i]);
    if (ring.size() >= params.ring_min_points) {
      b.ground_z = median(ring);
      b.ground_points = ring.size();
      b.ring_outer = outer;
      char buf[160];
      std::snprintf(buf, sizeof buf, "median of %zu ground points %g-%g %s around the %s", ring.size(), params.ring_inner,
                    outer, params.length_unit.c_str(), around);
      b.ground_source = buf;
      return;
    }
    if (outer >= params.ring_max_outer) break;
  }
  b.ground_z = std::numeric_limits<double>::quiet_NaN();
  b.ground_points = 0;
  b.ring_outer = params.ring_max_outer;
  char buf[200];
  std::snprintf(buf, sizeof buf, "fewer than %zu ground points within %g %s of the %s: the building's lowest point",
                params.ring_min_points, params.ring_max_outer, params.length_unit.c_str(), around);
  b.ground_source = buf;
}

// ------------------------------------------------------------------------------------- step 2: footprints

/// Footprints' plan boxes on a grid: which footprints may hold a point.
class FootprintIndex {
 public:
  FootprintIndex(const std::vector<Footprint>& footprints, double cell) : footprints_(footprints), cell_(cell) {
    for (std::size_t f = 0; f < footprints.size(); ++f) {
      const BBox b = plan_box(footprints[f]);
      for (long i = cell_of(b.min.x()); i <= cell_of(b.max.x()); ++i)
        for (long j = cell_of(b.min.y()); j <= cell_of(b.max.y()); ++j) cells_[{i, j}].push_back(f);
    }
  }
  /// True when (x, y) lies inside a footprint other than `self`.
  bool inside_other(double x, double y, std::size_t self) const {
    const auto it = cells_.find({cell_of(x), cell_of(y)});
    if (it == cells_.end()) return false;
    for (std::size_t f : it->second)
      if (f != self && inside_footprint(x, y, footprints_[f])) return true;
    return false;
  }

 private:
  long cell_of(double v) const { return static_cast<long>(std::floor(v / cell_)); }
  const std::vector<Footprint>& footprints_;
  double cell_;
  std::map<std::pair<long, long>, std::vector<std::size_t>> cells_;
};

/// Why a building cannot be planned whole, or "": in a survey, a building (its footprint's or its group's cells'
/// bounding box, local) that reaches a side of the loaded region (the tile and its margin) with more survey
/// beyond it may go on past the points loaded.
std::string cut_by_margin(const BBox& cells, const PointCloud& tile, const CityParams& params, const SurveyRegion& region) {
  if (!region.several()) return "";
  const Vec3 o = tile.origin;
  const double near = 2 * params.component_cell;
  const double gaps[4] = {cells.min.x() + o.x() - region.loaded.min.x(), region.loaded.max.x() - (cells.max.x() + o.x()),
                          cells.min.y() + o.y() - region.loaded.min.y(), region.loaded.max.y() - (cells.max.y() + o.y())};
  for (int side = 0; side < 4; ++side)
    if (gaps[side] <= near && survey_beyond(region.loaded, side, near, region.extents)) {
      char buf[200];
      std::snprintf(buf, sizeof buf, "the building reaches past the %g %s around its tile that were read (a larger --tile-margin)",
                    params.tile_margin, params.length_unit.c_str());
      return buf;
    }
  return "";
}

/// Whether point i is the tile's own (not a neighbour's within the margin): only those count as unused.
bool is_own_point(std::size_t i, const SurveyRegion& region) { return !region.several() || i < region.own_points; }

/// Whether the tile plans the building whose bounding box's centre is `centre` (local coordinates). Alone:
/// the centre lies in the tile's bounding box. In a survey: the tile owns the centre (survey.h), so that a
/// building on two tiles is planned once.
/// A tile planned block by block (survey.h TileBlocks): a block plans, of the tile's buildings, those whose
/// centre it owns; every block computes the same centre (local + origin), so each building has one block.
bool tile_plans(const Vec3& centre, const Vec3& origin, const BBox& tile_box, const SurveyRegion& region) {
  const Vec2 global = centre.head<2>() + origin.head<2>();
  if (region.block >= 0 && region.blocks.of(global) != region.block) return false;
  if (!region.several())
    return centre.x() >= tile_box.min.x() && centre.x() <= tile_box.max.x() && centre.y() >= tile_box.min.y() &&
           centre.y() <= tile_box.max.y();
  return owning_tile(global, region.extents, region.edge_tolerance) == region.self;
}

/// Step 4 for a footprint with fewer points than a run needs (DECISIONS #165): under min_prism_points no model
/// (listed as no-points), else its footprint prism. Why: a user of a city expects every footprint with points
/// modelled (roofer extrudes every footprint); before, AHN3_13112 (43 points, 2.8 m²) failed and the whole run
/// exited 1.
void few_points_rule(const CityParams& params, TileBuilding& b) {
  const std::size_t n = b.points.size();
  if (n >= params.min_building_points) return;
  if (n < params.min_prism_points) {
    b.no_points = std::to_string(n) + " building points in the footprint (fewer than min_prism_points " +
                  std::to_string(params.min_prism_points) + "): no model";
    return;
  }
  b.footprint_prism = true;
}

void buildings_from_footprints(const PointCloud& tile, const std::vector<FootprintFeature>& features,
                               const CityParams& params, const SurveyRegion& region, CityTile& out) {
  out.buildings_from = "footprints";
  const Vec2 origin = tile.origin.head<2>();
  const BBox tile_box = region.left_out.extent.valid() ? region.left_out.extent : bounding_box(tile.points);
  std::vector<Footprint> local;
  for (const FootprintFeature& f : features) local.push_back(shifted(f.footprint, -origin));
  const FootprintIndex others(local, 20.0);
  std::vector<std::size_t> building_ids, ground_ids;
  building_ids.reserve(static_cast<std::size_t>(std::count(out.building.begin(), out.building.end(), 1)));
  ground_ids.reserve(static_cast<std::size_t>(std::count(out.ground.begin(), out.ground.end(), 1)));
  for (std::size_t i = 0; i < tile.size(); ++i) {
    if (out.building[i]) building_ids.push_back(i);
    if (out.ground[i]) ground_ids.push_back(i);
  }
  const PlanIndex building_index(tile.points, building_ids, 4.0), ground_index(tile.points, ground_ids, 4.0);
  std::vector<char> used(tile.size(), 0);
  for (std::size_t f = 0; f < features.size(); ++f) {
    const BBox box = plan_box(local[f]);
    const Vec3 centre = box.center();
    if (!tile_plans(centre, tile.origin, tile_box, region)) {
      ++out.footprints_elsewhere;
      continue;
    }
    TileBuilding b;
    b.id = features[f].id;
    b.footprint = features[f].footprint;
    b.attributes = features[f].attributes;
    b.area = footprint_area(local[f]);
    const double reach = params.buffer;
    for (std::size_t i : building_index.query(box.min.x() - reach, box.min.y() - reach, box.max.x() + reach, box.max.y() + reach)) {
      const Vec3& p = tile.points[i];
      const bool take = inside_footprint(p.x(), p.y(), local[f]) ||
                        (distance_to_footprint(p.head<2>(), local[f]) <= params.buffer && !others.inside_other(p.x(), p.y(), f));
      if (!take) continue;
      b.points.push_back(i);
      used[i] = 1;
    }
    std::vector<Vec3> ground;
    const double far = params.ring_max_outer;
    for (std::size_t i : ground_index.query(box.min.x() - far, box.min.y() - far, box.max.x() + far, box.max.y() + far))
      ground.push_back(tile.points[i]);
    ring_ground_height(ground, local[f], params, b);
    if (!std::isnan(b.ground_z)) b.ground_z += tile.origin.z();
    b.failure = cut_by_margin(box, tile, params, region);
    if (b.failure.empty()) few_points_rule(params, b);
    out.buildings.push_back(std::move(b));
  }
  for (std::size_t i : building_ids) out.unused_building_points += !used[i] && is_own_point(i, region);
  out.unused_building_points += region.left_out.own_building;  // left out: near no footprint
}

// ------------------------------------------------------------------------------------- step 2: groups

/// A plan grid over the building points: cell of each point, occupied cells.
struct PlanGrid {
  double x0 = 0, y0 = 0, cell = 1;
  int nx = 0, ny = 0;
  std::vector<int> label;  ///< per cell: -1 empty, -2 occupied (unlabelled), >= 0 its group
  std::size_t at(int i, int j) const { return static_cast<std::size_t>(i) + static_cast<std::size_t>(nx) * j; }
  int cell_i(double x) const { return std::clamp(static_cast<int>(std::floor((x - x0) / cell)), 0, nx - 1); }
  int cell_j(double y) const { return std::clamp(static_cast<int>(std::floor((y - y0) / cell)), 0, ny - 1); }
};

/// Labels the 8-connected groups of occupied cells in raster order (row j from the south, cell i from the
/// west); returns the cells of each group.
std::vector<std::vector<std::size_t>> label_groups(PlanGrid& g) {
  std::vector<std::vector<std::size_t>> groups;
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      if (g.label[g.at(i, j)] != -2) continue;
      const int id = static_cast<int>(groups.size());
      groups.emplace_back();
      std::deque<std::pair<int, int>> queue{{i, j}};
      g.label[g.at(i, j)] = id;
      while (!queue.empty()) {
        const auto [a, b] = queue.front();
        queue.pop_front();
        groups.back().push_back(g.at(a, b));
        for (int da = -1; da <= 1; ++da)
          for (int db = -1; db <= 1; ++db) {
            const int u = a + da, v = b + db;
            if (u < 0 || v < 0 || u >= g.nx || v >= g.ny || g.label[g.at(u, v)] != -2) continue;
            g.label[g.at(u, v)] = id;
            queue.push_back({u, v});
          }
      }
      std::sort(groups.back().begin(), groups.back().end());
    }
  return groups;
}

/// The groups of the occupied cells after an opening of the occupancy by one cell (erosion, then dilation,
/// 3 x 3): a link thinner than three cells (points in a garden between two rows of houses, a fence, a tree's
/// planar patches) does not join two groups. The occupied cells the opening removed go to the group they
/// reach first through occupied cells (breadth first from the opened groups, in raster order); the others
/// (a thin structure on its own) to none. Labels in g.label (-1 none); returns each group's cells.
std::vector<std::vector<std::size_t>> open_and_label(PlanGrid& g) {
  const std::vector<int> occupied = g.label;  // -2 occupied, -1 empty
  auto is_occupied = [&](int i, int j) { return i >= 0 && j >= 0 && i < g.nx && j < g.ny && occupied[g.at(i, j)] == -2; };
  std::vector<char> eroded(occupied.size(), 0);
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      bool all = true;
      for (int dj = -1; dj <= 1 && all; ++dj)
        for (int di = -1; di <= 1 && all; ++di) all = is_occupied(i + di, j + dj);
      eroded[g.at(i, j)] = all;
    }
  std::fill(g.label.begin(), g.label.end(), -1);
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i)
      for (int dj = -1; dj <= 1; ++dj)
        for (int di = -1; di <= 1; ++di) {
          const int a = i + di, b = j + dj;
          if (a >= 0 && b >= 0 && a < g.nx && b < g.ny && eroded[g.at(a, b)]) g.label[g.at(i, j)] = -2;
        }
  label_groups(g);
  std::deque<std::size_t> queue;
  for (std::size_t c = 0; c < g.label.size(); ++c)
    if (g.label[c] >= 0) queue.push_back(c);
  while (!queue.empty()) {
    const std::size_t c = queue.front();
    queue.pop_front();
    const int i = static_cast<int>(c % g.nx), j = static_cast<int>(c / g.nx);
    for (int dj = -1; dj <= 1; ++dj)
      for (int di = -1; di <= 1; ++di) {
        if (!is_occupied(i + di, j + dj)) continue;
        const std::size_t n = g.at(i + di, j + dj);
        if (g.label[n] >= 0) continue;
        g.label[n] = g.label[c];
        queue.push_back(n);
      }
  }
  int groups = 0;
  for (int l : g.label) groups = std::max(groups, l + 1);
  std::vector<std::vector<std::size_t>> cells(static_cast<std::size_t>(groups));
  for (std::size_t c = 0; c < g.label.size(); ++c)
    if (g.label[c] >= 0) cells[static_cast<std::size_t>(g.label[c])].push_back(c);
  return cells;
}

/// Distance from p to the group's cells (each a square); negative inside one. Only the group's border
/// cells (those with a neighbour outside the group) can be nearest from outside.
double distance_to_cells(const Vec2& p, const PlanGrid& g, int id, const std::vector<std::size_t>& border) {
  const int i = static_cast<int>(std::floor((p.x() - g.x0) / g.cell)), j = static_cast<int>(std::floor((p.y() - g.y0) / g.cell));
  if (i >= 0 && j >= 0 && i < g.nx && j < g.ny && g.label[g.at(i, j)] == id) return -1.0;
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t c : border) {
    const double cx = g.x0 + (static_cast<double>(c % g.nx) + 0.5) * g.cell, cy = g.y0 + (static_cast<double>(c / g.nx) + 0.5) * g.cell;
    const double dx = std::max(0.0, std::abs(p.x() - cx) - 0.5 * g.cell), dy = std::max(0.0, std::abs(p.y() - cy) - 0.5 * g.cell);
    best = std::min(best, std::hypot(dx, dy));
  }
  return best;
}

/// Step 5: why a group of building points found by the rule is vegetation, or "" when it may be a building.
/// Why: a crown lets some of its points through step 1's per-point bound (a patch of leaves can look flat),
/// but they stay scattered as a whole, while a roof's points are flat but for its ridges and edges.
std::string vegetation_reason(const std::vector<std::size_t>& members, const CityTile& tile, const CityParams& params) {
  if (tile.variation.empty()) return "";  // the file's class 6: trusted
  std::vector<double> v;
  for (std::size_t i : members)
    if (!std::isnan(tile.variation[i])) v.push_back(tile.variation[i]);
  if (v.empty()) return "";
  const double m = median(v);
  if (m <= params.max_group_variation) return "";
  char buf[200];
  std::snprintf(buf, sizeof buf, "vegetation: the median surface variation of its points is %.3f (> %g)", m,
                params.max_group_variation);
  return buf;
}

void buildings_from_groups(const PointCloud& tile, const CityParams& params, const SurveyRegion& region, CityTile& out) {
  out.buildings_from = "connected groups of building points in plan";
  std::vector<std::size_t> building_ids, ground_ids;
  BBox box;
  for (std::size_t i = 0; i < tile.size(); ++i) {
    if (out.building[i]) {
      building_ids.push_back(i);
      box.extend(tile.points[i]);
    }
    if (out.ground[i]) ground_ids.push_back(i);
  }
  out.unused_building_points += region.left_out.own_building;  // none: groups keep every building point
  if (building_ids.empty()) return;
  PlanGrid g;
  g.cell = params.component_cell;
  g.x0 = box.min.x();
  g.y0 = box.min.y();
  g.nx = static_cast<int>(std::floor((box.max.x() - g.x0) / g.cell)) + 1;
  g.ny = static_cast<int>(std::floor((box.max.y() - g.y0) / g.cell)) + 1;
  if (static_cast<double>(g.nx) * g.ny > 4e8) bad("the plan grid needs more than 4e8 cells (a larger --component-cell)");
  g.label.assign(static_cast<std::size_t>(g.nx) * g.ny, -1);
  for (std::size_t i : building_ids) g.label[g.at(g.cell_i(tile.points[i].x()), g.cell_j(tile.points[i].y()))] = -2;
  const std::vector<std::vector<std::size_t>> groups = open_and_label(g);
  std::vector<std::vector<std::size_t>> members(groups.size());
  for (std::size_t i : building_ids) {
    const int label = g.label[g.at(g.cell_i(tile.points[i].x()), g.cell_j(tile.points[i].y()))];
    if (label >= 0) members[static_cast<std::size_t>(label)].push_back(i);
    else out.unused_building_points += is_own_point(i, region);
  }
  const PlanIndex ground_index(tile.points, ground_ids, 4.0);
  int number = 0;
  for (std::size_t id = 0; id < groups.size(); ++id) {
    const double area = static_cast<double>(groups[id].size()) * g.cell * g.cell;
    BBox cells;
    for (std::size_t c : groups[id]) {
      const int i = static_cast<int>(c % g.nx), j = static_cast<int>(c / g.nx);
      cells.extend(Vec3(g.x0 + i * g.cell, g.y0 + j * g.cell, 0));
      cells.extend(Vec3(g.x0 + (i + 1) * g.cell, g.y0 + (j + 1) * g.cell, 0));
    }
    if (region.several() && !tile_plans(cells.center(), tile.origin, cells, region)) {  // another tile of the survey plans it
      ++out.groups_elsewhere;
      continue;
    }
    std::size_t own = 0;
    for (std::size_t i : members[id]) own += is_own_point(i, region);
    if (area < params.min_building_area || members[id].size() < params.min_building_points) {
      out.unused_building_points += own;  // not a building: a tree's remnant, a car, a shed's corner
      ++out.small_groups;
      continue;
    }
    TileBuilding b;
    char name[32];
    std::snprintf(name, sizeof name, "b%04d", ++number);
    b.id = name;
    b.area = area;
    b.points = members[id];
    b.failure = cut_by_margin(cells, tile, params, region);
    std::vector<std::size_t> border;
    for (std::size_t c : groups[id]) {
      const int i = static_cast<int>(c % g.nx), j = static_cast<int>(c / g.nx);
      bool inner = i > 0 && j > 0 && i + 1 < g.nx && j + 1 < g.ny;
      for (int d = 0; inner && d < 4; ++d) {
        const int u = i + (d == 0) - (d == 1), v = j + (d == 2) - (d == 3);
        inner = g.label[g.at(u, v)] == static_cast<int>(id);
      }
      if (!inner) border.push_back(c);
    }
    const double far = params.ring_max_outer;
    std::vector<double> z, distance;
    for (std::size_t i : ground_index.query(cells.min.x() - far, cells.min.y() - far, cells.max.x() + far, cells.max.y() + far)) {
      z.push_back(tile.points[i].z());
      distance.push_back(distance_to_cells(tile.points[i].head<2>(), g, static_cast<int>(id), border));
    }
    ring_from_distances(z, distance, params, "group", b);
    if (!std::isnan(b.ground_z)) b.ground_z += tile.origin.z();
    b.not_building = vegetation_reason(b.points, out, params);
    out.vegetation_groups += !b.not_building.empty();
    out.buildings.push_back(std::move(b));
  }
}

void check_params(const CityParams& p) {
  if (!(p.buffer >= 0) || !(p.component_cell > 0) || !(p.min_building_area >= 0) || !(p.ring_inner >= 0) ||
      !(p.ring_outer > p.ring_inner) || !(p.ring_max_outer >= p.ring_outer) || p.ring_min_points == 0 || !(p.tile_margin >= 0) ||
      p.planar_neighbours < 3 || !(p.max_surface_variation >= 0) || !(p.max_group_variation >= 0) ||
      !std::isfinite(p.ring_max_outer + p.buffer))
    bad("parameters: buffer >= 0, component cell > 0, 0 <= ring inner < ring outer <= ring max, ring points >= 1, "
        "planar neighbours >= 3, surface variations >= 0, tile margin >= 0 required");
}

}  // namespace

const char* class_source_name(ClassSource s) {
  switch (s) {
    case ClassSource::Auto: return "auto";
    case ClassSource::File: return "file";
    case ClassSource::Filter: return "filter";
  }
  return "?";
}

ClassSource parse_class_source(const std::string& name) {
  for (ClassSource s : {ClassSource::Auto, ClassSource::File, ClassSource::Filter})
    if (name == class_source_name(s)) return s;
  bad("unknown --classes '" + name + "' (auto, file, filter)");
}

bool tile_plans_footprint(const Footprint& footprint, const Vec3& origin, const BBox& tile_box, const SurveyRegion& region) {
  return tile_plans(plan_box(shifted(footprint, -origin.head<2>())).center(), origin, tile_box, region);
}

Vec2 footprint_plan_centre(const Footprint& footprint, const Vec3& origin) {
  return plan_box(shifted(footprint, -origin.head<2>())).center().head<2>() + origin.head<2>();
}

double distance_to_footprint(const Vec2& p, const Footprint& footprint) {
  double best = std::numeric_limits<double>::infinity();
  auto ring_distance = [&](const std::vector<Vec2>& ring) {
    for (std::size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++) best = std::min(best, segment_distance(p, ring[j], ring[i]));
  };
  for (const FootprintPolygon& poly : footprint) {
    ring_distance(poly.outer);
    for (const auto& h : poly.holes) ring_distance(h);
  }
  return best;
}

double footprint_area(const Footprint& footprint) {
  auto ring_area = [](const std::vector<Vec2>& r) { return std::abs(0.5 * twice_ring_area(r)); };
  double area = 0;
  for (const FootprintPolygon& p : footprint) {
    area += ring_area(p.outer);
    for (const auto& h : p.holes) area -= ring_area(h);
  }
  return area;
}

void ring_ground_height(const std::vector<Vec3>& ground, const Footprint& footprint, const CityParams& params, TileBuilding& b) {
  std::vector<double> z, distance;
  for (const Vec3& p : ground) {
    z.push_back(p.z());
    distance.push_back(inside_footprint(p.x(), p.y(), footprint) ? -1.0 : distance_to_footprint(p.head<2>(), footprint));
  }
  ring_from_distances(z, distance, params, "footprint", b);
}

CityParams in_tile_units(const CityParams& params, double metres_per_unit, const std::string& unit_name) {
  if (!(metres_per_unit > 0) || !std::isfinite(metres_per_unit)) bad("the tile's unit must be a positive length");
  CityParams p = params;
  const double k = 1.0 / metres_per_unit;
  for (double* length : {&p.smrf.cell, &p.smrf.max_window, &p.smrf.elevation_threshold, &p.min_height_above_ground, &p.buffer,
                         &p.component_cell, &p.ring_inner, &p.ring_outer, &p.ring_max_outer, &p.tile_margin})
    *length *= k;
  p.min_building_area *= k * k;
  p.length_unit = unit_name;
  return p;
}

void split_classes(const PointCloud& tile, const CityParams& params, CityTile& out, const PointsLeftOut& left_out) {
  const auto& cls = tile.attributes.classification;
  const bool use_file = params.classes != ClassSource::Filter;
  const bool ground_class =
      use_file && (left_out.ground_class || std::any_of(cls.begin(), cls.end(), [](std::uint8_t c) { return c == 2; }));
  const bool building_class =
      use_file && (left_out.building_class || std::any_of(cls.begin(), cls.end(), [](std::uint8_t c) { return c == 6; }));
  // Points left out are read by no rule below only when both classes come from the file.
  if (left_out.any() && !(ground_class && building_class))
    throw Error(Status::Internal, kCityStage, "points were left out of a tile whose ground and building points are not both the file's");
  if (params.classes == ClassSource::File && !ground_class && !building_class)
    bad("'" + tile.source + "' has no point of class 2 (ground) or 6 (building): use --classes filter (or auto)");
  out.ground.assign(tile.size(), 0);
  out.building.assign(tile.size(), 0);
  std::string ground_how, building_how;
  HeightGrid model;
  if (ground_class) {
    std::vector<Vec3> ground;
    for (std::size_t i = 0; i < tile.size(); ++i)
      if ((out.ground[i] = cls[i] == 2)) ground.push_back(tile.points[i]);
    out.ground_points = ground.size() + left_out.ground;
    ground_how = "ground = LAS class 2: " + count_text(out.ground_points) + " points";
    if (!building_class) model = ground_model_of(ground, params.smrf);
  } else {
    GroundFilterResult g = run_ground_filter(tile.points, params.smrf);
    for (std::size_t i = 0; i < tile.size(); ++i) out.ground[i] = g.ground[i];
    out.ground_points = static_cast<std::size_t>(std::count(out.ground.begin(), out.ground.end(), 1));
    char buf[200];
    std::snprintf(buf, sizeof buf, "ground by SMRF (Pingel et al. 2013; cell %g %s, slope %g, window %g %s): %zu points",
                  params.smrf.cell, params.length_unit.c_str(), params.smrf.slope, params.smrf.max_window,
                  params.length_unit.c_str(), out.ground_points);
    ground_how = buf;
    model = std::move(g.model);
  }
  if (building_class) {
    for (std::size_t i = 0; i < tile.size(); ++i) out.building[i] = cls[i] == 6;
    out.building_points = static_cast<std::size_t>(std::count(out.building.begin(), out.building.end(), 1)) + left_out.building;
    building_how = "building = LAS class 6: " + count_text(out.building_points) + " points";
  } else {
    buildings_by_rule(tile, model, params, out, building_how);
  }
  const std::size_t all = tile.size() + left_out.ground + left_out.building + left_out.other;
  out.classes = ground_how + "; " + building_how + "; " + count_text(all - out.ground_points - out.building_points) +
                " other points left out";
}

CityTile run_city_tile(const PointCloud& tile, const std::vector<FootprintFeature>* footprints, const CityParams& params,
                       const SurveyRegion& region) {
  check_params(params);
  if (tile.empty() && !region.left_out.any()) bad("the tile has no point");
  if (region.several() && (static_cast<std::size_t>(region.self) >= region.extents.size() || region.own_points > tile.size()))
    bad("survey region: its tile index or own point count is out of range");
  CityTile out;
  split_classes(tile, params, out, region.left_out);
  if (footprints) buildings_from_footprints(tile, *footprints, params, region, out);
  else buildings_from_groups(tile, params, region, out);
  return out;
}

}  // namespace hsr
