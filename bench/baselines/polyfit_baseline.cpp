// polyfit_baseline INPUT OUTPUT [--time-limit S] [--report R.json]
//
// Peer baseline "PolyFit" (Nan & Wonka, ICCV 2017) as shipped in CGAL 5.5: Polygonal_surface_reconstruction
// on the planes hsr's structure stage detects (run_structure: each point's plane index, -1 when unassigned),
// with the points' normals from that stage, default weights (fitting 0.43, coverage 0.27, complexity 0.30),
// and the face-selection integer program solved by GLPK. Using hsr's planes means the comparison is about
// the partition and the selection, not about plane detection.
//
// The whole run happens in a forked child with a wall-clock limit (CGAL 5.5's GLPK traits expose no time
// limit): on the limit the child is killed, "timed out" is printed and the exit code is 3. Exit codes: see
// baseline_common.h. Writes a polygon mesh (hsr::write_mesh: .obj/.off/.ply) and, with --report, a JSON
// summary (status, message, seconds, peak_memory_mb, planes, vertices, faces).
#include "baseline_common.h"

#include "core/error.h"
#include "core/log.h"
#include "io/io.h"
#include "structure/structure.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/GLPK_mixed_integer_program_traits.h>
#include <CGAL/Polygonal_surface_reconstruction.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/property_map.h>

#include <cstdio>
#include <cstdlib>
#include <tuple>

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Vector = Kernel::Vector_3;
using PointWithPlane = std::tuple<Point, Vector, int>;
using PointMap = CGAL::Nth_of_tuple_property_map<0, PointWithPlane>;
using NormalMap = CGAL::Nth_of_tuple_property_map<1, PointWithPlane>;
using PlaneIndexMap = CGAL::Nth_of_tuple_property_map<2, PointWithPlane>;
using Mesh = CGAL::Surface_mesh<Point>;

hsr::PolygonMesh to_polygon_mesh(const Mesh& mesh, const hsr::Vec3& origin) {
  hsr::PolygonMesh out;
  out.origin = origin;
  std::vector<std::uint32_t> index(mesh.number_of_vertices() + mesh.number_of_removed_vertices(), 0);
  for (auto v : mesh.vertices()) {
    index[v.idx()] = static_cast<std::uint32_t>(out.vertices.size());
    const Point& p = mesh.point(v);
    out.vertices.emplace_back(p.x(), p.y(), p.z());
  }
  for (auto f : mesh.faces()) {
    std::vector<std::uint32_t> face;
    for (auto v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) face.push_back(index[v.idx()]);
    out.faces.push_back(std::move(face));
  }
  return out;
}

int reconstruct(const std::string& input, const std::string& output, const std::string& report_path) {
  const double start = hsr::log::now_seconds();
  nlohmann::json report;
  report["method"] = "polyfit";
  report["input"] = input;
  auto finish = [&](int code, const std::string& message) {
    report["message"] = message;
    report["seconds"] = hsr::log::now_seconds() - start;
    report["peak_memory_mb"] = hsr::log::peak_memory_mb();
    hsr::bench::write_report(report_path, report, code);
    std::printf("polyfit_baseline: %s%s%s\n", code == hsr::bench::kOk ? "ok" : "failed",
                message.empty() ? "" : ": ", message.c_str());
    return code;
  };

  const hsr::PointCloud cloud = hsr::read_points(input);
  const hsr::SceneStructure structure = hsr::run_structure(cloud);
  report["points"] = cloud.size();
  report["planes"] = structure.planes.size();

  std::vector<PointWithPlane> points;
  points.reserve(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const hsr::Vec3& p = cloud.points[i];
    const hsr::Vec3& n = structure.normals[i];
    points.emplace_back(Point(p.x(), p.y(), p.z()), Vector(n.x(), n.y(), n.z()), structure.point_plane[i]);
  }
  CGAL::Polygonal_surface_reconstruction<Kernel> psr(points, PointMap(), NormalMap(), PlaneIndexMap());
  if (!psr.error_message().empty()) return finish(hsr::bench::kFailed, psr.error_message());

  Mesh mesh;
  if (!psr.reconstruct<CGAL::GLPK_mixed_integer_program_traits<double>>(mesh))
    return finish(hsr::bench::kFailed, psr.error_message().empty() ? "no solution" : psr.error_message());
  if (mesh.number_of_faces() == 0) return finish(hsr::bench::kFailed, "empty mesh");

  const hsr::PolygonMesh out = to_polygon_mesh(mesh, cloud.origin);
  hsr::write_mesh(output, out);
  report["vertices"] = out.num_vertices();
  report["faces"] = out.num_faces();
  return finish(hsr::bench::kOk, "");
}

}  // namespace

int main(int argc, char** argv) {
  hsr::bench::Args args;
  try {
    args = hsr::bench::parse_args(argc, argv, {"--time-limit", "--report"});
    if (args.positional.size() != 2) throw std::runtime_error("expected INPUT OUTPUT");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "polyfit_baseline: %s\nusage: polyfit_baseline INPUT OUTPUT [--time-limit S] [--report R.json]\n",
                 e.what());
    return hsr::bench::kUsage;
  }
  hsr::log::set_level(hsr::log::Level::Quiet);
  const double limit = std::atof(args.get("--time-limit", "300").c_str());
  const std::string report_path = args.get("--report");
  const double start = hsr::log::now_seconds();
  const int code = hsr::bench::run_with_time_limit(
      [&] {
        try {
          return reconstruct(args.positional[0], args.positional[1], report_path);
        } catch (const std::exception& e) {
          std::fprintf(stderr, "polyfit_baseline: %s\n", e.what());
          nlohmann::json r = {{"method", "polyfit"}, {"message", e.what()}};
          hsr::bench::write_report(report_path, r, hsr::bench::kFailed);
          return static_cast<int>(hsr::bench::kFailed);
        }
      },
      limit);
  if (code == hsr::bench::kTimedOut || code == hsr::bench::kCrashed) {
    const bool timed_out = code == hsr::bench::kTimedOut;
    char message[128];
    std::snprintf(message, sizeof message, timed_out ? "timed out after %g s" : "crashed (killed by a signal)", limit);
    std::printf("polyfit_baseline: %s\n", message);
    nlohmann::json r = {{"method", "polyfit"}, {"message", message}, {"seconds", hsr::log::now_seconds() - start}};
    hsr::bench::write_report(report_path, r, code);
  }
  return code;
}
