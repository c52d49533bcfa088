// Synthetic scans (DESIGN.md §3): builds a model (models.cpp), groups its faces into planes, casts the
// simulated scanner's rays (scan.cpp) and writes points / truth / plane list.
#include "synth/synth.h"

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/face_class.h"
#include "io/io.h"
#include "synth/synth_internal.h"

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <limits>
#include <optional>
#include <map>
#include <random>
#include <set>
#include <algorithm>

namespace hsr {
namespace {

using synth_detail::Model;
using synth_detail::RayCaster;

using synth_detail::gaussian;
using synth_detail::kCrownEchoShare;
using synth_detail::uniform01;

Eigen::Matrix3d random_rotation(std::mt19937_64& rng) {
  Eigen::Quaterniond q(gaussian(rng), gaussian(rng), gaussian(rng), gaussian(rng));
  q.normalize();
  return q.toRotationMatrix();
}

/// i-th of n directions of a Fibonacci spiral on the spherical cap {z >= cap_cos} (the whole sphere for
/// cap_cos = -1): near-uniform, deterministic.
Vec3 fibonacci_direction(std::size_t i, std::size_t n, double cap_cos) {
  const double z = 1.0 - (1.0 - cap_cos) * (static_cast<double>(i) + 0.5) / static_cast<double>(n);
  const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
  const double phi = static_cast<double>(i) * M_PI * (3.0 - std::sqrt(5.0));
  return {r * std::cos(phi), r * std::sin(phi), z};
}

/// The rays of one scanner. A real scanner sweeps the whole sphere at a fixed angular resolution; rays
/// outside the cone around the model's bounding sphere cannot hit it, so only that cap is cast (same
/// result, far fewer rays for aerial and distant positions).
struct ScannerRays {
  Eigen::Matrix3d frame;  ///< maps the cap's +z axis towards the model, randomly spun (seeded)
  double cap_cos = -1.0;  ///< cosine of the cap's half-angle; -1: full sphere (scanner inside the sphere)
  double solid_angle() const { return 2.0 * M_PI * (1.0 - cap_cos); }
  std::size_t count(double rays_per_steradian) const {
    return static_cast<std::size_t>(std::ceil(rays_per_steradian * solid_angle()));
  }
  Vec3 direction(std::size_t i, std::size_t n) const { return frame * fibonacci_direction(i, n, cap_cos); }
};

ScannerRays scanner_rays(const Vec3& scanner, const BBox& box, std::mt19937_64& rng) {
  ScannerRays r;
  const Eigen::Matrix3d random = random_rotation(rng);
  const Vec3 to_centre = box.center() - scanner;
  const double radius = 0.5 * box.diagonal(), dist = to_centre.norm();
  if (dist <= 1.01 * radius) {
    r.frame = random;
    return r;
  }
  const Vec3 axis = to_centre / dist;
  // Turn +z onto the axis, after a random spin about +z.
  const Eigen::Matrix3d onto = Eigen::Quaterniond::FromTwoVectors(Vec3::UnitZ(), axis).toRotationMatrix();
  const double spin = 2.0 * M_PI * uniform01(rng);
  r.frame = onto * Eigen::AngleAxisd(spin, Vec3::UnitZ()).toRotationMatrix();
  // Slightly wider than the bounding sphere's cone, so rays tangent to it are cast too.
  r.cap_cos = std::cos(std::min(M_PI, 1.01 * std::asin(radius / dist)));
  return r;
}

/// Distinct planes of the truth (core/face_class.h coplanar_groups), with their areas.
void group_planes(const PolygonMesh& mesh, std::vector<SynthPlane>& planes, std::vector<int>& face_plane,
                  std::vector<Plane>& face_planes) {
  CoplanarGroups g = coplanar_groups(mesh);
  for (const Plane& p : g.planes) planes.push_back({p, 0.0, 0});
  for (std::size_t f = 0; f < mesh.faces.size(); ++f)
    planes[static_cast<std::size_t>(g.face_group[f])].area += 0.5 * newell_vector(mesh.vertices, mesh.faces[f]).norm();
  face_plane = std::move(g.face_group);
  face_planes = std::move(g.face_planes);
}


using synth_detail::Crown;

constexpr double kAerialFlightHeight = 500.0;  ///< metres above the ground

/// A horizontal square at z = 0 around `box` (margin m), as one extra face appended to `mesh`, facing up.
void append_ground(PolygonMesh& mesh, std::vector<Plane>& face_planes, const BBox& box, double margin) {
  const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
  const double x0 = box.min.x() - margin, x1 = box.max.x() + margin, y0 = box.min.y() - margin, y1 = box.max.y() + margin;
  mesh.vertices.insert(mesh.vertices.end(), {{x0, y0, 0}, {x1, y0, 0}, {x1, y1, 0}, {x0, y1, 0}});
  mesh.faces.push_back({base, base + 1, base + 2, base + 3});
  face_planes.push_back({Vec3::UnitZ(), 0.0});
}

/// Tree crowns beside the building (outside its bbox, touching distance at most 2 m).
std::vector<Crown> place_trees(int count, const BBox& box, std::mt19937_64& rng) {
  std::vector<Crown> trees;
  for (int i = 0; i < count; ++i) {
    Crown c;
    c.radius = 2.0 + 2.0 * uniform01(rng);
    c.height = 0.8 * c.radius;
    const double gap = c.radius + 2.0 * uniform01(rng);
    const int side = static_cast<int>(rng() % 4);
    const double t = uniform01(rng);
    const Vec3 lo = box.min, hi = box.max;
    const double x = side == 0 ? lo.x() - gap : side == 1 ? hi.x() + gap : lo.x() + t * (hi.x() - lo.x());
    const double y = side == 2 ? lo.y() - gap : side == 3 ? hi.y() + gap : lo.y() + t * (hi.y() - lo.y());
    c.centre = {x, y, c.height + 2.0 + 5.0 * uniform01(rng)};
    trees.push_back(c);
  }
  return trees;
}

/// The airborne scan of an aerial model (see synth_aerial_model_names() for the scanner).
void scan_aerial(SynthScan& scan, const std::vector<Plane>& truth_face_planes, const SynthParams& params,
                 std::mt19937_64& rng) {
  const BBox box = bounding_box(scan.truth.vertices);
  const bool ground = params.aerial_ground < 0 ? (params.seed % 2) == 1 : params.aerial_ground > 0;
  const int tree_count = params.aerial_trees < 0 ? static_cast<int>(rng() % 3) : params.aerial_trees;
  const double margin = ground ? 4.0 + 4.0 * uniform01(rng) : 1.0;
  PolygonMesh scene = scan.truth;  // the truth plus, when there is ground, one ground face
  std::vector<Plane> face_planes = truth_face_planes;
  if (ground) append_ground(scene, face_planes, box, margin);
  const std::size_t truth_faces = scan.truth.faces.size();
  const RayCaster caster(scene, face_planes);
  const std::vector<Crown> trees = place_trees(tree_count, box, rng);

  const int lines = 1 + static_cast<int>(rng() % 2);
  const double heading = M_PI * uniform01(rng);
  const double spacing = 1.0 / std::sqrt(params.aerial_density / lines);  // each line gets its share
  const Vec3 centre(box.center().x(), box.center().y(), 0.0);
  for (int line = 0; line < lines; ++line) {
    // The second line flies the other way on the other side, so it sees the walls the first one cannot.
    const double dir_angle = heading + (line == 1 ? M_PI : 0.0);
    const Vec3 along(std::cos(dir_angle), std::sin(dir_angle), 0.0), across(-along.y(), along.x(), 0.0);
    const double off_nadir = (2.0 + 13.0 * uniform01(rng)) * M_PI / 180.0;
    const double pitch = (-4.0 + 8.0 * uniform01(rng)) * M_PI / 180.0;
    const Vec3 track = centre + kAerialFlightHeight * std::tan(off_nadir) * across;  // the line's point abeam
    scan.scanners.push_back(track + Vec3(0, 0, kAerialFlightHeight));
    // Ground samples on a jittered grid in the line's frame, covering the building and its margin.
    const double half = 0.5 * (box.max - box.min).head<2>().norm() + margin;
    const int n = static_cast<int>(std::ceil(2.0 * half / spacing));
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        const double u = -half + (i + uniform01(rng)) * spacing, v = -half + (j + uniform01(rng)) * spacing;
        const Vec3 target = centre + u * along + v * across;
        if (target.x() < box.min.x() - margin || target.x() > box.max.x() + margin ||
            target.y() < box.min.y() - margin || target.y() > box.max.y() + margin)
          continue;
        const Vec3 sensor = track + (u - kAerialFlightHeight * std::tan(pitch)) * along + Vec3(0, 0, kAerialFlightHeight);
        const Vec3 dir = (target - sensor).normalized();
        auto hit = caster.first_hit(sensor, dir);
        if (hit && std::abs(face_planes[hit->face].normal.dot(dir)) < 0.02) hit.reset();  // grazing: no echo
        const double surface_t = hit ? hit->t : std::numeric_limits<double>::infinity();
        // A crown in front of the surface returns an echo from its foliage for a share of the rays.
        std::optional<double> crown_t;
        for (const Crown& c : trees)
          if (auto cross = c.crossing(sensor, dir); cross && cross->first < surface_t && !crown_t)
            if (uniform01(rng) < kCrownEchoShare)
              crown_t = cross->first + 0.4 * uniform01(rng) * (std::min(cross->second, surface_t) - cross->first);
        const double noise = params.aerial_range_noise * gaussian(rng);
        if (crown_t) {
          Vec3 nrm(gaussian(rng), gaussian(rng), std::abs(gaussian(rng)) + 0.5);  // foliage: no plane
          scan.cloud.points.push_back(sensor + (*crown_t + noise) * dir);
          scan.cloud.normals.push_back(nrm.normalized());
          scan.point_plane.push_back(-1);
        } else if (hit) {
          const Vec3 nf = face_planes[hit->face].normal;
          scan.cloud.points.push_back(sensor + (hit->t + noise) * dir);
          scan.cloud.normals.push_back(nf.dot(dir) < 0 ? nf : Vec3(-nf));
          const bool on_truth = static_cast<std::size_t>(hit->face) < truth_faces;
          const int plane = on_truth ? scan.face_plane[hit->face] : -1;
          scan.point_plane.push_back(plane);
          if (on_truth) ++scan.planes[plane].points;
        } else {
          continue;
        }
        scan.point_scanner.push_back(line);
      }
  }
}

/// The indoor models' scan: the stations' scans registered and thinned to one density, as a survey
/// delivers them. Points are drawn uniformly on the truth's faces (about `count` in all, density = count /
/// area); a point is kept when some scanner sees it: the first hit from the scanner towards it is on its
/// face, at an incidence of at least 6 degrees off grazing (|cos| >= 0.1; thinner returns than that do
/// not survive the thinning). It is then measured from the nearest such scanner (range noise sigma along
/// that ray; normal towards it). Hidden faces (tops above the scanners, sides facing a nearby wall at a
/// grazing view) get no points. Points are ordered by face, then by draw.
void scan_visible_surface(SynthScan& scan, const std::vector<Plane>& face_planes, std::size_t count, double sigma,
                          std::mt19937_64& rng) {
  const RayCaster caster(scan.truth, face_planes);
  double area = 0.0;
  for (const SynthPlane& p : scan.planes) area += p.area;
  const double density = static_cast<double>(count) / std::max(area, 1e-300);
  const double diag = bounding_box(scan.truth.vertices).diagonal();
  std::vector<std::size_t> order(scan.scanners.size());
  for (std::size_t f = 0; f < scan.truth.faces.size(); ++f) {
    const auto& loop = scan.truth.faces[f];
    const Vec3& a = scan.truth.vertices[loop[0]];
    for (std::size_t i = 1; i + 1 < loop.size(); ++i) {  // the face's fan triangles (faces are convex)
      const Vec3& b = scan.truth.vertices[loop[i]];
      const Vec3& c = scan.truth.vertices[loop[i + 1]];
      const double expected = 0.5 * (b - a).cross(c - a).norm() * density;
      const auto draws = static_cast<std::size_t>(std::floor(expected + uniform01(rng)));
      for (std::size_t d = 0; d < draws; ++d) {
        double u = uniform01(rng), v = uniform01(rng);
        if (u + v > 1) u = 1 - u, v = 1 - v;
        const Vec3 p = a + u * (b - a) + v * (c - a);
        for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
        std::sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) {
          const double dx = (scan.scanners[x] - p).squaredNorm(), dy = (scan.scanners[y] - p).squaredNorm();
          return dx != dy ? dx < dy : x < y;
        });
        for (std::size_t sc : order) {
          const Vec3& o = scan.scanners[sc];
          const double range = (p - o).norm();
          const Vec3 dir = (p - o) / range;
          const Vec3& n = face_planes[f].normal;
          if (std::abs(n.dot(dir)) < 0.1) continue;
          const auto hit = caster.first_hit(o, dir);
          if (!hit || scan.face_plane[hit->face] != scan.face_plane[f] || std::abs(hit->t - range) > 1e-7 * diag) continue;
          const double measured = range + (sigma > 0 ? sigma * gaussian(rng) : 0.0);
          scan.cloud.points.push_back(o + measured * dir);
          scan.cloud.normals.push_back(n.dot(dir) < 0 ? n : Vec3(-n));  // towards the scanner
          scan.point_plane.push_back(scan.face_plane[f]);
          scan.point_scanner.push_back(static_cast<int>(sc));
          ++scan.planes[scan.face_plane[f]].points;
          break;
        }
      }
    }
  }
}

}  // namespace

std::vector<std::string> synth_model_names() {
  return {"box", "house", "dormer_house", "bracket", "room", "courtyard"};
}

std::vector<std::string> synth_aerial_model_names() {
  return {"aerial_flat", "aerial_gable", "aerial_hip", "aerial_shed", "aerial_dormer", "aerial_mixed", "aerial_steep"};
}

std::vector<std::string> synth_indoor_model_names() { return {"hall", "meeting_room", "office"}; }

SynthScan run_synth(const std::string& model_name, const SynthParams& params) {
  if (params.blocks < 0 || params.planes < 0 || !(params.density >= 0) || !std::isfinite(params.density))
    throw Error(Status::BadInput, "synth", "blocks, planes and density must be >= 0 (finite)");
  std::optional<Model> model = synth_detail::build_model(model_name, params);
  if (!model) {
    std::string names;
    std::vector<std::string> all = synth_model_names();
    for (const auto& n : synth_aerial_model_names()) all.push_back(n);
    for (const auto& n : synth_indoor_model_names()) all.push_back(n);
    for (const auto& n : all) names += (names.empty() ? "" : ", ") + n;
    throw Error(Status::BadInput, "synth", "unknown model '" + model_name + "' (valid: " + names + ")");
  }
  if (!(params.noise >= 0.0) || !std::isfinite(params.noise))
    throw Error(Status::BadInput, "synth", "noise must be a finite value >= 0 (got " + std::to_string(params.noise) + ")");
  if (params.target_points == 0) throw Error(Status::BadInput, "synth", "target_points must be > 0");
  for (const Vec3& s : params.scanners)
    if (!s.allFinite()) throw Error(Status::BadInput, "synth", "scanner position is not finite");

  if (model->aerial && (!(params.aerial_density > 0) || !std::isfinite(params.aerial_density) ||
                        !(params.aerial_range_noise >= 0) || !std::isfinite(params.aerial_range_noise)))
    throw Error(Status::BadInput, "synth", "aerial density must be > 0 and range noise >= 0 (finite)");

  SynthScan scan;
  scan.model = model_name;
  scan.seed = params.seed;
  scan.truth = std::move(model->mesh);
  scan.indoor = model->indoor;
  scan.aerial = model->aerial;
  scan.blocks = std::move(model->blocks);
  std::vector<Plane> face_planes;
  group_planes(scan.truth, scan.planes, scan.face_plane, face_planes);
  scan.polygon_faces = polygon_regions(scan.truth, scan.face_plane);
  // Points and normals use the plane of the group, so every point of a plane id lies on that very plane.
  for (std::size_t f = 0; f < face_planes.size(); ++f) face_planes[f] = scan.planes[scan.face_plane[f]].plane;
  std::mt19937_64 rng(params.seed);
  if (scan.aerial) {
    scan.noise = params.aerial_range_noise / bounding_box(scan.truth.vertices).diagonal();
    scan_aerial(scan, face_planes, params, rng);
    if (scan.cloud.empty()) throw Error(Status::BadInput, "synth", "the aerial scan of '" + model_name + "' has no point");
    scan.cloud.source = "synth:" + model_name;
    return scan;
  }
  const double diag = bounding_box(scan.truth.vertices).diagonal();
  const double sigma = params.noise * (model->noise_length > 0 ? model->noise_length : diag);
  scan.noise = model->noise_length > 0 ? sigma / diag : params.noise;
  scan.target_points = params.target_points;
  if (const double density = params.density > 0 ? params.density : model->density; density > 0) {
    double area = 0.0;
    for (const SynthPlane& p : scan.planes) area += p.area;
    scan.target_points = static_cast<std::size_t>(std::llround(std::max(1.0, density * area)));
  }
  scan.scanners = params.scanners.empty() ? model->scanners : params.scanners;
  if (model->indoor && model->density > 0) {  // the indoor models: a registered scan at a uniform density
    scan_visible_surface(scan, face_planes, scan.target_points, params.noise * model->noise_length, rng);
    if (scan.cloud.empty()) throw Error(Status::BadInput, "synth", "no scanner sees the model '" + model_name + "'");
    scan.cloud.source = "synth:" + model_name;
    return scan;
  }

  const RayCaster caster(scan.truth, face_planes);
  const BBox box = bounding_box(scan.truth.vertices);
  std::vector<ScannerRays> scanner_ray_sets;
  for (const Vec3& s : scan.scanners) scanner_ray_sets.push_back(scanner_rays(s, box, rng));

  // A valid return: first hit, seen at an incidence not too grazing for a real LiDAR to get an echo.
  auto cast = [&](std::size_t s, const Vec3& dir) -> std::optional<RayCaster::Hit> {
    auto hit = caster.first_hit(scan.scanners[s], dir);
    if (hit && std::abs(face_planes[hit->face].normal.dot(dir)) < 0.02) return std::nullopt;
    return hit;
  };

  // Pilot pass to learn the fraction of rays that hit, then the ray count that gives ~target_points.
  // The pilot grows until it sees enough hits, so a small or distant model is not mistaken for an invisible one.
  double pilot_density = 2048.0 / (4.0 * M_PI);  // rays per steradian
  std::size_t pilot_hits = 0;
  for (;;) {
    pilot_hits = 0;
    for (std::size_t s = 0; s < scan.scanners.size(); ++s) {
      const std::size_t n = scanner_ray_sets[s].count(pilot_density);
      for (std::size_t i = 0; i < n; ++i)
        if (cast(s, scanner_ray_sets[s].direction(i, n))) ++pilot_hits;
    }
    if (pilot_hits >= 256 || pilot_density > 1e7) break;
    pilot_density *= 8;
  }
  if (pilot_hits == 0) throw Error(Status::BadInput, "synth", "no scanner sees the model '" + model_name + "'");
  const double density = pilot_density * static_cast<double>(scan.target_points) / static_cast<double>(pilot_hits);

  for (std::size_t s = 0; s < scan.scanners.size(); ++s) {
    const Vec3& origin = scan.scanners[s];
    const std::size_t rays = scanner_ray_sets[s].count(density);
    for (std::size_t i = 0; i < rays; ++i) {
      const Vec3 dir = scanner_ray_sets[s].direction(i, rays);
      auto hit = cast(s, dir);
      if (!hit) continue;
      const double range = hit->t + (sigma > 0 ? sigma * gaussian(rng) : 0.0);
      const Vec3 n = face_planes[hit->face].normal;
      scan.cloud.points.push_back(origin + range * dir);
      scan.cloud.normals.push_back(n.dot(dir) < 0 ? n : Vec3(-n));  // towards the scanner
      const int plane = scan.face_plane[hit->face];
      scan.point_plane.push_back(plane);
      scan.point_scanner.push_back(static_cast<int>(s));
      ++scan.planes[plane].points;
    }
  }
  scan.cloud.source = "synth:" + model_name;
  return scan;
}

void write_synth(const SynthScan& scan, const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw Error(Status::FileNotFound, "synth", "cannot create output folder '" + dir + "': " + ec.message());
  const std::filesystem::path root(dir);
  write_points((root / "points.ply").string(), scan.cloud, FileEncoding::Binary);
  write_mesh((root / "truth.obj").string(), scan.truth);

  nlohmann::json j;
  j["model"] = scan.model;
  j["seed"] = scan.seed;
  j["noise"] = scan.noise;
  j["noise_sigma"] = scan.noise * bounding_box(scan.truth.vertices).diagonal();
  j["target_points"] = scan.target_points;
  j["points"] = scan.cloud.size();
  j["diagonal"] = bounding_box(scan.truth.vertices).diagonal();
  j["aerial"] = scan.aerial;
  j["polygon_faces"] = scan.polygon_faces;
  j["solid"] = scan.indoor ? "interior air of the room (truth normals point away from the scanners)"
                           : "model volume (truth normals point out of it)";
  j["scanners"] = nlohmann::json::array();
  for (const Vec3& s : scan.scanners) j["scanners"].push_back({s.x(), s.y(), s.z()});
  j["planes"] = nlohmann::json::array();
  for (std::size_t k = 0; k < scan.planes.size(); ++k) {
    const SynthPlane& p = scan.planes[k];
    j["planes"].push_back({{"id", k},
                           {"normal", {p.plane.normal.x(), p.plane.normal.y(), p.plane.normal.z()}},
                           {"offset", p.plane.offset},
                           {"area", p.area},
                           {"points", p.points}});
  }
  if (!scan.blocks.empty()) {
    j["blocks"] = nlohmann::json::array();
    for (const SynthBlock& b : scan.blocks) {
      j["blocks"].push_back({{"kind", b.kind},
                             {"min", {b.box.min.x(), b.box.min.y(), b.box.min.z()}},
                             {"max", {b.box.max.x(), b.box.max.y(), b.box.max.z()}},
                             {"angle", b.angle}});
      if (b.own.valid()) {
        j["blocks"].back()["own_min"] = {b.own.min.x(), b.own.min.y(), b.own.min.z()};
        j["blocks"].back()["own_max"] = {b.own.max.x(), b.own.max.y(), b.own.max.z()};
        j["blocks"].back()["origin"] = {b.origin.x(), b.origin.y(), b.origin.z()};
      }
    }
  }
  AtomicFile out((root / "planes.json").string(), "synth");
  out.stream() << j.dump(2) << '\n';
  out.commit();
}

}  // namespace hsr
