// --dump outputs of stages 2-4 (see hulls.h): coloured point PLYs, recovered polygons, JSON fields.
#include "hulls/hulls.h"

#include "core/atomic_file.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <sstream>

namespace hsr {

namespace {

using Rgb = std::array<int, 3>;

/// Blue (0) -> white (0.5) -> red (1).
Rgb ratio_colour(double v) {
  v = std::clamp(v, 0.0, 1.0);
  auto ch = [](double x) { return static_cast<int>(std::lround(255.0 * std::clamp(x, 0.0, 1.0))); };
  if (v < 0.5) return {ch(2 * v), ch(2 * v), 255};
  return {255, ch(2 * (1 - v)), ch(2 * (1 - v))};
}

struct ColouredPoint { Vec3 p; Rgb c; };

void write_ply(const std::string& path, const Vec3& origin, const std::vector<ColouredPoint>& pts,
               const std::vector<std::vector<std::uint32_t>>& faces) {
  AtomicFile f(path, "hulls");
  std::ostream& out = f.stream();
  out << "ply\nformat ascii 1.0\ncomment hsr stage 2-4 dump\nelement vertex " << pts.size()
      << "\nproperty double x\nproperty double y\nproperty double z\n"
         "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  if (!faces.empty()) out << "element face " << faces.size() << "\nproperty list uchar int vertex_indices\n";
  out << "end_header\n" << std::setprecision(17);
  for (const ColouredPoint& q : pts) {
    const Vec3 g = q.p + origin;
    out << g.x() << ' ' << g.y() << ' ' << g.z() << ' ' << q.c[0] << ' ' << q.c[1] << ' ' << q.c[2] << '\n';
  }
  for (const auto& face : faces) {
    out << face.size();
    for (std::uint32_t v : face) out << ' ' << v;
    out << '\n';
  }
  f.commit();
}

std::vector<int> level_of_planes(const SceneStructure& s, const VisibilityResult& vis) {
  std::vector<int> level(s.planes.size(), 1);
  for (std::size_t k = 0; k < s.planes.size() && k < vis.highly.size(); ++k) level[k] = vis.highly[k] ? 1 : 2;
  return level;
}

}  // namespace

void write_hulls_dump(const PointCloud& cloud, const SceneStructure& structure, const VisibilityResult& visibility,
                      const RecoveryResult& recovery, const std::vector<ConvexPolygon>& polygons,
                      const std::string& dir) {
  std::filesystem::create_directories(dir);
  const std::size_t m = structure.planes.size();
  std::vector<ColouredPoint> by_ratio, by_level;
  const std::vector<int> level = level_of_planes(structure, visibility);
  static const Rgb level_colour[4] = {{128, 128, 128}, {40, 180, 60}, {250, 150, 20}, {220, 30, 30}};
  for (std::size_t k = 0; k < m; ++k) {
    const double v = k < visibility.ratio.size() ? visibility.ratio[k] : 0.0;
    for (int i : structure.planes[k].inliers) {
      const Vec3& p = cloud.points[static_cast<std::size_t>(i)];
      by_ratio.push_back({p, ratio_colour(v)});
      by_level.push_back({p, level_colour[level[k]]});
    }
  }
  for (const RecoveredPlane& rp : recovery.recovered)
    for (int i : rp.support) by_level.push_back({cloud.points[static_cast<std::size_t>(i)], level_colour[3]});
  write_ply((std::filesystem::path(dir) / "visibility.ply").string(), cloud.origin, by_ratio, {});
  write_ply((std::filesystem::path(dir) / "levels.ply").string(), cloud.origin, by_level, {});

  std::vector<ColouredPoint> rec_pts;
  std::vector<std::vector<std::uint32_t>> faces;
  for (const ConvexPolygon& poly : polygons) {
    if (poly.level != 3) continue;
    std::vector<std::uint32_t> face;
    for (const Vec3& v : poly.vertices) {
      face.push_back(static_cast<std::uint32_t>(rec_pts.size()));
      rec_pts.push_back({v, level_colour[3]});
    }
    faces.push_back(std::move(face));
  }
  for (const RecoveredPlane& rp : recovery.recovered)
    for (int i : rp.support) rec_pts.push_back({cloud.points[static_cast<std::size_t>(i)], {0, 0, 0}});
  write_ply((std::filesystem::path(dir) / "recovered.ply").string(), cloud.origin, rec_pts, faces);
}

nlohmann::json add_hulls_fields(nlohmann::json& planes, const SceneStructure& structure,
                                const VisibilityResult& visibility, const RecoveryResult& recovery,
                                const std::vector<ConvexPolygon>& polygons) {
  const std::size_t m = structure.planes.size();
  if (!planes.is_array()) planes = nlohmann::json::array();
  while (planes.size() < m) planes.push_back(nlohmann::json::object());
  std::vector<const ConvexPolygon*> poly_of(m + recovery.recovered.size(), nullptr);
  for (const ConvexPolygon& p : polygons)
    if (p.plane_id >= 0 && static_cast<std::size_t>(p.plane_id) < poly_of.size()) poly_of[static_cast<std::size_t>(p.plane_id)] = &p;
  for (std::size_t k = 0; k < m; ++k) {
    nlohmann::json& j = planes[k];
    if (k < visibility.ratio.size()) {
      j["visibility_ratio"] = visibility.ratio[k];
      j["visibility_ratio_sphere"] = visibility.ratio_sphere[k];
      j["highly_visible"] = static_cast<bool>(visibility.highly[k]);
      const Vec3& n = visibility.outward_normal[k];
      j["outward_normal"] = {n.x(), n.y(), n.z()};
    }
    j["level"] = poly_of[k] ? nlohmann::json(poly_of[k]->level) : nlohmann::json(nullptr);
    j["speed"] = poly_of[k] ? nlohmann::json(poly_of[k]->speed) : nlohmann::json(nullptr);
    std::size_t singular = 0;
    if (k < recovery.singular.size())
      for (bool s : recovery.singular[k]) singular += s;
    j["singular_segments"] = singular;
    j["segments"] = structure.planes[k].segments.size();
  }
  nlohmann::json rec = nlohmann::json::array();
  for (std::size_t q = 0; q < recovery.recovered.size(); ++q) {
    const RecoveredPlane& rp = recovery.recovered[q];
    nlohmann::json j;
    j["plane_id"] = m + q;
    j["normal"] = {rp.plane.normal.x(), rp.plane.normal.y(), rp.plane.normal.z()};
    j["offset"] = rp.plane.offset;
    nlohmann::json segs = nlohmann::json::array();
    for (const SegmentRef& s : rp.segments) segs.push_back({s.plane, s.segment});
    j["segments"] = segs;
    j["support"] = rp.support.size();
    j["hull_vertices"] = poly_of[m + q] ? poly_of[m + q]->vertices.size() : 0;
    rec.push_back(j);
  }
  return rec;
}

}  // namespace hsr
