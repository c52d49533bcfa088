// poisson_qem_baseline INPUT OUTPUT --faces N [--time-limit S] [--report R.json]
//
// Peer baseline "Poisson + QEM": CGAL 5.5 Poisson surface reconstruction
// (poisson_surface_reconstruction_delaunay, default mesher criteria, spacing = mean distance to the 6 nearest
// neighbours), then Garland-Heckbert edge collapse (GarlandHeckbert_plane_policies: plane quadrics, optimal
// placement) until the mesh has about N triangles (stop below 3N/2 edges, i.e. N faces on a closed mesh).
// bench/run.sh passes hsr's facet count on the same input, so conciseness is compared at an equal budget.
//
// Normals: the file's when it has them (as hsr uses them), else those of hsr's structure stage (PCA,
// oriented by minimum spanning tree). Poisson needs consistently oriented normals; that is its weak spot on
// scans whose normals are not oriented, and the table shows it.
// Time limit, exit codes and --report as polyfit_baseline (baseline_common.h).
#include "baseline_common.h"

#include "core/log.h"
#include "core/spacing.h"
#include "io/io.h"
#include "structure/structure.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Count_stop_predicate.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/GarlandHeckbert_plane_policies.h>
#include <CGAL/Surface_mesh_simplification/edge_collapse.h>
#include <CGAL/poisson_surface_reconstruction.h>
#include <CGAL/property_map.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <utility>

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Vector = Kernel::Vector_3;
using PointWithNormal = std::pair<Point, Vector>;
using Mesh = CGAL::Surface_mesh<Point>;
namespace SMS = CGAL::Surface_mesh_simplification;

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

int reconstruct(const std::string& input, const std::string& output, std::size_t target_faces,
                const std::string& report_path) {
  const double start = hsr::log::now_seconds();
  nlohmann::json report;
  report["method"] = "poisson_qem";
  report["input"] = input;
  report["target_faces"] = target_faces;
  auto finish = [&](int code, const std::string& message) {
    return hsr::bench::finish_run("poisson_qem_baseline", report, start, report_path, code, message);
  };

  const hsr::PointCloud cloud = hsr::read_points(input);
  report["points"] = cloud.size();
  std::vector<hsr::Vec3> normals = cloud.normals;
  report["normals"] = cloud.has_normals() ? "file" : "hsr structure stage (estimated, MST-oriented)";
  if (!cloud.has_normals()) normals = hsr::run_structure(cloud).normals;

  std::vector<PointWithNormal> points;
  points.reserve(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const hsr::Vec3& p = cloud.points[i];
    const hsr::Vec3& n = normals[i];
    points.emplace_back(Point(p.x(), p.y(), p.z()), Vector(n.x(), n.y(), n.z()));
  }
  const double spacing = hsr::average_spacing(cloud.points, 6);
  report["spacing"] = spacing;

  Mesh mesh;
  if (!CGAL::poisson_surface_reconstruction_delaunay(points.begin(), points.end(),
                                                     CGAL::First_of_pair_property_map<PointWithNormal>(),
                                                     CGAL::Second_of_pair_property_map<PointWithNormal>(), mesh,
                                                     spacing))
    return finish(hsr::bench::kFailed, "Poisson reconstruction failed");
  if (mesh.number_of_faces() == 0) return finish(hsr::bench::kFailed, "Poisson produced an empty mesh");
  report["poisson_faces"] = mesh.number_of_faces();

  if (mesh.number_of_faces() > target_faces) {
    const std::size_t target_edges = static_cast<std::size_t>(std::ceil(1.5 * static_cast<double>(target_faces)));
    SMS::GarlandHeckbert_plane_policies<Mesh, Kernel> policies(mesh);
    SMS::Count_stop_predicate<Mesh> stop(target_edges);
    SMS::edge_collapse(mesh, stop,
                       CGAL::parameters::get_cost(policies.get_cost()).get_placement(policies.get_placement()));
    mesh.collect_garbage();
  }

  const hsr::PolygonMesh out = to_polygon_mesh(mesh, cloud.origin);
  hsr::write_mesh(output, out);
  report["vertices"] = out.num_vertices();
  report["faces"] = out.num_faces();
  return finish(hsr::bench::kOk, "");
}

}  // namespace

int main(int argc, char** argv) {
  hsr::bench::Args args;
  long faces = 0;
  try {
    args = hsr::bench::parse_args(argc, argv, {"--faces", "--time-limit", "--report"});
    if (args.positional.size() != 2) throw std::runtime_error("expected INPUT OUTPUT");
    faces = std::atol(args.get("--faces", "0").c_str());
    if (faces < 4) throw std::runtime_error("--faces N needs N >= 4");
  } catch (const std::exception& e) {
    std::fprintf(stderr,
                 "poisson_qem_baseline: %s\nusage: poisson_qem_baseline INPUT OUTPUT --faces N [--time-limit S] "
                 "[--report R.json]\n",
                 e.what());
    return hsr::bench::kUsage;
  }
  hsr::log::set_level(hsr::log::Level::Quiet);
  const double limit = std::atof(args.get("--time-limit", "300").c_str());
  const std::string report_path = args.get("--report");
  return hsr::bench::run_baseline("poisson_qem_baseline", "poisson_qem", limit, report_path, [&] {
    return reconstruct(args.positional[0], args.positional[1], static_cast<std::size_t>(faces), report_path);
  });
}
