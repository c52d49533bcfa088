// The scene stage (scene.h): the mode, by the user or by the `auto` rule, then the kind's own rules
// (scene/building/ for a building; a room is known only after visibility, scene/plan.h).
#include "scene/scene.h"

#include "core/error.h"
#include "scene/scene_internal.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <unordered_map>

namespace hsr {

namespace {

using scene_detail::kDeg;
using scene_detail::kStage;
using scene_detail::plan_cell;

/// Inliers of the planes with |n_z| >= min_nz (foliage planes left out when `foliage` is given).
std::size_t inliers_facing(const SceneStructure& s, double min_nz, const std::vector<bool>* foliage) {
  std::size_t on = 0;
  for (std::size_t k = 0; k < s.planes.size(); ++k)
    if ((!foliage || !(*foliage)[k]) && std::abs(s.planes[k].plane.normal.z()) >= min_nz) on += s.planes[k].inliers.size();
  return on;
}

/// Two planes meeting in a (near-)horizontal line as roofs do: a ridge (both below the line), a valley (both
/// above it) or an eave (a roof above, an upright wall below). Where one tilted plane lies above the line and
/// another tilted plane below it, the pair is the top and bottom of an object seen all round (an
/// octahedron's equator) and says nothing of "level". Sides by the planes' centroids against the line's
/// height midway between them; upright within auto_level_deg.
bool meet_as_roofs(const DetectedPlane& a, const DetectedPlane& b, const SceneParams& params) {
  const double s10 = std::sin(params.auto_level_deg * kDeg);
  if (std::abs(a.plane.normal.z()) <= s10 || std::abs(b.plane.normal.z()) <= s10) return true;
  const Vec3 d = a.plane.normal.cross(b.plane.normal);
  Eigen::Matrix3d m;
  m.row(0) = a.plane.normal.transpose();
  m.row(1) = b.plane.normal.transpose();
  m.row(2) = d.transpose();
  const Vec3 mid = 0.5 * (a.centroid + b.centroid);
  const Vec3 on_line = m.colPivHouseholderQr().solve(Vec3(-a.plane.offset, -b.plane.offset, d.dot(mid)));
  return (a.centroid.z() - on_line.z()) * (b.centroid.z() - on_line.z()) > 0;
}

/// A hip (or a hip's valley) in a level frame: two tilted planes (neither within auto_level_deg of horizontal
/// nor of upright) of the same pitch within auto_level_deg, whose slopes run at right angles in plan within
/// auto_level_deg (the faces of a hipped or pyramid roof over a rectangular plan: their line climbs to the
/// ridge or the apex). Why (DECISIONS #203): a steep hipped roof at half density (AHN3_00061, draw 8 of
/// variants.py: three faces at 49-52 degrees, its ridge's two faces not adjacent) had no horizontal line, so
/// the scene was not level and rule (a) saw 0.00 of its points on planes facing up. A tilted frame gives both
/// conditions only by chance: a room's corner with its diagonal up (planefinder_officeCorner) has three planes
/// of one pitch whose slopes run 120 degrees apart in plan.
bool hip_pair(const DetectedPlane& a, const DetectedPlane& b, const SceneParams& params) {
  const double level = params.auto_level_deg * kDeg;
  const auto pitch = [](const DetectedPlane& p) { return std::acos(std::min(1.0, std::abs(p.plane.normal.z()))); };
  const double pa = pitch(a), pb = pitch(b);
  const auto tilted = [&](double x) { return x > level && x < M_PI / 2 - level; };
  if (!tilted(pa) || !tilted(pb) || std::abs(pa - pb) > level) return false;
  const Vec2 sa = a.plane.normal.head<2>().normalized(), sb = b.plane.normal.head<2>().normalized();
  return std::abs(sa.dot(sb)) <= std::sin(level);  // slopes at right angles in plan, whichever way each normal points
}

/// Rule (a)'s "level" test on the planes that are not foliage: the share of their inliers on planes within
/// auto_level_deg of horizontal or vertical, and the share (weighted by the smaller plane's inliers) of
/// adjacent non-parallel pairs meeting as roofs do (meet_as_roofs) in a line within auto_level_deg of
/// horizontal (ridges, valleys, eaves) or in a hip (hip_pair; not where a pair is a tilted top over a tilted
/// bottom). The larger of the two.
double levelness(const SceneStructure& s, const std::vector<bool>& foliage, const SceneParams& params) {
  const double c10 = std::cos(params.auto_level_deg * kDeg), s10 = std::sin(params.auto_level_deg * kDeg);
  std::size_t level = 0, all = 0;
  for (std::size_t k = 0; k < s.planes.size(); ++k) {
    if (foliage[k]) continue;
    const double nz = std::abs(s.planes[k].plane.normal.z());
    all += s.planes[k].inliers.size();
    if (nz >= c10 || nz <= s10) level += s.planes[k].inliers.size();
  }
  // A hip counts only where no adjacent pair meeting in a level line is a tilted top over a tilted bottom
  // (meet_as_roofs false): the upper half of an octahedron is a pyramid roof of hips, its equator (level lines)
  // says it is an object seen all round. Only level lines (DECISIONS #231): a hip's line climbs, and where one face
  // holds a higher part of the roof (a dormer's face, an upper step of one slope) its centroid stands above the
  // line's height midway and the hip looked like a top over a bottom (AHN3_00061 at half density, draw 15 of
  // variants.py: its hips uncounted, the scene not level, object, p2m 1.56 % where the building's is 0.31 %).
  bool top_over_bottom = false;
  const auto for_pairs = [&](auto&& f) {
    for (std::size_t i = 0; i < s.planes.size(); ++i)
      for (int j : s.adjacency[i]) {
        if (j <= static_cast<int>(i) || foliage[i] || foliage[static_cast<std::size_t>(j)]) continue;
        const DetectedPlane& a = s.planes[i];
        const DetectedPlane& b = s.planes[static_cast<std::size_t>(j)];
        const Vec3 d = a.plane.normal.cross(b.plane.normal);
        if (d.norm() >= params.auto_pair_min_sin) f(a, b, d);
      }
  };
  for_pairs([&](const DetectedPlane& a, const DetectedPlane& b, const Vec3& d) {
    top_over_bottom |= std::abs(d.normalized().z()) <= s10 && !meet_as_roofs(a, b, params);
  });
  const bool hips = params.auto_level_hips && !top_over_bottom;
  double horizontal = 0, total = 0;
  for_pairs([&](const DetectedPlane& a, const DetectedPlane& b, const Vec3& d) {
    const double w = static_cast<double>(std::min(a.inliers.size(), b.inliers.size()));
    total += w;
    const bool roof_line = std::abs(d.normalized().z()) <= s10 || (hips && hip_pair(a, b, params));
    if (roof_line && meet_as_roofs(a, b, params)) horizontal += w;
  });
  const double plane_share = all ? static_cast<double>(level) / static_cast<double>(all) : 0.0;
  return std::max(plane_share, total > 0 ? horizontal / total : 0.0);
}

/// Rule (a): the share of all points on planes within auto_roof_deg of horizontal; when the scene is level
/// (levelness() >= auto_min_levelness), at least the share of the plane points (foliage left out) on planes
/// within auto_steep_roof_deg, so steep roofs count, and points on no plane do not count against them, but a
/// tilted frame does not pass.
double roof_share(const SceneStructure& s, std::size_t points, const std::vector<bool>& foliage,
                  const SceneParams& params) {
  const double within45 =
      points ? static_cast<double>(inliers_facing(s, std::cos(params.auto_roof_deg * kDeg), nullptr)) / static_cast<double>(points)
             : 0.0;
  if (levelness(s, foliage, params) < params.auto_min_levelness) return within45;
  const std::size_t on_planes = inliers_facing(s, 0.0, &foliage);
  const double within60 =
      on_planes ? static_cast<double>(inliers_facing(s, std::cos(params.auto_steep_roof_deg * kDeg), &foliage)) / static_cast<double>(on_planes)
                : 0.0;
  return std::max(within45, within60);
}

/// Rule (b): share of the occupied xy cells (side auto_layer_cell r) whose points have a height gap above
/// max(auto_layer_gap r, auto_layer_gap_share of the z extent) under a point on a surface (a plane that is not
/// foliage): two surfaces one above the other. A tree over a roof (its points on no plane, or on a foliage
/// plane) is no second surface.
double layered_share(const PointCloud& cloud, const SceneStructure& s, const std::vector<bool>& foliage,
                     const SceneParams& params) {
  const BBox& box = s.bbox;
  const double cell = params.auto_layer_cell * s.spacing,
               gap = std::max(params.auto_layer_gap * s.spacing, params.auto_layer_gap_share * box.size().z());
  std::unordered_map<std::int64_t, std::vector<std::pair<double, bool>>> cells;  // (height, on a surface)
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const int k = s.point_plane[i];
    cells[plan_cell(cloud.points[i], box.min.head<2>(), cell)].push_back(
        {cloud.points[i].z(), k >= 0 && !foliage[static_cast<std::size_t>(k)]});
  }
  std::size_t layered = 0;
  for (auto& [key, z] : cells) {
    std::sort(z.begin(), z.end());
    for (std::size_t i = 1; i < z.size(); ++i)
      if (z[i].second && z[i].first - z[i - 1].first > gap) {
        ++layered;
        break;
      }
  }
  return cells.empty() ? 0.0 : static_cast<double>(layered) / static_cast<double>(cells.size());
}

/// A roof alone (DECISIONS #76): the planes (foliage left out) are all parallel, so object mode could enclose
/// nothing, and they face up (within auto_steep_roof_deg of horizontal, rule (a)'s steep roofs): a lean-to, the one face of a gable the
/// scan holds, a flat roof. Whatever else the scan holds (trees, points on no plane), it is a building's roof
/// when rule (b) holds too (a top seen over a bottom everywhere is an object's, not a roof over the ground).
bool roof_alone(const SceneStructure& s, const std::vector<bool>& foliage, const SceneParams& params) {
  std::vector<bool> keep(s.planes.size());
  for (std::size_t k = 0; k < s.planes.size(); ++k) keep[k] = !foliage[k];
  if (!all_parallel(s, keep)) return false;
  for (std::size_t k = 0; k < s.planes.size(); ++k)
    if (keep[k]) return std::abs(s.planes[k].plane.normal.z()) >= std::cos(params.auto_steep_roof_deg * kDeg);
  return false;
}

/// The mode: given, or `auto`'s rule (the file comment of scene.h), its figures said in `reason`.
SceneMode decide_mode(const SceneParams& params, double roof, double layered, bool alone, std::size_t building_class,
                      std::string& reason) {
  const bool one_layer = layered <= params.auto_max_layered_share;
  const bool rules_ab = roof >= params.auto_min_roof_share && one_layer;
  std::ostringstream why;
  why.precision(2);
  if (building_class > 0) {
    why << "the file classes " << building_class << " points as building (LAS class 6)";
  } else {
    why << std::fixed << roof << " of the points on planes facing up (building: >= " << params.auto_min_roof_share
        << "), " << layered << " of the xy cells with two layers (building: <= " << params.auto_max_layered_share << ")";
    if (alone && one_layer && !rules_ab) why << "; but the planes are parallel and face up: a roof alone, a building";
  }
  if (params.mode != SceneMode::Auto) {
    reason = std::string("given (") + why.str() + ")";
    return params.mode;
  }
  reason = why.str();
  if (building_class > 0) return SceneMode::Building;
  return rules_ab || (alone && one_layer) ? SceneMode::Building : SceneMode::Object;
}

}  // namespace

const char* scene_mode_name(SceneMode m) {
  switch (m) {
    case SceneMode::Object: return "object";
    case SceneMode::Building: return "building";
    case SceneMode::Auto: break;
  }
  return "auto";
}

SceneMode parse_scene_mode(const std::string& name) {
  for (SceneMode m : {SceneMode::Auto, SceneMode::Object, SceneMode::Building})
    if (name == scene_mode_name(m)) return m;
  throw Error(Status::BadInput, "cli", "unknown scene mode '" + name + "' (auto | object | building)");
}

const char* plane_role_name(PlaneRole r) {
  switch (r) {
    case PlaneRole::Roof: return "roof";
    case PlaneRole::Wall: return "wall";
    case PlaneRole::Ground: return "ground";
    case PlaneRole::Clutter: return "clutter";
    case PlaneRole::Object: break;
  }
  return "object";
}

const char* ground_source_name(GroundSource g) {
  switch (g) {
    case GroundSource::Plane: return "plane";
    case GroundSource::Given: return "given";
    case GroundSource::LowestPoints: return "lowest building point";
    case GroundSource::Raster: return "raster";
    case GroundSource::ClassifiedPoints: return "classified ground points";
    case GroundSource::Assumed: return "assumed storey";
    case GroundSource::None: break;
  }
  return "none";
}

std::size_t SceneResult::count(PlaneRole r) const {
  return static_cast<std::size_t>(std::count(roles.begin(), roles.end(), r));
}

ClassSplit split_by_class(const PointCloud& cloud) {
  ClassSplit out;
  const auto& cls = cloud.attributes.classification;
  if (cls.size() != cloud.size()) return out;
  // ASPRS LAS classification codes (LAS 1.4 R15, table 17).
  enum : std::uint8_t { kGround = 2, kLowVegetation = 3, kMediumVegetation = 4, kHighVegetation = 5, kBuilding = 6,
                        kLowNoise = 7, kWater = 9, kHighNoise = 18 };
  const auto is_ground = [](std::uint8_t c) { return c == kGround; };
  const auto left_out = [](std::uint8_t c) {
    return c == kLowVegetation || c == kMediumVegetation || c == kHighVegetation || c == kLowNoise || c == kWater ||
           c == kHighNoise;
  };
  std::vector<std::size_t> keep;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (is_ground(cls[i])) out.ground.push_back(cloud.points[i]);
    else if (left_out(cls[i])) ++out.left_out;
    else keep.push_back(i);
    if (cls[i] == kBuilding) ++out.building_class_points;
  }
  if (out.ground.empty() && out.left_out == 0) {  // nothing to split off: the cloud as it is
    out.ground.clear();
    return out;
  }
  out.applied = true;
  PointCloud& b = out.building;
  b.origin = cloud.origin;
  b.source = cloud.source;
  b.crs = cloud.crs;
  const PointAttributes& a = cloud.attributes;
  const auto pick = [&](const auto& from, auto& to) {
    if (from.size() != cloud.size()) return;
    to.reserve(keep.size());
    for (std::size_t i : keep) to.push_back(from[i]);
  };
  pick(cloud.points, b.points);
  pick(cloud.normals, b.normals);
  pick(a.classification, b.attributes.classification);
  pick(a.return_number, b.attributes.return_number);
  pick(a.number_of_returns, b.attributes.number_of_returns);
  pick(a.intensity, b.attributes.intensity);
  pick(a.gps_time, b.attributes.gps_time);
  pick(a.rgb, b.attributes.rgb);
  return out;
}

SceneResult run_scene(const PointCloud& cloud, const SceneStructure& structure, const SceneParams& params,
                      const SceneGround& ground) {
  if (!(params.auto_min_roof_share >= 0 && params.auto_min_roof_share <= 1) ||
      !(params.auto_max_layered_share >= 0 && params.auto_max_layered_share <= 1) ||
      !(params.auto_roof_deg > 0 && params.auto_roof_deg < 90) ||
      !(params.auto_steep_roof_deg > 0 && params.auto_steep_roof_deg < 90) ||
      !(params.auto_level_deg > 0 && params.auto_level_deg < 45) || !(params.auto_layer_cell > 0) ||
      !(params.auto_choice_margin >= 0) || params.auto_choice_max_points < 0 || !(params.auto_choice_min_gain >= 0))
    throw Error(Status::BadInput, kStage, "parameters out of range (see scene.h)");
  check_building_params(params.building);
  SceneResult out;
  const std::vector<bool> foliage = foliage_planes(cloud, structure, params.building);
  out.roof_share = roof_share(structure, cloud.size(), foliage, params);
  out.layered_share = layered_share(cloud, structure, foliage, params);
  out.mode = decide_mode(params, out.roof_share, out.layered_share, roof_alone(structure, foliage, params),
                         ground.building_class_points, out.reason);
  out.roles.assign(structure.planes.size(), PlaneRole::Object);
  if (out.is_building()) building_scene(cloud, structure, params.building, ground, foliage, out);
  return out;
}

SceneStructure building_structure(const PointCloud& cloud, const SceneStructure& structure, const SceneResult& scene,
                                  const SceneParams& params) {
  if (!scene.is_building()) return structure;
  return building_planes(cloud, structure, scene, params.building);
}

PointsToExplain points_to_explain(const PointCloud& cloud, const SceneStructure& detected, const SceneResult& scene,
                                  const SceneParams& params) {
  PointsToExplain out;
  out.explain.assign(cloud.size(), true);
  if (!scene.is_building()) return out;
  const double low = scene.ground_z + params.building.building_min_height * detected.spacing;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const int k = detected.point_plane[i];
    const PlaneRole role = k < 0 ? PlaneRole::Object : scene.roles[static_cast<std::size_t>(k)];
    if (k < 0 && cloud.points[i].z() < low) ++out.low_points;
    else if (role == PlaneRole::Ground) ++out.ground_plane_points;
    else if (role == PlaneRole::Clutter) ++out.clutter_plane_points;
    else continue;
    out.explain[i] = false;
  }
  return out;
}

bool small_enough_to_run_again(std::size_t points, const SceneParams& params) {
  return points <= static_cast<std::size_t>(params.auto_choice_max_points);
}

double scene_margin(const SceneResult& scene, const SceneParams& params) {
  const double roof = scene.roof_share - params.auto_min_roof_share;        // >= 0: rule (a) holds
  const double layers = params.auto_max_layered_share - scene.layered_share;  // >= 0: rule (b) holds
  if (roof >= 0 && layers >= 0) return std::min(roof, layers);
  return -std::max(std::max(-roof, 0.0), std::max(-layers, 0.0));
}

nlohmann::json to_json(const SceneResult& scene) {
  nlohmann::json j = {{"mode", scene_mode_name(scene.mode)},
                      {"reason", scene.reason},
                      {"roof_share", scene.roof_share},
                      {"layered_share", scene.layered_share}};
  if (scene.is_building()) {
    j["ground_z"] = scene.ground_z;
    j["ground_source"] = ground_source_name(scene.ground_source);
    if (!scene.ground_note.empty()) j["ground_note"] = scene.ground_note;
    j["ground_planes"] = scene.ground_planes;
    j["main_direction_deg"] = scene.main_direction / scene_detail::kDeg;
    for (PlaneRole r : {PlaneRole::Roof, PlaneRole::Wall, PlaneRole::Ground, PlaneRole::Clutter})
      j["planes"][plane_role_name(r)] = scene.count(r);
  }
  return j;
}

}  // namespace hsr
