// How a later run's model of a building is judged against the model kept so far (pipeline_runs.h): the points
// farther than the inlier distance from each, keep_tighter_planes on the two evaluations, and both ways the roof
// that no point sees (no_more_unseen_roof). One judgement for #159's walls and steps 6 and 7.
#include "pipeline/pipeline_runs.h"

#include "core/kd_tree.h"
#include "core/spacing.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>

namespace hsr::pipeline_detail {

/// The scan's points farther than `distance` from the model, on every point's distance to it.
std::size_t farther_than(const std::vector<double>& d, double distance) {
  return static_cast<std::size_t>(std::count_if(d.begin(), d.end(), [distance](double x) { return x > distance; }));
}

/// Whether a later run's model (`other`, unless it `failed`) replaces the model kept so far (`out`), by the
/// result: keep_tighter_planes on the two evaluations and their far points. One judgement for the runs of
/// walls_for_left_out_roofs and of steps 6 and 7 (which also ask for the same ground, same_ground).
bool later_run_explains_more(const PipelineResult& out, const PipelineResult& other, bool failed, FarPoints far,
                             const BuildingParams& b) {
  return !failed && keep_tighter_planes(out.eval.validity.valid(), out.eval.accuracy.p2m_mean,
                                        out.eval.face_sizes.small_faces, far.before, other.eval.validity.valid(),
                                        other.eval.accuracy.p2m_mean, other.eval.face_sizes.small_faces, far.after, b);
}

/// A later run's report (scene.left_out_roofs, scene.tighter_planes, scene.gable_halves): whether it gave a valid
/// solid, and the figures later_run_explains_more judged, before and (unless it failed) after.
nlohmann::json later_run_json(const PipelineResult& out, const PipelineResult& other, bool failed, FarPoints far) {
  nlohmann::json j = {{"valid", !failed && other.eval.validity.valid()},
                      {"p2m_before", out.eval.accuracy.p2m_mean},
                      {"small_faces_before", out.eval.face_sizes.small_faces},
                      {"far_points_before", far.before}};
  if (!failed) {
    j["p2m"] = other.eval.accuracy.p2m_mean;
    j["small_faces"] = other.eval.face_sizes.small_faces;
    j["far_points"] = far.after;
  }
  return j;
}

namespace {

/// The scan's points as unseen_roof_area reads them: their kd-tree, and their highest z per cell of a plan grid.
struct SeenFromAbove {
  KdTree kd;                              ///< the scan's points
  double cell = 0.0;                      ///< the plan grid's cell (the unseen distance)
  std::map<std::pair<std::int64_t, std::int64_t>, double> top;  ///< the points' highest z per plan cell
};
SeenFromAbove seen_from_above(const PointCloud& cloud, double distance) {
  SeenFromAbove out{KdTree(cloud.points), distance, {}};
  for (const Vec3& p : cloud.points) {
    auto [it, fresh] = out.top.try_emplace({static_cast<std::int64_t>(std::floor(p.x() / distance)),
                                            static_cast<std::int64_t>(std::floor(p.y() / distance))}, p.z());
    if (!fresh) it->second = std::max(it->second, p.z());
  }
  return out;
}

/// The surface of `mesh` that a scan from above would see but no point of `cloud` does, each piece's area
/// times its distance to the nearest point (in the points' units cubed: with the scan's density, 1 / r², the
/// sum of the distances of the points such a surface would have had). The surface: farther than
/// `distance` from every point (BuildingParams::unseen_roof_distance; `mesh` in the cloud's coordinates), on a
/// face facing up (more than `wall_max_angle_deg` from upright) or higher by more than `distance` than every
/// point within about `distance` of it in plan (the points' highest in its cell of a `distance` grid and the 8
/// around it; `seen`: seen_from_above with `distance`). Walls under the roof's points are not counted: a scan
/// from above sees them poorly; a face standing over the points (a gable's end filled up to the ridge) is. Each
/// face's triangles (triangulate_polygon) are cut into a grid of equal triangles of sides at most `step` (r: a
/// point's share of the surface), each counted at its centroid: the same figure whatever the thread count.
/// 0 for an empty cloud.
double unseen_roof_area(const SeenFromAbove& seen, const PolygonMesh& mesh, double distance, double step,
                        double wall_max_angle_deg) {
  if (seen.kd.size() == 0 || !(step > 0) || !(distance > 0)) return 0.0;
  const auto highest_near = [&](const Vec3& q) {  // the points' highest in q's cell and the 8 around it
    const std::int64_t cx = static_cast<std::int64_t>(std::floor(q.x() / seen.cell));
    const std::int64_t cy = static_cast<std::int64_t>(std::floor(q.y() / seen.cell));
    double z = -std::numeric_limits<double>::infinity();
    for (std::int64_t dx = -1; dx <= 1; ++dx)
      for (std::int64_t dy = -1; dy <= 1; ++dy)
        if (auto it = seen.top.find({cx + dx, cy + dy}); it != seen.top.end()) z = std::max(z, it->second);
    return z;
  };
  const double min_up = std::sin(wall_max_angle_deg * M_PI / 180.0), d2max = distance * distance;
  constexpr int kMaxCuts = 256;  // a side cut in at most this many: the grid's count stays bounded on a large face
  double area = 0.0;
  std::vector<Vec3> loop;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  for (const std::vector<std::uint32_t>& face : mesh.faces) {
    loop.clear();
    for (std::uint32_t v : face) loop.push_back(mesh.vertices[v]);
    Vec3 n = Vec3::Zero();  // Newell's normal
    for (std::size_t i = 0; i < loop.size(); ++i) n += loop[i].cross(loop[(i + 1) % loop.size()]);
    if (!(n.norm() > 0)) continue;
    const bool facing_up = n.z() > min_up * n.norm();
    triangles.clear();
    triangulate_polygon(loop, triangles);
    for (const auto& t : triangles) {
      const Vec3 &a = loop[t[0]], &b = loop[t[1]], &c = loop[t[2]];
      const double side = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
      const int m = std::clamp(static_cast<int>(std::ceil(side / step)), 1, kMaxCuts);
      const double piece = 0.5 * (b - a).cross(c - a).norm() / (static_cast<double>(m) * m);
      const Vec3 u = (b - a) / m, w = (c - a) / m;
      for (int i = 0; i < m; ++i)
        for (int j = 0; i + j < m; ++j)
          for (int k = 0; k < (i + j + 1 < m ? 2 : 1); ++k) {  // the grid's triangle pointing up, then down
            const double f = k == 0 ? 1.0 / 3.0 : 2.0 / 3.0;
            const Vec3 q = a + (i + f) * u + (j + f) * w;
            if (!facing_up && !(q.z() > highest_near(q) + distance)) continue;  // a wall under the points
            double d2 = 0.0;
            seen.kd.nearest(q, &d2);
            if (d2 > d2max) area += piece * std::sqrt(d2);
          }
    }
  }
  return area;
}

}  // namespace

// UnseenRoof (pipeline_runs.h): each model's sums both ways, and whether the second may be kept.
UnseenRoof compare_unseen_roof(const PointCloud& cloud, const PipelineResult& first, const PipelineResult& second,
                               double r, const BuildingParams& b) {
  UnseenRoof out;
  if (!(b.unseen_roof_distance > 0) || !(r > 0)) return out;
  const double distance = b.unseen_roof_distance * r, n = static_cast<double>(cloud.size());
  const SeenFromAbove seen = seen_from_above(cloud, distance);
  out.first = unseen_roof_area(seen, first.mesh, distance, r, b.wall_max_angle_deg) / (r * r);
  out.second = unseen_roof_area(seen, second.mesh, distance, r, b.wall_max_angle_deg) / (r * r);
  out.first_p2m = first.eval.accuracy.p2m_mean * first.eval.diagonal * n;
  out.second_p2m = second.eval.accuracy.p2m_mean * second.eval.diagonal * n;
  out.may_keep = no_more_unseen_roof(out.first_p2m, out.first, out.second_p2m, out.second, b);
  return out;
}

/// The report's figures of compare_unseen_roof, in `j` (scene.left_out_roofs, scene.finer_outline.tried[],
/// scene.tighter_planes).
void report_unseen_roof(const UnseenRoof& u, nlohmann::json& j) {
  j["unseen_before"] = u.first;
  j["unseen"] = u.second;
  j["p2m_sum_before"] = u.first_p2m;
  j["p2m_sum"] = u.second_p2m;
}

/// Whether a second run of the same building (step 6) stands on the first run's ground: the same source, and no
/// more points in ground planes. Why: the scene decides on the planes of the first detection (DECISIONS #99); with
/// tighter planes a flat roof under a tree can become a ground plane and the tree the building (AHN3_15708 at
/// half density: the roof's 247 points taken for ground, the tree's points modelled; p2m lower, the building gone).
bool same_ground(const nlohmann::json& first, const nlohmann::json& second) {
  const auto quality = [](const nlohmann::json& r) { return r.value("quality", nlohmann::json::object()); };
  const auto source = [&](const nlohmann::json& r) { return quality(r).value("ground_source", std::string()); };
  const auto ground_points = [&](const nlohmann::json& r) {
    return quality(r).value("removed_points", nlohmann::json::object()).value("ground_planes", 0);
  };
  return source(first) == source(second) && ground_points(second) <= ground_points(first);
}

namespace {

/// StructureParams::max_distance in the scan's units as a run's report.resolved (`resolved`) gives it, else
/// max_distance r.
double resolved_inlier_distance(const PointCloud& cloud, const PipelineParams& params, const nlohmann::json& resolved) {
  const nlohmann::json structure = resolved.is_object() ? resolved.value("structure", nlohmann::json::object())
                                                        : nlohmann::json::object();
  return structure.contains("max_distance") ? structure["max_distance"].get<double>()
                                            : params.structure.max_distance * average_spacing(cloud.points);
}

/// The scan's points farther than `distance` from r's model: counted on the distances its evaluation kept
/// (Run::keep_point_distance), measured again only where it kept none.
std::size_t points_farther(const PointCloud& cloud, const PipelineResult& r, double distance) {
  const std::vector<double>& d = r.eval.point_distance;
  if (d.size() != cloud.size()) return count_farther(cloud.points, r.mesh, distance);
  return farther_than(d, distance);
}

}  // namespace

/// FarPoints of steps 6 and 7 (points_farther) at the first detection's inlier distance: StructureParams::
/// max_distance as the first run's report.resolved (`first_resolved`) gives it in the scan's units, else
/// max_distance r.
FarPoints far_points_of_runs(const PointCloud& cloud, const PipelineParams& params, const nlohmann::json& first_resolved,
                             const PipelineResult& out, const PipelineResult& other, bool failed) {
  const double inlier_distance = resolved_inlier_distance(cloud, params, first_resolved);
  return {points_farther(cloud, out, inlier_distance), failed ? cloud.size() : points_farther(cloud, other, inlier_distance)};
}

/// The points farther from `out`'s model than its own detection's inlier distance (its report.resolved).
std::size_t far_points_of_model(const PointCloud& cloud, const PipelineParams& params, const PipelineResult& out) {
  return points_farther(cloud, out, resolved_inlier_distance(cloud, params, out.report.value("resolved", nlohmann::json())));
}

}  // namespace hsr::pipeline_detail
