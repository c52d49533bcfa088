// write_3d_tiles (tiles3d.h).
#include "tiles3d/tiles3d.h"

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/face_class.h"
#include "eval/eval.h"
#include "io/cityjson.h"
#include "tiles3d/crs_gdal.h"
#include "tiles3d/glb.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>

extern "C" const char hsr_three_js[];           // src/report/embed.cpp
extern "C" const char hsr_orbit_controls_js[];  // src/report/embed.cpp
extern "C" const char hsr_gltf_loader_js[];     // embed.cpp
extern "C" const char hsr_tiles_viewer_template[];  // embed.cpp

namespace hsr {

namespace {

constexpr const char* kStage = "tiles3d";

[[noreturn]] void bad(const std::string& what) { throw Error(Status::BadInput, kStage, what); }

/// "EPSG:N" of a CityJSON referenceSystem URL (".../EPSG/0/N"), or "".
std::string epsg_of_url(const std::string& url) {
  const std::size_t at = url.rfind("/EPSG/");
  if (at == std::string::npos) return "";
  const std::size_t slash = url.rfind('/');
  return "EPSG:" + url.substr(slash + 1);
}

/// Where the tileset's frame lies: `to_frame` takes a point of the sequences' CRS into the root's frame,
/// `transform` (column-major 4 x 4) takes the frame to the tileset's coordinates (ECEF or the CRS).
struct Frame {
  std::function<bool(double&, double&, double&)> to_ecef;  ///< the CRS to ECEF (tiles3d_gdal::EarthPlace)
  Vec3 origin = Vec3::Zero();  ///< ECEF of the centre, or the centre itself
  Eigen::Matrix3d enu = Eigen::Matrix3d::Identity();  ///< rows: east, north, up in ECEF
  bool earth_fixed = false;

  Vec3 to_frame(const Vec3& p) const {
    if (!earth_fixed) return p - origin;
    double x = p.x(), y = p.y(), z = p.z();
    if (!to_ecef(x, y, z)) throw Error(Status::BadInput, kStage, "a vertex cannot be brought to ECEF");
    return enu * (Vec3(x, y, z) - origin);
  }
  std::vector<double> transform() const {
    const Eigen::Matrix3d axes = enu.transpose();  // columns: east, north, up
    return {axes(0, 0), axes(1, 0), axes(2, 0), 0, axes(0, 1), axes(1, 1), axes(2, 1), 0,
            axes(0, 2), axes(1, 2), axes(2, 2), 0, origin.x(), origin.y(), origin.z(), 1};
  }
};

/// The frame at `centre` (CRS coordinates): east-north-up on the ellipsoid when the CRS is known and
/// earth_fixed asks for it, else the CRS shifted to the centre.
Frame make_frame(const Vec3& centre, const std::string& crs, bool earth_fixed) {
  Frame f;
  f.origin = centre;
  if (crs.empty() || !earth_fixed) return f;
  tiles3d_gdal::EarthPlace place = module_function<HsrGdalEarthPlace>("gdal", "hsr_gdal_earth_place")(centre, crs);
  f.to_ecef = std::move(place.to_ecef);
  const double lon = place.lon, lat = place.lat;
  const double l = lon * M_PI / 180, p = lat * M_PI / 180;
  f.enu.row(0) = Vec3(-std::sin(l), std::cos(l), 0);
  f.enu.row(1) = Vec3(-std::sin(p) * std::cos(l), -std::sin(p) * std::sin(l), std::cos(p));
  f.enu.row(2) = Vec3(std::cos(p) * std::cos(l), std::cos(p) * std::sin(l), std::sin(p));
  f.origin = place.ecef;
  f.earth_fixed = true;
  return f;
}

/// The colour a face is drawn in: roofs red, walls off-white, ground grey (what the eye expects of a city).
std::array<float, 3> surface_colour(FaceClass c) {
  switch (c) {
    case FaceClass::Roof: return {0.80f, 0.30f, 0.25f};
    case FaceClass::Wall: return {0.92f, 0.90f, 0.86f};
    case FaceClass::Ground: return {0.45f, 0.45f, 0.45f};
    default: return {0.75f, 0.75f, 0.78f};
  }
}

/// One building as a glb mesh in the frame, glTF y-up; its box (frame, z-up) extended.
GlbMesh building_mesh(const CityBuilding& b, const Frame& frame, BBox& box, std::size_t& triangles) {
  GlbMesh m;
  m.name = b.id;
  m.extras = b.attributes;
  std::vector<Vec3> local;
  local.reserve(b.mesh.vertices.size());
  for (const Vec3& v : b.mesh.vertices) {
    local.push_back(frame.to_frame(v + b.mesh.origin));
    box.extend(local.back());
  }
  const std::vector<FaceClass> classes = face_classes_or_by_normal(b.mesh);
  for (std::size_t f = 0; f < b.mesh.faces.size(); ++f) {
    std::vector<Vec3> loop;
    for (std::uint32_t i : b.mesh.faces[f]) loop.push_back(local[i]);
    Vec3 normal = Vec3::Zero();  // Newell
    for (std::size_t i = 0; i < loop.size(); ++i) normal += loop[i].cross(loop[(i + 1) % loop.size()]);
    if (!(normal.norm() > 0)) continue;
    normal.normalize();
    std::vector<std::array<std::uint32_t, 3>> tris;
    triangulate_polygon(loop, tris);
    const std::array<float, 3> colour = surface_colour(classes[f]);
    const std::array<float, 3> n = {float(normal.x()), float(normal.z()), float(-normal.y())};
    for (const auto& t : tris) {
      for (std::uint32_t k : t) {
        const Vec3& p = loop[k];
        m.indices.push_back(static_cast<std::uint32_t>(m.positions.size()));
        m.positions.push_back({float(p.x()), float(p.z()), float(-p.y())});
        m.normals.push_back(n);
        m.colors.push_back(colour);
      }
      ++triangles;
    }
  }
  return m;
}

nlohmann::json box_volume(const BBox& b) {
  const Vec3 c = b.center(), h = 0.5 * b.size();
  return {{"box", {c.x(), c.y(), c.z(), h.x(), 0, 0, 0, h.y(), 0, 0, 0, h.z()}}};
}

void write_file(const std::filesystem::path& path, const std::string& bytes) {
  AtomicFile out(path.string(), kStage);
  out.stream().write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.commit();
}

/// The viewer page (see tiles3d.h): the template with three.js, GLTFLoader and OrbitControls inlined.
std::string viewer_page() {
  if (std::string(hsr_three_js).size() < 1000 || std::string(hsr_gltf_loader_js).size() < 1000)
    bad("three.js or its GLTFLoader was not found when hsr was built (install Debian's libjs-three and rebuild)");
  std::string page = hsr_tiles_viewer_template;
  for (const auto& [key, value] : std::map<std::string, const char*>{{"/*{{THREE_JS}}*/", hsr_three_js},
                                                                     {"/*{{GLTF_LOADER_JS}}*/", hsr_gltf_loader_js},
                                                                     {"/*{{ORBIT_CONTROLS_JS}}*/", hsr_orbit_controls_js}}) {
    const std::size_t at = page.find(key);
    if (at == std::string::npos) throw Error(Status::Internal, kStage, "viewer template lacks " + key);
    page.replace(at, key.size(), value);
  }
  return page;
}

}  // namespace

Tiles3dSummary write_3d_tiles(const std::vector<std::string>& sequences, const std::string& dir, const Tiles3dParams& params) {
  namespace fs = std::filesystem;
  if (sequences.empty()) bad("no CityJSON sequence given");
  std::vector<CityModel> models;
  std::string crs = params.crs;
  BBox all;
  for (const std::string& s : sequences) {
    models.push_back(read_cityjson(s));
    const CityModel& m = models.back();
    if (m.buildings.empty()) bad(s + " holds no building");
    const std::string own = epsg_of_url(m.reference_system);
    if (params.crs.empty() && !own.empty()) {
      if (!crs.empty() && crs != own) bad(s + " is in " + own + ", another sequence in " + crs + ": give them in one CRS");
      crs = own;
    }
    for (const CityBuilding& b : m.buildings)
      for (const Vec3& v : b.mesh.vertices) all.extend(v + b.mesh.origin);
  }
  const Frame frame = make_frame(all.center(), crs, params.earth_fixed);
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw Error(Status::FileNotFound, kStage, "cannot create output folder '" + dir + "': " + ec.message());
  Tiles3dSummary summary;
  summary.earth_fixed = frame.earth_fixed;
  summary.crs = crs;
  nlohmann::json children = nlohmann::json::array();
  BBox root;
  std::map<std::string, int> used;
  for (std::size_t i = 0; i < models.size(); ++i) {
    std::string name = fs::path(sequences[i]).filename().string();
    for (const char* tail : {".city.jsonl", ".city.json"})
      if (name.size() > std::string(tail).size() && name.compare(name.size() - std::string(tail).size(), std::string::npos, tail) == 0)
        name.resize(name.size() - std::string(tail).size());
    if (used[name]++) name += "_" + std::to_string(used[name]);
    std::vector<GlbMesh> meshes;
    BBox box;
    for (const CityBuilding& b : models[i].buildings) meshes.push_back(building_mesh(b, frame, box, summary.triangles));
    write_file(fs::path(dir) / (name + ".glb"), glb_bytes(meshes));
    summary.buildings += meshes.size();
    ++summary.contents;
    root.extend(box.min);
    root.extend(box.max);
    children.push_back({{"boundingVolume", box_volume(box)}, {"geometricError", 0}, {"content", {{"uri", name + ".glb"}}}});
  }
  const double error = root.diagonal();
  const nlohmann::json tileset = {
      {"asset", {{"version", "1.1"}, {"generator", "hsr"}}},
      {"geometricError", error},
      {"root", {{"transform", frame.transform()}, {"boundingVolume", box_volume(root)}, {"geometricError", error},
                {"refine", "ADD"}, {"children", children}}}};
  write_file(fs::path(dir) / "tileset.json", tileset.dump(1) + "\n");
  write_file(fs::path(dir) / "index.html", viewer_page());
  return summary;
}

}  // namespace hsr
