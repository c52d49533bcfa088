// Stage 1 helpers: a structure restricted to some of its planes (used by the building scene mode, which
// leaves ground and clutter planes out of the later stages), and whether its planes can enclose anything.
#include "structure/structure_internal.h"

#include "core/error.h"

#include <cmath>

namespace hsr {

SceneStructure subset_planes(const SceneStructure& s, const std::vector<bool>& keep, double min_line_angle_deg) {
  if (keep.size() != s.planes.size())
    throw Error(Status::Internal, "structure", "subset_planes: keep has " + std::to_string(keep.size()) +
                                                   " entries for " + std::to_string(s.planes.size()) + " planes");
  std::vector<int> new_index(s.planes.size(), -1);
  SceneStructure out;
  out.spacing = s.spacing;
  out.alpha_radius = s.alpha_radius;
  out.bbox = s.bbox;
  out.normals = s.normals;
  out.params = s.params;
  for (std::size_t i = 0; i < s.planes.size(); ++i)
    if (keep[i]) {
      new_index[i] = static_cast<int>(out.planes.size());
      out.planes.push_back(s.planes[i]);
    }
  // Segments name their plane; keep them consistent with the new numbering.
  for (std::size_t i = 0; i < out.planes.size(); ++i)
    for (BoundarySegment& seg : out.planes[i].segments) seg.plane = static_cast<int>(i);
  out.point_plane.assign(s.point_plane.size(), -1);
  for (std::size_t p = 0; p < s.point_plane.size(); ++p)
    if (s.point_plane[p] >= 0) out.point_plane[p] = new_index[static_cast<std::size_t>(s.point_plane[p])];
  out.adjacency.assign(out.planes.size(), {});
  for (std::size_t i = 0; i < s.planes.size() && i < s.adjacency.size(); ++i) {
    if (new_index[i] < 0) continue;
    for (int j : s.adjacency[i])
      if (new_index[static_cast<std::size_t>(j)] >= 0)
        out.adjacency[static_cast<std::size_t>(new_index[i])].push_back(new_index[static_cast<std::size_t>(j)]);
  }
  structure_detail::compute_second_order(out);
  structure_detail::compute_lines(out, min_line_angle_deg);
  return out;
}

bool all_parallel(const SceneStructure& s, const std::vector<bool>& keep, double max_angle_deg) {
  const double cos_max = std::cos(max_angle_deg * M_PI / 180.0);
  const Vec3* first = nullptr;
  for (std::size_t k = 0; k < s.planes.size(); ++k) {
    if (!keep.empty() && !keep[k]) continue;
    const Vec3& n = s.planes[k].plane.normal;
    if (!first) first = &n;
    else if (std::abs(n.dot(*first)) < cos_max) return false;
  }
  return first != nullptr;
}

}  // namespace hsr
