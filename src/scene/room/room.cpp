// What makes a scene a room (room.h): normals facing into the box, a ceiling over a floor, content between.
#include "scene/room/room.h"
#include "scene/scene_internal.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <unordered_set>

namespace hsr {

using scene_detail::kDeg;
using scene_detail::plan_cell;

bool normals_face_inward(const PointCloud& cloud, const RoomParams& params) {
  if (!cloud.has_normals() || cloud.empty()) return false;
  const BBox box = bounding_box(cloud.points);
  const double slab = params.inward_slab * (box.max - box.min).maxCoeff();
  const double min_along = params.inward_side_cos;
  // Votes per side: 0..3 the lateral sides (x-, x+, y-, y+), 4 the top. The bottom is left out: the
  // ground under a building scanned from outside faces up, into the box.
  std::array<long, 5> inward{}, outward{};
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Vec3& p = cloud.points[i];
    const Vec3& n = cloud.normals[i];
    for (int s = 0; s < 5; ++s) {
      const int axis = s < 4 ? s / 2 : 2;
      const bool high = s == 4 || s % 2 == 1;
      const double d = high ? box.max[axis] - p[axis] : p[axis] - box.min[axis];
      const double along = high ? n[axis] : -n[axis];  // the normal along the side's outward axis
      if (d > slab || std::abs(along) < min_along * n.norm()) continue;
      (along < 0 ? inward : outward)[static_cast<std::size_t>(s)] += 1;
    }
  }
  const double lined = params.inward_lined_share * static_cast<double>(cloud.size());
  auto faces_in = [&](int s) {
    const auto k = static_cast<std::size_t>(s);
    return static_cast<double>(inward[k] + outward[k]) >= lined &&
           static_cast<double>(inward[k]) >= params.inward_ratio * static_cast<double>(outward[k]);
  };
  int sides = 0;
  for (int s = 0; s < 4; ++s) sides += faces_in(s);
  return faces_in(4) && sides >= params.inward_min_sides;
}

RoomEnds room_ends(const SceneStructure& structure, const std::vector<bool>& enclosing, double tolerance,
                   double level_deg) {
  RoomEnds ends;
  const double zmin = structure.bbox.min.z(), zmax = structure.bbox.max.z();
  for (std::size_t i = 0; i < structure.planes.size() && i < enclosing.size(); ++i) {
    const DetectedPlane& plane = structure.planes[i];
    if (!enclosing[i] || std::abs(plane.plane.normal.z()) < std::cos(level_deg * kDeg)) continue;
    const bool top = plane.centroid.z() >= zmax - tolerance, bottom = plane.centroid.z() <= zmin + tolerance;
    int* slot = top ? &ends.ceiling : bottom ? &ends.floor : nullptr;
    if (slot && (*slot < 0 || structure.planes[*slot].inliers.size() < plane.inliers.size())) *slot = static_cast<int>(i);
  }
  return ends;
}

RoomEvidence room_evidence(const PointCloud& cloud, const SceneStructure& structure, const std::vector<bool>& enclosing,
                           double tolerance, double level_deg, const RoomParams& params) {
  RoomEvidence out;
  const auto [floor, ceiling] = room_ends(structure, enclosing, tolerance, level_deg);
  if (ceiling < 0 || floor < 0 || ceiling == floor) return out;
  const double cell = params.evidence_cell * structure.spacing;
  const Vec2 origin = structure.bbox.min.head<2>();
  std::unordered_set<std::int64_t> floor_cells, ceiling_cells;
  for (int k : structure.planes[floor].inliers) floor_cells.insert(plan_cell(cloud.points[k], origin, cell));
  for (int k : structure.planes[ceiling].inliers) ceiling_cells.insert(plan_cell(cloud.points[k], origin, cell));
  std::size_t over = 0;
  for (std::int64_t c : ceiling_cells) over += floor_cells.count(c);
  const double top = structure.planes[ceiling].centroid.z(), bottom = structure.planes[floor].centroid.z();
  std::vector<const Plane*> enclosure;  // a hall has six among hundreds of planes: not looked up per point
  for (std::size_t i = 0; i < structure.planes.size(); ++i)
    if (enclosing[i]) enclosure.push_back(&structure.planes[i].plane);
  std::size_t beyond = 0, content = 0;
  for (const Vec3& p : cloud.points) {
    if (p.z() > top + tolerance || p.z() < bottom - tolerance) {
      ++beyond;
      continue;
    }
    content += std::none_of(enclosure.begin(), enclosure.end(),
                            [&](const Plane* e) { return std::abs(e->signed_distance(p)) <= tolerance; });
  }
  const double n = static_cast<double>(cloud.size());
  out.ceiling_over_floor =
      static_cast<double>(over) >= params.floor_under_ceiling_share * static_cast<double>(ceiling_cells.size()) &&
      static_cast<double>(beyond) < params.stray_share * n;
  out.content_share = static_cast<double>(content) / n;
  return out;
}

bool is_a_room(const PointCloud& cloud, const SceneStructure& structure, bool building,
               const std::vector<bool>& enclosing, bool scanned_from_inside, double tolerance, double level_deg,
               const RoomParams& params) {
  if (building) return false;
  if (cloud.has_normals() && !scanned_from_inside) return false;
  const RoomEvidence room = room_evidence(cloud, structure, enclosing, tolerance, level_deg, params);
  return room.ceiling_over_floor && (cloud.has_normals() || room.content_share > params.min_content_share);
}

}  // namespace hsr
