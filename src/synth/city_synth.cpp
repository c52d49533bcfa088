// A synthetic survey tile (city_synth.h): plots, buildings of the aerial families, terrain, trees, the
// airborne scan of the whole tile, and the files.
#include "synth/city_synth.h"

#include "city/city.h"
#include "city/footprints.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "io/io.h"
#include "io/las_writer.h"
#include "synth/synth.h"
#include "synth/city_synth_internal.h"
#include "synth/synth_internal.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <random>

namespace hsr {

namespace {

using synth_detail::CityScanScene;
using synth_detail::CityTerrain;
using synth_detail::Crown;
using synth_detail::plan_box_of;
using synth_detail::RayCaster;

constexpr const char* kStage = "synth";
constexpr double kCityFlightHeight = 1000.0;  ///< metres above the tile's mean ground
using synth_detail::kCrownEchoShare;
constexpr double kSecondReturnShare = 0.5;
constexpr double kBlend = synth_detail::kCityPlotBlend;

using synth_detail::gaussian;
using synth_detail::uniform01;

// ------------------------------------------------------------------------------------- footprints of truths

/// The outline of the truth's bottom (its faces on z = min z facing down): outer rings counter-clockwise,
/// holes clockwise, each hole with the outer ring holding it.
Footprint footprint_of(const PolygonMesh& mesh) {
  double z0 = INFINITY;
  for (const Vec3& v : mesh.vertices) z0 = std::min(z0, v.z());
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;  // directed boundary edges of the bottom
  for (const auto& face : mesh.faces) {
    bool bottom = true;
    for (std::uint32_t v : face) bottom = bottom && std::abs(mesh.vertices[v].z() - z0) < 1e-9;
    if (!bottom) continue;
    for (std::size_t i = 0; i < face.size(); ++i) {
      const std::uint32_t a = face[i], b = face[(i + 1) % face.size()];
      if (!edges.erase({b, a})) edges[{a, b}] = 1;
    }
  }
  std::map<std::uint32_t, std::uint32_t> next;
  for (const auto& [e, n] : edges) next[e.first] = e.second;
  std::vector<std::vector<Vec2>> rings;
  while (!next.empty()) {
    std::vector<Vec2> ring;
    std::uint32_t v = next.begin()->first;
    while (next.count(v)) {
      ring.emplace_back(mesh.vertices[v].x(), mesh.vertices[v].y());
      const std::uint32_t w = next[v];
      next.erase(v);
      v = w;
    }
    // Seen from above the bottom faces turn clockwise: reversed, the outer rings turn counter-clockwise.
    std::reverse(ring.begin(), ring.end());
    if (ring.size() >= 3) rings.push_back(std::move(ring));
  }
  Footprint fp;
  for (const auto& r : rings)
    if (twice_ring_area(r) > 0) fp.push_back({r, {}});
  for (const auto& r : rings)
    if (twice_ring_area(r) < 0)
      for (FootprintPolygon& p : fp)
        if (inside_footprint(r.front().x(), r.front().y(), Footprint{{p.outer, {}}})) {
          p.holes.push_back(r);
          break;
        }
  return fp;
}

// ------------------------------------------------------------------------------------- terraced blocks

/// A closed convex mesh from its corners and faces, each face turned to face away from the centroid.
PolygonMesh convex_mesh(std::vector<Vec3> vertices, std::vector<std::vector<std::uint32_t>> faces) {
  Vec3 c = Vec3::Zero();
  for (const Vec3& v : vertices) c += v;
  c /= static_cast<double>(vertices.size());
  for (auto& f : faces) {
    Vec3 n = Vec3::Zero(), m = Vec3::Zero();
    for (std::size_t i = 0; i < f.size(); ++i) {
      n += vertices[f[i]].cross(vertices[f[(i + 1) % f.size()]]);
      m += vertices[f[i]];
    }
    m /= static_cast<double>(f.size());
    if (n.dot(m - c) < 0) std::reverse(f.begin(), f.end());
  }
  PolygonMesh mesh;
  mesh.vertices = std::move(vertices);
  mesh.faces = std::move(faces);
  return mesh;
}

/// The block over the rectangle q0 q1 q2 q3 (q0 q1 on the shared wall), from z0 up to `eave`; with a ridge
/// (ridge > eave) running from the shared wall to the far one, its gables on both.
PolygonMesh block_mesh(const Vec2 q[4], double z0, double eave, double ridge) {
  std::vector<Vec3> v;
  for (int k = 0; k < 4; ++k) v.emplace_back(q[k].x(), q[k].y(), z0);
  for (int k = 0; k < 4; ++k) v.emplace_back(q[k].x(), q[k].y(), eave);
  if (!(ridge > eave)) return convex_mesh(v, {{0, 1, 2, 3}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}});
  const Vec2 m01 = 0.5 * (q[0] + q[1]), m32 = 0.5 * (q[3] + q[2]);
  v.emplace_back(m01.x(), m01.y(), ridge);  // 8
  v.emplace_back(m32.x(), m32.y(), ridge);  // 9
  return convex_mesh(v, {{0, 1, 2, 3},        // bottom
                         {1, 2, 6, 5},        // side walls (along the ridge)
                         {3, 0, 4, 7},
                         {0, 1, 5, 8, 4},     // gable on the shared wall
                         {2, 3, 7, 9, 6},     // far gable
                         {5, 6, 9, 8},        // roof halves
                         {7, 4, 8, 9}});
}

bool segments_cross(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  auto orient = [](const Vec2& p, const Vec2& q, const Vec2& r) { return (q - p).x() * (r - p).y() - (q - p).y() * (r - p).x(); };
  const double d1 = orient(a, b, c), d2 = orient(a, b, d), d3 = orient(c, d, a), d4 = orient(c, d, b);
  return ((d1 > 0) != (d2 > 0)) && ((d3 > 0) != (d4 > 0)) && d1 != 0 && d2 != 0 && d3 != 0 && d4 != 0;
}

/// True when the rectangle (shrunk by 5 cm) meets the footprint.
bool rectangle_meets(const Vec2 q[4], const Footprint& f) {
  const Vec2 c = 0.25 * (q[0] + q[1] + q[2] + q[3]);
  Vec2 s[4];
  for (int k = 0; k < 4; ++k) s[k] = q[k] + 0.05 * (c - q[k]).normalized();
  for (int k = 0; k < 4; ++k)
    if (inside_footprint(s[k].x(), s[k].y(), f)) return true;
  const Footprint rect{{{s[0], s[1], s[2], s[3]}, {}}};
  for (const FootprintPolygon& p : f) {
    for (const Vec2& v : p.outer)
      if (inside_footprint(v.x(), v.y(), rect)) return true;
    for (std::size_t i = 0, j = p.outer.size() - 1; i < p.outer.size(); j = i++)
      for (int k = 0; k < 4; ++k)
        if (segments_cross(p.outer[j], p.outer[i], s[k], s[(k + 1) % 4])) return true;
  }
  return false;
}

/// The terraced neighbour of `host`: a block outside the longest edge of the host's outer ring that leaves
/// room for it (clear of the host and of the other buildings' boxes). False when no edge does.
bool terraced_block(const SynthCityBuilding& host, const std::vector<SynthCityBuilding>& all, std::mt19937_64& rng,
                    SynthCityBuilding& out) {
  const std::vector<Vec2>& ring = host.footprint.front().outer;
  std::vector<std::size_t> order(ring.size());
  for (std::size_t i = 0; i < ring.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return (ring[(a + 1) % ring.size()] - ring[a]).norm() > (ring[(b + 1) % ring.size()] - ring[b]).norm();
  });
  const double depth = 6.0 + 4.0 * uniform01(rng);
  const bool gable = rng() % 2;
  const double eave = 3.0 + 4.0 * uniform01(rng);
  for (std::size_t e : order) {
    const Vec2 a = ring[e], b = ring[(e + 1) % ring.size()];
    const double len = (b - a).norm();
    if (len < 5.0) break;
    const Vec2 dir = (b - a) / len, outward(dir.y(), -dir.x());  // outer ring counter-clockwise: outside on the right
    const double width = std::min(len, 8.0 + 4.0 * uniform01(rng)), start = 0.5 * (len - width);
    Vec2 q[4] = {a + start * dir, a + (start + width) * dir, Vec2::Zero(), Vec2::Zero()};
    q[2] = q[1] + depth * outward;
    q[3] = q[0] + depth * outward;
    if (rectangle_meets(q, host.footprint)) continue;
    bool clear = true;
    for (const SynthCityBuilding& other : all) {
      if (&other == &host) continue;
      const BBox ob = plan_box_of(other.footprint);
      for (int k = 0; k < 4 && clear; ++k)
        clear = !(q[k].x() > ob.min.x() - 2 && q[k].x() < ob.max.x() + 2 && q[k].y() > ob.min.y() - 2 && q[k].y() < ob.max.y() + 2);
    }
    if (!clear) continue;
    out.family = gable ? "terraced_gable" : "terraced_flat";
    out.attached_to = host.id;
    out.ground_z = host.ground_z;
    const double ridge = gable ? eave + 0.5 * width * std::tan((25.0 + 20.0 * uniform01(rng)) * M_PI / 180.0) : eave;
    out.truth = block_mesh(q, host.ground_z, host.ground_z + eave, host.ground_z + ridge);
    out.footprint = footprint_of(out.truth);
    return true;
  }
  return false;
}

// ------------------------------------------------------------------------------------- terrain

double smoothstep(double t) {
  t = std::clamp(t, 0.0, 1.0);
  return t * t * (3 - 2 * t);
}

/// Ground height at (x, y): the terrain, levelled to each plot's height near its footprint.
double ground_height(double x, double y, const CityTerrain& t, const std::vector<SynthCityBuilding>& buildings,
                     const std::vector<BBox>& boxes, double flat) {
  const double natural = t.natural(x, y);
  double weight = 0, shift = 0;
  for (std::size_t b = 0; b < buildings.size(); ++b) {
    const BBox& box = boxes[b];
    const double reach = flat + kBlend;
    if (x < box.min.x() - reach || x > box.max.x() + reach || y < box.min.y() - reach || y > box.max.y() + reach) continue;
    const Vec2 p(x, y);
    const double d = inside_footprint(x, y, buildings[b].footprint) ? 0.0 : distance_to_footprint(p, buildings[b].footprint);
    const double w = 1.0 - smoothstep((d - flat) / kBlend);
    if (w <= 0) continue;
    weight += w;
    shift += w * (buildings[b].ground_z - natural);
  }
  return natural + (weight > 1 ? shift / weight : shift);
}

// ------------------------------------------------------------------------------------- layout

std::string building_id(int i) {
  char id[16];
  std::snprintf(id, sizeof id, "B%04d", i + 1);
  return id;
}

SynthCityBuilding plot_building(int i, const SynthCityParams& p, const Vec2& centre, const CityTerrain& terrain,
                                std::mt19937_64& rng) {
  static const char* families[] = {"aerial_flat", "aerial_gable", "aerial_hip", "aerial_shed", "aerial_dormer", "aerial_mixed"};
  SynthCityBuilding b;
  b.family = families[i % 6];
  b.seed = p.seed * 1000 + static_cast<std::uint64_t>(i);
  SynthParams model_params;
  model_params.seed = b.seed;
  auto model = synth_detail::build_model(b.family, model_params);
  HSR_ASSERT(model.has_value(), "aerial family missing");
  b.truth = std::move(model->mesh);
  const BBox box = bounding_box(b.truth.vertices);
  const Vec2 at = centre + Vec2(-2 + 4 * uniform01(rng), -2 + 4 * uniform01(rng));
  b.ground_z = terrain.natural(at.x(), at.y());
  const Vec3 shift(at.x() - box.center().x(), at.y() - box.center().y(), b.ground_z - box.min.z());
  for (Vec3& v : b.truth.vertices) v += shift;
  b.footprint = footprint_of(b.truth);
  return b;
}

// ------------------------------------------------------------------------------------- the scan

void scan_tile(SynthCity& city, const CityScanScene& scene, const std::vector<Crown>& trees, const BBox& tile,
               std::mt19937_64& rng) {
  const SynthCityParams& p = city.params;
  const RayCaster caster(scene.mesh, scene.planes);
  const double heading = M_PI * uniform01(rng);
  const Vec2 centre = tile.center().head<2>();
  const Vec2 along(std::cos(heading), std::sin(heading)), across(-along.y(), along.x());
  double half_along = 0, half_across = 0;
  for (double x : {tile.min.x(), tile.max.x()})
    for (double y : {tile.min.y(), tile.max.y()}) {
      half_along = std::max(half_along, std::abs((Vec2(x, y) - centre).dot(along)));
      half_across = std::max(half_across, std::abs((Vec2(x, y) - centre).dot(across)));
    }
  const double spacing = 1.0 / std::sqrt(p.density / 2.0);
  auto& a = city.cloud.attributes;
  for (int line = 0; line < 2; ++line) {
    const double offset = (line == 0 ? -0.5 : 0.5) * half_across;
    const Vec2 dir = line == 0 ? along : Vec2(-along);
    const double pitch = (-4.0 + 8.0 * uniform01(rng)) * M_PI / 180.0;
    const int nu = static_cast<int>(std::ceil(2 * half_along / spacing)), nv = static_cast<int>(std::ceil(2 * half_across / spacing));
    for (int iu = 0; iu < nu; ++iu)
      for (int iv = 0; iv < nv; ++iv) {
        const double u = -half_along + (iu + uniform01(rng)) * spacing, v = -half_across + (iv + uniform01(rng)) * spacing;
        const Vec2 target2 = centre + u * along + v * across;
        if (target2.x() < tile.min.x() || target2.x() > tile.max.x() || target2.y() < tile.min.y() || target2.y() > tile.max.y())
          continue;
        const Vec2 sensor2 = centre + offset * across + u * along - kCityFlightHeight * std::tan(pitch) * dir;
        const Vec3 sensor(sensor2.x(), sensor2.y(), kCityFlightHeight);
        const Vec3 ray = (Vec3(target2.x(), target2.y(), 0.0) - sensor).normalized();
        auto hit = caster.first_hit(sensor, ray);
        if (hit && std::abs(scene.planes[hit->face].normal.dot(ray)) < 0.02) hit.reset();
        const double surface_t = hit ? hit->t : INFINITY;
        std::optional<double> crown_t;
        for (const Crown& c : trees)
          if (auto cross = c.crossing(sensor, ray); cross && cross->first < surface_t && !crown_t)
            if (uniform01(rng) < kCrownEchoShare)
              crown_t = cross->first + 0.4 * uniform01(rng) * (std::min(cross->second, surface_t) - cross->first);
        const bool second = crown_t && hit && uniform01(rng) < kSecondReturnShare;
        auto emit = [&](double t, std::uint8_t cls, int building, std::uint8_t ret, std::uint8_t of) {
          city.cloud.points.push_back(sensor + (t + p.range_noise * gaussian(rng)) * ray);
          a.classification.push_back(cls);
          a.return_number.push_back(ret);
          a.number_of_returns.push_back(of);
          city.point_building.push_back(building);
          if (building >= 0) ++city.buildings[static_cast<std::size_t>(building)].points;
        };
        if (crown_t) emit(*crown_t, 5, -1, 1, second ? 2 : 1);
        if (hit && (!crown_t || second)) {
          const int b = scene.face_building[hit->face];
          emit(hit->t, b >= 0 ? 6 : 2, b, crown_t ? 2 : 1, crown_t ? 2 : 1);
        }
      }
  }
}

}  // namespace

namespace synth_detail {

void check_city_params(const SynthCityParams& p) {
  if (!(p.density > 0) || !(p.range_noise >= 0) || !std::isfinite(p.density + p.range_noise + p.slope) || !(p.plot >= 20) ||
      !(p.plot_flat >= 0))
    throw Error(Status::BadInput, kStage, "city: density > 0, range noise >= 0, finite slope, plot >= 20 m required");
  if (p.survey_size != 0) {
    if (!(p.survey_size >= p.plot) || !(p.survey_size <= SynthCityParams::kMaxSurveySize))
      throw Error(Status::BadInput, kStage, "city: --size from one plot (" + std::to_string(static_cast<int>(p.plot)) + " m) to " +
                                                std::to_string(static_cast<int>(SynthCityParams::kMaxSurveySize / 1000)) + " km");
    if (!(p.tile_size >= 1) || !(std::ceil(p.survey_size / p.tile_size) <= 100))
      throw Error(Status::BadInput, kStage, "city: --tile-size of at least 1 m and at most 100 tiles per side");
    if (p.tiles != 1) throw Error(Status::BadInput, kStage, "city: --tiles cuts a tile; a survey (--size) is cut by --tile-size");
    const int plots = survey_plots_per_side(p);
    if (p.terraced < 0 || p.terraced >= plots * plots)
      throw Error(Status::BadInput, kStage, "city: 0 <= terraced < the survey's " + std::to_string(plots * plots) + " plots");
    return;
  }
  if (p.buildings < 1 || p.terraced < 0 || p.terraced >= p.buildings)
    throw Error(Status::BadInput, kStage, "city: need at least 1 building and 0 <= terraced < buildings");
  if (p.tiles < 1 || p.tiles > 100) throw Error(Status::BadInput, kStage, "city: tiles from 1 to 100 per side");
}

CityTerrain draw_city_terrain(const SynthCityParams& p, std::mt19937_64& rng) {
  CityTerrain terrain;
  const double slope_dir = 2 * M_PI * uniform01(rng);
  terrain.gradient = p.slope * Vec2(std::cos(slope_dir), std::sin(slope_dir));
  return terrain;
}

std::vector<SynthCityBuilding> place_city_buildings(const SynthCityParams& p, const std::vector<Vec2>& centres,
                                                    const CityTerrain& terrain, std::mt19937_64& rng) {
  std::vector<SynthCityBuilding> buildings;
  const int standing = static_cast<int>(centres.size());
  for (int i = 0; i < standing; ++i) {
    buildings.push_back(plot_building(i, p, centres[static_cast<std::size_t>(i)], terrain, rng));
    buildings.back().id = building_id(i);
  }
  for (int t = 0; t < p.terraced; ++t) {
    SynthCityBuilding block;
    bool placed = false;
    for (int k = 0; k < standing && !placed; ++k) {
      const std::size_t host = static_cast<std::size_t>((t * 7 + k) % standing);
      placed = terraced_block(buildings[host], buildings, rng, block);
    }
    if (!placed) throw Error(Status::BadInput, kStage, "city: no room for terraced building " + std::to_string(t + 1));
    block.seed = p.seed * 1000 + static_cast<std::uint64_t>(standing + t);
    block.id = building_id(standing + t);
    buildings.push_back(std::move(block));
  }
  return buildings;
}

BBox plan_box_of(const Footprint& f) {
  BBox b;
  for (const FootprintPolygon& p : f)
    for (const Vec2& q : p.outer) b.extend(Vec3(q.x(), q.y(), 0));
  return b;
}

void add_city_buildings(CityScanScene& scene, const std::vector<SynthCityBuilding>& buildings, const std::vector<int>& index) {
  for (std::size_t b = 0; b < buildings.size(); ++b) {
    const SynthCityBuilding& sb = buildings[b];
    const auto base = static_cast<std::uint32_t>(scene.mesh.vertices.size());
    scene.mesh.vertices.insert(scene.mesh.vertices.end(), sb.truth.vertices.begin(), sb.truth.vertices.end());
    for (auto face : sb.truth.faces) {
      Vec3 n = Vec3::Zero(), c = Vec3::Zero();
      for (std::size_t i = 0; i < face.size(); ++i) {
        n += sb.truth.vertices[face[i]].cross(sb.truth.vertices[face[(i + 1) % face.size()]]);
        c += sb.truth.vertices[face[i]];
      }
      n.normalize();
      c /= static_cast<double>(face.size());
      for (auto& v : face) v += base;
      scene.mesh.faces.push_back(face);
      scene.planes.push_back({n, -n.dot(c)});
      scene.face_building.push_back(index[b]);
    }
  }
}

void append_city_terrain(CityScanScene& out, const BBox& box, const CityTerrain& t,
                         const std::vector<SynthCityBuilding>& buildings, double flat) {
  PolygonMesh& scene = out.mesh;
  std::vector<Plane>& planes = out.planes;
  std::vector<BBox> boxes;
  for (const auto& b : buildings) boxes.push_back(plan_box_of(b.footprint));
  const double cell = 1.0;
  const int nx = static_cast<int>(std::ceil((box.max.x() - box.min.x()) / cell)) + 1;
  const int ny = static_cast<int>(std::ceil((box.max.y() - box.min.y()) / cell)) + 1;
  const auto base = static_cast<std::uint32_t>(scene.vertices.size());
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const double x = box.min.x() + i * cell, y = box.min.y() + j * cell;
      scene.vertices.emplace_back(x, y, ground_height(x, y, t, buildings, boxes, flat));
    }
  auto id = [&](int i, int j) { return base + static_cast<std::uint32_t>(i + nx * j); };
  for (int j = 0; j + 1 < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i)
      for (const std::vector<std::uint32_t>& tri : {std::vector<std::uint32_t>{id(i, j), id(i + 1, j), id(i + 1, j + 1)},
                                                    std::vector<std::uint32_t>{id(i, j), id(i + 1, j + 1), id(i, j + 1)}}) {
        const Vec3 &a = scene.vertices[tri[0]], &b = scene.vertices[tri[1]], &c = scene.vertices[tri[2]];
        const Vec3 n = (b - a).cross(c - a).normalized();
        scene.faces.push_back(tri);
        planes.push_back({n, -n.dot(a)});
      }
  out.face_building.resize(scene.faces.size(), -1);
}

std::vector<Crown> place_city_trees(int count, const BBox& tile, const std::vector<SynthCityBuilding>& buildings,
                                    const CityTerrain& terrain, double flat, std::mt19937_64& rng) {
  std::vector<BBox> boxes;
  for (const auto& b : buildings) boxes.push_back(plan_box_of(b.footprint));
  std::vector<Crown> trees;
  for (int t = 0; t < count; ++t)
    for (int attempt = 0; attempt < 100; ++attempt) {
      Crown c;
      c.radius = 1.0 + 1.0 * uniform01(rng);
      c.height = 0.8 * c.radius + 0.8;
      const double x = tile.min.x() + (tile.max.x() - tile.min.x()) * uniform01(rng);
      const double y = tile.min.y() + (tile.max.y() - tile.min.y()) * uniform01(rng);
      bool clear = true;
      for (const BBox& b : boxes)
        clear = clear && !(x > b.min.x() - c.radius - 2 && x < b.max.x() + c.radius + 2 && y > b.min.y() - c.radius - 2 &&
                           y < b.max.y() + c.radius + 2);
      if (!clear) continue;
      c.centre = {x, y, ground_height(x, y, terrain, buildings, boxes, flat) + 2.0 + 5.0 * uniform01(rng) + c.height};
      trees.push_back(c);
      break;
    }
  return trees;
}

}  // namespace synth_detail

SynthCity run_synth_city(const SynthCityParams& params) {
  if (params.survey_size != 0) throw Error(Status::BadInput, kStage, "city: a survey (--size) is written tile by tile: write_synth_survey");
  synth_detail::check_city_params(params);
  SynthCity city;
  city.params = params;
  std::mt19937_64 rng(params.seed * 0x9E3779B97F4A7C15ull + 27);
  const CityTerrain terrain = synth_detail::draw_city_terrain(params, rng);
  // Plots: the free-standing buildings, then the terraced ones attached to a building before them.
  const int standing = params.buildings - params.terraced;
  const int cols = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(standing))));
  std::vector<Vec2> centres;
  for (int i = 0; i < standing; ++i) centres.emplace_back((i % cols + 0.5) * params.plot, (i / cols + 0.5) * params.plot);
  city.buildings = synth_detail::place_city_buildings(params, centres, terrain, rng);
  BBox tile;
  for (int k = 0; k < 2; ++k) tile.extend(Vec3(k * cols * params.plot, k * std::ceil(double(standing) / cols) * params.plot, 0));
  CityScanScene scene;
  std::vector<int> index(city.buildings.size());
  for (std::size_t b = 0; b < index.size(); ++b) index[b] = static_cast<int>(b);
  synth_detail::add_city_buildings(scene, city.buildings, index);
  synth_detail::append_city_terrain(scene, tile, terrain, city.buildings, params.plot_flat);
  const int tree_count = params.trees < 0 ? params.buildings : params.trees;
  const std::vector<Crown> trees = synth_detail::place_city_trees(tree_count, tile, city.buildings, terrain, params.plot_flat, rng);
  scan_tile(city, scene, trees, tile, rng);
  city.cloud.origin = params.origin;
  city.cloud.crs = params.crs;
  city.cloud.source = "synth:city";
  for (SynthCityBuilding& b : city.buildings) b.truth.origin = params.origin;
  return city;
}

/// Cuts the cloud into n x n tiles of equal plan size (SynthCityParams::tiles) and writes each, classified and
/// not, into root/tiles/ and root/tiles_unclassified/ (a tile without points is not written). Why: surveys are
/// published in tiles cut along a grid, through buildings (issue 40).
void write_survey_tiles(const PointCloud& cloud, int n, const std::filesystem::path& root) {
  namespace fs = std::filesystem;
  const BBox box = bounding_box(cloud.points);
  const Vec3 size = box.size();
  std::vector<std::vector<std::size_t>> cells(static_cast<std::size_t>(n) * n);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const auto cell_of = [&](int k) {
      const int c = static_cast<int>(std::floor((cloud.points[i][k] - box.min[k]) / size[k] * n));
      return std::clamp(c, 0, n - 1);
    };
    cells[static_cast<std::size_t>(cell_of(1) * n + cell_of(0))].push_back(i);
  }
  for (const char* folder : {"tiles", "tiles_unclassified"}) synth_detail::create_folder(root / folder);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) {
      const std::vector<std::size_t>& ids = cells[static_cast<std::size_t>(r * n + c)];
      if (ids.empty()) continue;
      const std::string name = "r" + std::to_string(r) + "c" + std::to_string(c) + ".las";
      PointCloud part = select_points(cloud, ids);
      write_las((root / "tiles" / name).string(), part);
      std::fill(part.attributes.classification.begin(), part.attributes.classification.end(), 0);
      write_las((root / "tiles_unclassified" / name).string(), part);
    }
}

namespace synth_detail {

void write_city_truth(const SynthCityParams& params, const std::vector<SynthCityBuilding>& buildings, std::size_t points,
                      const std::filesystem::path& root, const nlohmann::json& extra) {
  const Vec3& o = params.origin;
  std::vector<FootprintFeature> features;
  nlohmann::json truth = {{"buildings", params.survey_size != 0 ? static_cast<int>(buildings.size()) : params.buildings},
                          {"tiles", params.tiles}, {"seed", params.seed},
                          {"terraced", params.terraced}, {"density", params.density},
                          {"range_noise", params.range_noise}, {"slope", params.slope},
                          {"origin", {o.x(), o.y(), o.z()}}, {"crs", params.crs}, {"points", points}};
  truth.update(extra);
  truth["building"] = nlohmann::json::array();
  for (const SynthCityBuilding& b : buildings) {
    FootprintFeature f;
    f.id = b.id;
    for (const FootprintPolygon& p : b.footprint) {
      FootprintPolygon g = p;
      for (Vec2& q : g.outer) q += o.head<2>();
      for (auto& h : g.holes)
        for (Vec2& q : h) q += o.head<2>();
      f.footprint.push_back(std::move(g));
    }
    f.attributes = {{"family", b.family}, {"seed", static_cast<std::int64_t>(b.seed)}, {"truth_ground_z", b.ground_z + o.z()},
                    {"attached_to", b.attached_to}};
    write_mesh((root / "truth" / (b.id + ".obj")).string(), b.truth);
    truth["building"].push_back({{"id", b.id}, {"family", b.family}, {"seed", b.seed}, {"attached_to", b.attached_to},
                                 {"ground_z", b.ground_z + o.z()}, {"points", b.points},
                                 {"footprint", footprint_geojson(f)["features"][0]["geometry"]}});
    features.push_back(std::move(f));
  }
  write_footprints((root / "footprints.geojson").string(), features, params.crs);
  AtomicFile out((root / "truth.json").string(), kStage);
  out.stream() << truth.dump(1) << '\n';
  out.commit();
}

void create_folder(const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw Error(Status::FileNotFound, kStage, "cannot create output folder '" + dir.string() + "': " + ec.message());
}

}  // namespace synth_detail

void write_synth_city(const SynthCity& city, const std::string& dir) {
  const std::filesystem::path root(dir);
  synth_detail::create_folder(root / "truth");
  write_las((root / "tile.las").string(), city.cloud);
  PointCloud plain = city.cloud;
  std::fill(plain.attributes.classification.begin(), plain.attributes.classification.end(), 0);
  write_las((root / "tile_unclassified.las").string(), plain);
  if (city.params.tiles > 1) write_survey_tiles(city.cloud, city.params.tiles, root);
  synth_detail::write_city_truth(city.params, city.buildings, city.cloud.size(), root, nlohmann::json::object());
}

}  // namespace hsr
