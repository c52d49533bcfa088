// The outline prism (building.h BuildingParams::outline_prism, DECISIONS #135): a building scan where detection
// found no plane still gets a model, a block over its points' outline.
#include "scene/building/building.h"

#include "core/footprint.h"
#include "core/hull2d.h"
#include "core/spacing.h"
#include "core/stats.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace hsr {

namespace {

/// The roof points: those above the lowest gap of at least `gap` in the sorted heights, when at least 3 lie
/// above it; else every point (nothing is seen under the roof). Why the lowest gap: a wall's foot or the ground
/// beside the building lies under the roof with nothing between (as ground source 5's under_roof_gap), while
/// a raised roof part (Vaihingen_00026's ridge over its flat roof) rises from the roof in small steps.
std::vector<bool> roof_points(const PointCloud& cloud, double gap, bool* found_gap) {
  std::vector<double> z;
  z.reserve(cloud.size());
  for (const Vec3& p : cloud.points) z.push_back(p.z());
  std::sort(z.begin(), z.end());
  double cut = -std::numeric_limits<double>::infinity();
  *found_gap = false;
  for (std::size_t i = 1; i + 2 < z.size(); ++i)  // at least 3 points above the gap
    if (z[i] - z[i - 1] >= gap) {
      cut = 0.5 * (z[i] + z[i - 1]);
      *found_gap = true;
      break;
    }
  std::vector<bool> roof(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) roof[i] = cloud.points[i].z() > cut;
  return roof;
}

/// The ground under the prism, from building.h's sources in order, the roof points standing for the roof and
/// wall inliers: given; the raster's median under them; the classified ground points within ground_ring r of one
/// in plan (their median, at least ground_min_points); the lowest point when a gap lies under the roof; else
/// assumed_wall_height under the lowest roof point (with the note that says so).
void prism_ground(const PointCloud& cloud, double r, const BuildingParams& params, const SceneGround& ground,
                  bool found_gap, OutlinePrism& out) {
  const auto use = [&](GroundSource src, double z) {
    out.ground_source = src;
    out.ground_z = z;
  };
  if (!std::isnan(params.ground_z)) return use(GroundSource::Given, params.ground_z);
  if (ground.raster) {
    std::vector<double> z;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      const Vec3 g = cloud.points[i] + ground.origin;
      double h;
      if (out.roof[i] && ground.raster->sample(g.x(), g.y(), h)) z.push_back(h - ground.origin.z());
    }
    if (!z.empty()) return use(GroundSource::Raster, quantile(std::move(z), 0.5));
  }
  if (!ground.points.empty()) {
    const double ring = params.ground_ring * r;
    std::vector<double> z;
    for (const Vec3& g : ground.points)
      for (std::size_t i = 0; i < cloud.size(); ++i)
        if (out.roof[i] && (cloud.points[i].head<2>() - g.head<2>()).norm() <= ring) {
          z.push_back(g.z());
          break;
        }
    if (z.size() >= static_cast<std::size_t>(params.ground_min_points))
      return use(GroundSource::ClassifiedPoints, quantile(std::move(z), 0.5));
  }
  double lowest = std::numeric_limits<double>::infinity(), lowest_roof = lowest;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    lowest = std::min(lowest, cloud.points[i].z());
    if (out.roof[i]) lowest_roof = std::min(lowest_roof, cloud.points[i].z());
  }
  if (found_gap) return use(GroundSource::LowestPoints, lowest);
  use(GroundSource::Assumed, lowest_roof - params.assumed_wall_height);
  std::ostringstream note;
  note << "nothing in the scan lies under its roof and no ground is known: the walls are assumed "
       << params.assumed_wall_height << " tall (one storey); give the ground with --ground-z Z or --ground DTM.tif";
  out.ground_note = note.str();
}

/// The prism over `outline` (counter-clockwise, no collinear vertices) from z0 to z1 > z0: a closed, outward
/// oriented polyhedron (roof up, bottom down, each wall's normal the outline's outward side).
PolygonMesh prism(const std::vector<Vec2>& outline, double z0, double z1) {
  PolygonMesh mesh;
  const auto n = static_cast<std::uint32_t>(outline.size());
  for (const Vec2& q : outline) mesh.vertices.emplace_back(q.x(), q.y(), z0);
  for (const Vec2& q : outline) mesh.vertices.emplace_back(q.x(), q.y(), z1);
  std::vector<std::uint32_t> top, bottom;
  for (std::uint32_t i = 0; i < n; ++i) {
    top.push_back(n + i);
    bottom.push_back(n - 1 - i);
  }
  mesh.faces.push_back(top);
  mesh.face_class.push_back(FaceClass::Roof);
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::uint32_t j = (i + 1) % n;
    mesh.faces.push_back({i, j, n + j, n + i});
    mesh.face_class.push_back(FaceClass::Wall);
  }
  mesh.faces.push_back(bottom);
  mesh.face_class.push_back(FaceClass::Ground);
  return mesh;
}

/// A footprint ring as prism() wants it: counter-clockwise, without repeated or collinear vertices (exactly
/// collinear: such a vertex would join two coplanar walls).
std::vector<Vec2> prism_outline(std::vector<Vec2> ring) {
  if (twice_ring_area(ring) < 0) std::reverse(ring.begin(), ring.end());
  bool changed = true;
  while (changed && ring.size() >= 3) {
    changed = false;
    for (std::size_t i = 0; i < ring.size(); ++i) {
      const Vec2& a = ring[(i + ring.size() - 1) % ring.size()];
      const Vec2& b = ring[i];
      const Vec2& c = ring[(i + 1) % ring.size()];
      if (b == a || (b - a).x() * (c - b).y() - (b - a).y() * (c - b).x() == 0.0) {
        ring.erase(ring.begin() + static_cast<std::ptrdiff_t>(i));
        changed = true;
        break;
      }
    }
  }
  return ring;
}

}  // namespace

OutlinePrism outline_prism(const PointCloud& cloud, double spacing, const BuildingParams& params,
                           const SceneGround& ground, const std::vector<Vec2>* given) {
  OutlinePrism out;
  bool found_gap = false;
  out.roof = roof_points(cloud, params.under_roof_gap * spacing, &found_gap);
  prism_ground(cloud, spacing, params, ground, found_gap, out);
  std::vector<double> heights;
  std::vector<Vec2> plan;
  for (std::size_t i = 0; i < cloud.size(); ++i)
    if (out.roof[i]) {
      heights.push_back(cloud.points[i].z());
      plan.push_back(cloud.points[i].head<2>());
    }
  out.under_roof_points = cloud.size() - plan.size();
  if (heights.empty()) return out;
  out.roof_z = quantile(std::move(heights), params.outline_prism_roof_quantile);
  if (!given) out.beyond_hull = edge_beyond_outermost_points(plan_spacing(plan), params.outline_prism_beyond_hull);
  const std::vector<Vec2> outline = given ? prism_outline(*given) : offset_convex(convex_hull_2d(plan), out.beyond_hull);
  if (outline.size() < 3 || !(out.roof_z > out.ground_z)) return out;
  out.mesh = prism(outline, out.ground_z, out.roof_z);
  return out;
}

}  // namespace hsr
