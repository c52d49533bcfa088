// Stage 1 debug dump: planes.ply, boundaries.obj, adjacency.json, structure.json (no CGAL here).
#include "structure/structure.h"

#include "core/atomic_file.h"
#include "core/error.h"
#include "io/io.h"

#include <array>
#include <cstdint>
#include <filesystem>
#include <iomanip>

namespace hsr {

namespace {

// Distinct, deterministic colours: golden-ratio hue steps, full saturation.
std::array<std::uint8_t, 3> plane_color(int i) {
  if (i < 0) return {128, 128, 128};
  const double h = std::fmod(0.61803398874989485 * i, 1.0) * 6.0;
  const int sector = static_cast<int>(h);
  const double f = h - sector;
  const auto hi = static_cast<std::uint8_t>(230), lo = static_cast<std::uint8_t>(40);
  const auto up = static_cast<std::uint8_t>(lo + f * (hi - lo)), down = static_cast<std::uint8_t>(hi - f * (hi - lo));
  switch (sector % 6) {
    case 0: return {hi, up, lo};
    case 1: return {down, hi, lo};
    case 2: return {lo, hi, up};
    case 3: return {lo, down, hi};
    case 4: return {up, lo, hi};
    default: return {hi, lo, down};
  }
}

void write_json(const std::string& path, const nlohmann::json& j) {
  AtomicFile f(path, "structure");
  f.stream() << j.dump(2) << "\n";
  f.commit();
}

}  // namespace

void write_structure_dump(const PointCloud& cloud, const SceneStructure& s, const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw Error(Status::FileNotFound, "structure", "cannot create folder " + dir + ": " + ec.message());

  // Inliers of every plane, coloured by plane.
  PointCloud inl;
  inl.origin = cloud.origin;
  std::vector<std::array<std::uint8_t, 3>> colors;
  for (std::size_t p = 0; p < s.planes.size(); ++p)
    for (int i : s.planes[p].inliers) {
      inl.points.push_back(cloud.points[i]);
      if (s.normals.size() == cloud.points.size()) inl.normals.push_back(s.normals[i]);
      colors.push_back(plane_color(static_cast<int>(p)));
    }
  write_points(dir + "/planes.ply", inl, FileEncoding::Binary, colors);

  {
    AtomicFile f(dir + "/boundaries.obj", "structure");
    auto& out = f.stream();
    out << std::setprecision(17);
    out << "# hsr structure: boundary segments, one 'l' per segment (group = plane)\n";
    std::size_t v = 0;
    for (std::size_t p = 0; p < s.planes.size(); ++p) {
      if (s.planes[p].segments.empty()) continue;
      out << "g plane_" << p << "\n";
      for (const auto& seg : s.planes[p].segments) {
        const Vec3 a = seg.a + cloud.origin, b = seg.b + cloud.origin;
        out << "v " << a.x() << " " << a.y() << " " << a.z() << "\n";
        out << "v " << b.x() << " " << b.y() << " " << b.z() << "\n";
        out << "l " << v + 1 << " " << v + 2 << "\n";
        v += 2;
      }
    }
    f.commit();
  }

  nlohmann::json adj;
  adj["adjacency"] = s.adjacency;
  adj["second_order"] = s.second_order;
  nlohmann::json lines = nlohmann::json::array();
  for (const auto& l : s.lines) {
    const Vec3 p = l.point + cloud.origin;
    lines.push_back({{"planes", {l.plane_a, l.plane_b}},
                     {"point", {p.x(), p.y(), p.z()}},
                     {"direction", {l.direction.x(), l.direction.y(), l.direction.z()}},
                     {"adjacent", l.adjacent}});
  }
  adj["lines"] = lines;
  write_json(dir + "/adjacency.json", adj);

  nlohmann::json js;
  js["source"] = cloud.source;
  js["points"] = cloud.points.size();
  js["spacing"] = s.spacing;
  js["params"] = s.params;
  nlohmann::json planes = nlohmann::json::array();
  for (const auto& p : s.planes) {
    // Equation in global coordinates: n·(x − origin) + d = 0  =>  n·x + (d − n·origin) = 0.
    const double d_global = p.plane.offset - p.plane.normal.dot(cloud.origin);
    planes.push_back({{"normal", {p.plane.normal.x(), p.plane.normal.y(), p.plane.normal.z()}},
                      {"offset", d_global},
                      {"inliers", p.inliers.size()},
                      {"area", p.area},
                      {"boundary_points", p.boundary.size()},
                      {"segments", p.segments.size()}});
  }
  js["planes"] = planes;
  write_json(dir + "/structure.json", js);
}

}  // namespace hsr
