// A room's structure (room.h room_structure): the pieces of its floor, walls and ceiling that the furniture's
// shadows cut off join their plane, and so do the pieces of a piece of furniture's face (DECISIONS #71).
#include "scene/room/room.h"
#include "scene/scene_internal.h"

#include "core/error.h"
#include "core/kd_tree.h"

#include <algorithm>
#include <cmath>

namespace hsr {

using scene_detail::join_plane;
using scene_detail::kDeg;
using scene_detail::kStage;

namespace {

/// Whether plane `b` lies on plane `a`: its inliers within `r` of a on average, the normals within
/// `max_angle_deg` (either way).
bool lies_on(const PointCloud& cloud, const Plane& a, const DetectedPlane& b, double r, double max_angle_deg) {
  if (std::abs(a.normal.dot(b.plane.normal)) < std::cos(max_angle_deg * kDeg)) return false;
  double sum = 0;
  for (int i : b.inliers) sum += std::abs(a.signed_distance(cloud.points[static_cast<std::size_t>(i)]));
  return sum <= r * static_cast<double>(b.inliers.size());
}

/// room_structure's furniture rule: within each piece of furniture (points off the enclosure linked within the
/// alpha radius), a plane that lies on a larger one of the piece and faces the same way (outward normals within
/// max_angle_deg) joins it, largest first. Updates head, keep and s as room_structure's enclosure rule does;
/// returns how many joined.
std::size_t join_faces_of_pieces(const PointCloud& cloud, SceneStructure& s, const std::vector<bool>& enclosure,
                                 const std::vector<Vec3>& outward, double max_angle_deg, double piece_link,
                                 std::vector<int>& head, std::vector<bool>& keep) {
  const auto plane_of = [&](std::size_t i) {  // a point's plane, after the joins so far
    const int k = s.point_plane[i];
    return k >= 0 && head[static_cast<std::size_t>(k)] >= 0 ? head[static_cast<std::size_t>(k)] : k;
  };
  std::vector<int> off;  // the points on no enclosing plane
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const int k = plane_of(i);
    if (k < 0 || !enclosure[static_cast<std::size_t>(k)]) off.push_back(static_cast<int>(i));
  }
  const double link = s.alpha_radius > 0 ? s.alpha_radius : piece_link * s.spacing;
  std::size_t joined = 0;
  for (const std::vector<int>& piece : linked_groups(cloud.points, off, link)) {
    std::vector<int> planes;
    for (int p : piece)
      if (plane_of(static_cast<std::size_t>(p)) >= 0) planes.push_back(plane_of(static_cast<std::size_t>(p)));
    std::sort(planes.begin(), planes.end());
    planes.erase(std::unique(planes.begin(), planes.end()), planes.end());
    std::stable_sort(planes.begin(), planes.end(), [&](int x, int y) {
      return s.planes[static_cast<std::size_t>(x)].inliers.size() > s.planes[static_cast<std::size_t>(y)].inliers.size();
    });
    for (std::size_t i = 0; i < planes.size(); ++i) {
      const std::size_t a = static_cast<std::size_t>(planes[i]);
      if (head[a] >= 0 && head[a] != static_cast<int>(a)) continue;  // joined another already
      const Plane plane = s.planes[a].plane;  // the test is against a's own plane and size, as for the enclosure
      const std::size_t size = s.planes[a].inliers.size();
      for (std::size_t j = i + 1; j < planes.size(); ++j) {
        const std::size_t b = static_cast<std::size_t>(planes[j]);
        if (head[b] >= 0 || s.planes[b].inliers.size() >= size) continue;
        if (outward[a].dot(outward[b]) < std::cos(max_angle_deg * kDeg)) continue;  // a thin panel's two faces
        if (!lies_on(cloud, plane, s.planes[b], s.spacing, max_angle_deg)) continue;
        head[a] = static_cast<int>(a);
        head[b] = static_cast<int>(a);
        keep[b] = false;
        join_plane(s.planes[a], s.planes[b]);
        ++joined;
      }
    }
  }
  return joined;
}

}  // namespace

RoomStructure room_structure(const PointCloud& cloud, const SceneStructure& structure,
                             const std::vector<bool>& enclosure, double max_angle_deg,
                             const std::vector<Vec3>& outward, const RoomParams& params) {
  if (enclosure.size() != structure.planes.size() || !(outward.empty() || outward.size() == structure.planes.size()))
    throw Error(Status::Internal, kStage, "room_structure: one enclosure flag (and outward normal) per plane expected");
  RoomStructure out;
  SceneStructure s = structure;
  std::vector<int> head(s.planes.size(), -1);
  std::vector<bool> keep(s.planes.size(), true);
  // Largest enclosing planes first: a piece joins the largest plane it lies on.
  std::vector<std::size_t> order;
  for (std::size_t a = 0; a < s.planes.size(); ++a)
    if (enclosure[a]) order.push_back(a);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) {
    return s.planes[x].inliers.size() > s.planes[y].inliers.size();
  });
  for (std::size_t a : order) {
    if (head[a] >= 0) continue;
    // The test is against a's own plane and size, not as the pieces joined move them.
    const Plane plane = s.planes[a].plane;
    const std::size_t size = s.planes[a].inliers.size();
    for (std::size_t b = 0; b < s.planes.size(); ++b) {
      if (b == a || head[b] >= 0 || s.planes[b].inliers.size() >= size) continue;
      if (!lies_on(cloud, plane, s.planes[b], s.spacing, max_angle_deg)) continue;
      head[a] = static_cast<int>(a);
      head[b] = static_cast<int>(a);
      keep[b] = false;
      join_plane(s.planes[a], s.planes[b]);
      ++out.joined;
    }
  }
  if (!outward.empty()) {
    out.joined_faces = join_faces_of_pieces(cloud, s, enclosure, outward, max_angle_deg, params.piece_link, head, keep);
    out.joined += out.joined_faces;
  }
  for (std::size_t k = 0; k < keep.size(); ++k)
    if (keep[k]) out.from.push_back(static_cast<int>(k));
  if (out.joined == 0) {
    out.structure = structure;
    return out;
  }
  scene_detail::redirect_joined(s, head);
  out.structure = subset_planes(s, keep);
  return out;
}

}  // namespace hsr
