#include "fuzz_complex.h"

#include "core/error.h"
#include "eval/eval.h"
#include "io/io.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>

namespace hsr::fuzz {

namespace {

constexpr std::size_t kHeaderBytes = 2, kPolygonBytes = 8;

ConvexPolygon decode_polygon(const std::uint8_t* p, int id) {
  ConvexPolygon poly;
  poly.plane_id = id;
  Vec3 n(p[0] % 7 - 3.0, p[1] % 7 - 3.0, p[2] % 7 - 3.0);
  if (n.squaredNorm() == 0) n = Vec3::UnitZ();
  n.normalize();
  const Vec3 centre(p[3] % 17 / 16.0, p[4] % 17 / 16.0, p[5] % 17 / 16.0);
  const double radius = 0.05 + 0.75 * p[6] / 255.0;
  const int corners = 3 + p[7] % 6;
  const double phase = 0.5 * (p[7] / 18);
  poly.plane.normal = n;
  poly.plane.offset = -n.dot(centre);
  const Vec3 u = n.unitOrthogonal(), v = n.cross(u);
  for (int k = 0; k < corners; ++k) {
    const double a = phase + 2 * M_PI * k / corners;
    poly.vertices.push_back(centre + radius * (std::cos(a) * u + std::sin(a) * v));
  }
  poly.level = 1 + (p[7] / 6) % 3;
  poly.speed = (p[6] & 1) ? 1.0 : 0.5;
  return poly;
}

/// One inlier per facet between a target-inside and a target-outside cell, at its centroid, its normal
/// from the inside cell to the outside one (the side it votes outside). Box sides carrying no input plane
/// get none (their points would not vote).
void votes_for(const CellComplex& cx, const std::vector<bool>& target, PointCloud& cloud, std::vector<int>& plane_of) {
  auto inside = [&](int c) { return c >= 0 && target[static_cast<std::size_t>(c)]; };
  for (const Facet& f : cx.facets) {
    const SupportPlane& s = cx.planes[static_cast<std::size_t>(f.plane)];
    if (s.input_planes.empty() || inside(f.cells[0]) == inside(f.cells[1])) continue;
    Vec3 centroid = Vec3::Zero();
    for (std::uint32_t v : f.vertices) centroid += cx.vertices_approx[v];
    centroid /= static_cast<double>(f.vertices.size());
    const Vec3 n = s.approx.normal.normalized();  // points to cells[0]
    cloud.points.push_back(centroid);
    cloud.normals.push_back(inside(f.cells[0]) ? Vec3(-n) : n);
    plane_of.push_back(s.input_planes.front());
  }
}

/// Mesh index of each complex vertex (-1 if unused), recovered from the coordinates (mesh vertices are
/// complex vertices rounded); false when two used complex vertices round to the same doubles.
bool mesh_index_of(const CellComplex& cx, const PolygonMesh& mesh, std::vector<std::int64_t>& index) {
  std::map<std::array<double, 3>, std::int64_t> at;
  for (std::size_t k = 0; k < mesh.vertices.size(); ++k)
    at[{mesh.vertices[k].x(), mesh.vertices[k].y(), mesh.vertices[k].z()}] = static_cast<std::int64_t>(k);
  if (at.size() != mesh.vertices.size()) return false;
  index.assign(cx.vertices.size(), -1);
  std::vector<int> hits(mesh.vertices.size(), 0);
  for (std::size_t v = 0; v < cx.vertices.size(); ++v) {
    const Vec3& p = cx.vertices_approx[v];
    const auto it = at.find({p.x(), p.y(), p.z()});
    if (it == at.end()) continue;
    index[v] = it->second;
    if (++hits[static_cast<std::size_t>(it->second)] > 1) return false;
  }
  return true;
}

}  // namespace

ComplexCase decode_complex_case(const std::uint8_t* data, std::size_t size) {
  ComplexCase c;
  c.partition_input.points_bbox.min = Vec3::Zero();
  c.partition_input.points_bbox.max = Vec3::Ones();
  c.partition.threads = 1;  // libFuzzer wants one thread; results do not depend on it
  c.partition.exact_volumes = true;
  if (size < kHeaderBytes) return c;
  static const Partitioner methods[4] = {Partitioner::Exhaustive, Partitioner::Bsp, Partitioner::Kinetic,
                                         Partitioner::Hierarchical};
  static const double lambdas[4] = {0.0, 0.05, 0.5, 1.0};
  static const char* formats[4] = {"obj", "ply", "off", "obj"};
  const std::uint8_t flags = data[0];
  c.partition.method = methods[flags & 3];
  c.extraction.merge_coplanar = (flags & 4) == 0;
  c.extraction.lambda = lambdas[(flags >> 3) & 3];
  c.format = formats[(flags >> 5) & 3];
  const std::size_t wanted = 1 + data[1] % kMaxFuzzPolygons;
  const std::size_t n = std::min(wanted, (size - kHeaderBytes) / kPolygonBytes);
  for (std::size_t i = 0; i < n; ++i)
    c.partition_input.polygons.push_back(decode_polygon(data + kHeaderBytes + kPolygonBytes * i, static_cast<int>(i)));
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j)
      if ((data[kHeaderBytes + kPolygonBytes * i + 6] + data[kHeaderBytes + kPolygonBytes * j + 6]) % 3 == 0)
        c.partition_input.adjacent_planes.emplace_back(static_cast<int>(i), static_cast<int>(j));
  c.labels.assign(data + kHeaderBytes + kPolygonBytes * n, data + size);
  return c;
}

std::string check_extraction_case(const ComplexCase& c, const std::string& scratch_dir) {
  CellComplex cx;
  try {
    cx = run_partition(c.partition_input, c.partition);
  } catch (const Error& e) {
    if (e.status() == Status::BadInput || e.status() == Status::DegenerateInput) return "";
    return "partition: " + e.one_line();
  }
  std::vector<bool> target(cx.cells.size(), true);
  if (!c.labels.empty())
    for (std::size_t k = 0; k < target.size(); ++k)
      target[k] = (c.labels[(k / 8) % c.labels.size()] >> (k % 8)) & 1;

  PointCloud cloud;
  std::vector<int> plane_of;
  votes_for(cx, target, cloud, plane_of);
  if (cloud.empty()) {  // nothing votes: one point off every plane keeps the inputs well-formed
    cloud.points.push_back(Vec3::Constant(0.5));
    cloud.normals.push_back(Vec3::UnitZ());
    plane_of.push_back(-1);
  }
  ExtractionInput in;
  in.complex = &cx;
  in.cloud = &cloud;
  in.point_plane = &plane_of;
  in.spacing = 0.3;  // a vote (pi r^2 / A each) outweighs lambda times any facet's area
  ExtractionResult r;
  try {
    r = run_extraction(in, c.extraction);
  } catch (const Error& e) {
    if (e.status() == Status::DegenerateInput) return "";
    return "extraction: " + e.one_line();
  }
  if (r.mesh.faces.empty()) return "extraction returned no face";

  const Validity validity = check_validity(r.mesh);
  std::vector<std::int64_t> index;
  // A mesh whose sub-precision edges were collapsed (DECISIONS #158) is no longer the complex's vertices rounded;
  // one whose necks were zipped (#161) no longer has the complex's polygons.
  const bool exact_in_doubles = r.sub_precision_edges == 0 && r.sub_precision_necks == 0 &&
                                mesh_index_of(cx, r.mesh, index) && prove_simple_polygons(cx, r.mesh, index) == 0;
  if (r.non_manifold_edges == 0 && r.non_manifold_vertices == 0 && exact_in_doubles) {
    if (!validity.valid()) {
      write_mesh((std::filesystem::path(scratch_dir) / "invalid.obj").string(), r.mesh);  // for the post-mortem
      return "manifold extraction output is not valid: " + validity.summary();
    }
    double volume = 0;
    for (std::size_t k = 0; k < cx.cells.size(); ++k)
      if (r.inside[k]) volume += cx.cells[k].volume.get_d();
    if (std::abs(validity.volume - volume) > 1e-9 * std::max(1.0, volume))
      return "mesh volume " + std::to_string(validity.volume) + " != inside cells' volume " + std::to_string(volume);
  }

  const std::string path = (std::filesystem::path(scratch_dir) / ("mesh." + c.format)).string();
  write_mesh(path, r.mesh);
  const PolygonMesh back = read_mesh(path);
  if (back.faces != r.mesh.faces) return c.format + " round trip changed the faces";
  for (std::size_t k = 0; k < back.vertices.size(); ++k)
    if (back.vertices[k] + back.origin != r.mesh.vertices[k] + r.mesh.origin)
      return c.format + " round trip changed vertex " + std::to_string(k);

  PointCloud corners;
  corners.points = r.mesh.vertices;
  EvalParams ep;
  ep.mesh_samples = 200;
  try {
    PolygonMesh local = back;
    for (Vec3& v : local.vertices) v += back.origin - r.mesh.origin;
    local.origin = r.mesh.origin;
    const EvalResult e = run_eval(corners, local, nullptr, ep);
    if (e.validity.valid() != validity.valid()) return "eval of the written mesh disagrees with its validity";
  } catch (const Error& e) {
    if (e.status() != Status::BadInput) return "eval: " + e.one_line();  // BadInput: zero area / extent
  }
  return "";
}

}  // namespace hsr::fuzz
