// Evaluation stage, reports: JSON and human-readable summaries of an EvalResult, EvalParams <-> JSON
// (no CGAL here).
#include "eval/eval.h"

#include "core/face_class.h"
#include "core/params_json.h"

#include <algorithm>
#include <limits>

#include <cstdio>
#include <string>
#include <vector>

namespace hsr {

namespace {
const auto eval_fields = [](auto& p, auto&& f) {
  f("mesh_samples", p.mesh_samples);
  f("seed", p.seed);
  f("check_self_intersections", p.check_self_intersections);
  f("max_points", p.max_points);
  f("samples_per_point", p.samples_per_point);
  f("min_mesh_samples", p.min_mesh_samples);
  f("unexplained_distance", p.unexplained_distance);
  f("unexplained_warn_share", p.unexplained_warn_share);
};
}  // namespace

void to_json(nlohmann::json& j, const EvalParams& p) { params_json::write(j, p, eval_fields); }
void from_json(const nlohmann::json& j, EvalParams& p) { params_json::read(j, p, "eval", eval_fields); }

std::string Validity::summary() const {
  if (valid()) return self_intersections_checked ? "valid" : "valid (self-intersections not checked)";
  std::vector<std::string> failed;
  if (!closed) failed.push_back("not closed");
  if (!manifold) failed.push_back("not manifold");
  if (!oriented) failed.push_back("not oriented outward");
  if (!self_intersection_free) failed.push_back("self-intersecting");
  if (!bounds_volume) failed.push_back("does not bound a volume");
  std::string s = "invalid: ";
  for (std::size_t i = 0; i < failed.size(); ++i) s += (i ? ", " : "") + failed[i];
  return s;
}

FaceSizes face_sizes(const PolygonMesh& mesh, double small_share) {
  FaceSizes out;
  out.small_share = small_share;
  std::vector<double> areas;
  areas.reserve(mesh.faces.size());
  double total = 0.0;
  for (const auto& face : mesh.faces) total += areas.emplace_back(0.5 * newell_vector(mesh.vertices, face).norm());
  if (areas.empty() || !(total > 0)) return out;
  out.smallest_share = *std::min_element(areas.begin(), areas.end()) / total;
  for (double a : areas) out.small_faces += a < small_share * total;
  return out;
}

nlohmann::json to_json(const EvalResult& r) {
  nlohmann::json j;
  j["vertices"] = r.vertices;
  j["faces"] = r.faces;
  j["regions"] = r.regions;
  j["points"] = r.points;
  j["mesh_samples"] = r.mesh_samples;
  j["points_evaluated"] = r.points_evaluated;
  j["diagonal"] = r.diagonal;
  j["mesh_area"] = r.mesh_area;
  j["face_sizes"] = {{"smallest_share", r.face_sizes.smallest_share},
                     {"small_faces", r.face_sizes.small_faces},
                     {"small_share", r.face_sizes.small_share}};
  const Validity& v = r.validity;
  j["validity"] = {{"closed", v.closed},
                   {"manifold", v.manifold},
                   {"oriented", v.oriented},
                   {"self_intersection_free", v.self_intersection_free},
                   {"self_intersections_checked", v.self_intersections_checked},
                   {"bounds_volume", v.bounds_volume},
                   {"volume", v.volume},
                   {"valid", v.valid()}};
  const Accuracy& a = r.accuracy;
  nlohmann::json acc = {{"units", "fraction of the input points' bbox diagonal"},
                        {"p2m_mean", a.p2m_mean},
                        {"p2m_rms", a.p2m_rms},
                        {"p2m_max", a.p2m_max},
                        {"m2p_mean", a.m2p_mean},
                        {"m2p_max", a.m2p_max},
                        {"m2p_mean_stderr", a.m2p_mean_stderr},
                        {"has_truth", a.has_truth}};
  if (a.has_truth) {
    acc["chamfer"] = a.chamfer;
    acc["hausdorff"] = a.hausdorff;
    acc["truth_to_mesh_mean"] = a.truth_to_mesh_mean;
    acc["mesh_to_truth_mean"] = a.mesh_to_truth_mean;
    acc["truth_to_mesh_max"] = a.truth_to_mesh_max;
    acc["mesh_to_truth_max"] = a.mesh_to_truth_max;
  }
  j["accuracy"] = acc;
  return j;
}

namespace {
std::string percent(double fraction) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f%%", 100.0 * fraction);
  return buf;
}
}  // namespace

std::string summary(const EvalResult& r) {
  const Accuracy& a = r.accuracy;
  char buf[160];
  std::string s;
  std::snprintf(buf, sizeof buf, "mesh: %zu vertices, %zu faces, volume %.6g; %s\n", r.vertices, r.faces,
                r.validity.volume, r.validity.summary().c_str());
  s += buf;
  std::snprintf(buf, sizeof buf, "faces: smallest %.4f%% of the area, %zu under %.1f%%\n",
                100.0 * r.face_sizes.smallest_share, r.face_sizes.small_faces, 100.0 * r.face_sizes.small_share);
  s += buf;
  std::snprintf(buf, sizeof buf, "distances in %% of the points' bbox diagonal (%.6g, %zu points):\n",
                r.diagonal, r.points);
  s += buf;
  s += "  p2m mean " + percent(a.p2m_mean) + "  rms " + percent(a.p2m_rms) + "  max " + percent(a.p2m_max);
  if (r.points_evaluated > 0 && r.points_evaluated < r.points)
    s += "  (over a random " + std::to_string(r.points_evaluated) + " of the points)";
  s += "\n";
  s += "  m2p mean " + percent(a.m2p_mean) + "  max " + percent(a.m2p_max) + "\n";
  if (a.has_truth)
    s += "  vs truth: chamfer " + percent(a.chamfer) + " (truth->mesh " + percent(a.truth_to_mesh_mean) +
         ", mesh->truth " + percent(a.mesh_to_truth_mean) + ")  hausdorff " + percent(a.hausdorff) + "\n";
  return s;
}

}  // namespace hsr
