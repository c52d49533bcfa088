// Extraction on complexes built by the real partitioners (src/partition): voxel solids, optionally rotated,
// given as their boundary squares (input polygons) and points sampled on them with outward normals.
#include "extraction/extraction.h"

#include "core/error.h"
#include "extraction/box_complex.h"
#include "partition/partition.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <map>

namespace hsr {
namespace {

using test::VoxelSet;

struct Scene {
  PartitionInput partition_input;
  PointCloud cloud;
  std::vector<int> point_plane;
  double spacing = 0;
};

/// Boundary squares of `solid` as input polygons (rotated by `rotation` about the origin), and m x m points
/// per square with outward normals. Coplanar squares share one plane, computed once so that the partition
/// sees bit-identical coefficients; the square facing the other way on the same plane uses the negated plane.
Scene make_scene(const VoxelSet& solid, const Eigen::Matrix3d& rotation, int m) {
  Scene s;
  s.spacing = 1.0 / m;
  std::map<std::array<int, 2>, std::pair<int, Plane>> planes;  // (axis, coord) -> (id, plane with +axis normal)
  auto plane_of = [&](int axis, int coord) -> std::pair<int, Plane> {
    auto it = planes.find({axis, coord});
    if (it != planes.end()) return it->second;
    Plane p;
    p.normal = rotation * Vec3::Unit(axis);
    Vec3 on = Vec3::Zero();
    on[axis] = coord;
    p.offset = -p.normal.dot(rotation * on);
    const int id = static_cast<int>(planes.size());
    planes[{axis, coord}] = {id, p};
    return {id, p};
  };
  BBox box;
  for (const auto& c : solid)
    for (int axis = 0; axis < 3; ++axis)
      for (int sign : {-1, 1}) {
        auto nb = c;
        nb[axis] += sign;
        if (solid.count(nb)) continue;
        const int coord = sign > 0 ? c[axis] + 1 : c[axis];
        auto [id, plane] = plane_of(axis, coord);
        ConvexPolygon poly;
        poly.plane_id = id;
        poly.plane = plane;
        if (sign < 0) {
          poly.plane.normal = -plane.normal;
          poly.plane.offset = -plane.offset;
        }
        const int u = (axis + 1) % 3, v = (axis + 2) % 3;
        for (auto [a, b] : {std::pair{0, 0}, {1, 0}, {1, 1}, {0, 1}}) {
          Vec3 q;
          q[axis] = coord;
          q[u] = c[u] + a;
          q[v] = c[v] + b;
          poly.vertices.push_back(rotation * q);
          box.extend(rotation * q);
        }
        s.partition_input.polygons.push_back(poly);
        for (int i = 0; i < m; ++i)
          for (int j = 0; j < m; ++j) {
            Vec3 q;
            q[axis] = coord;
            q[u] = c[u] + (i + 0.5) / m;
            q[v] = c[v] + (j + 0.5) / m;
            s.cloud.points.push_back(rotation * q);
            s.cloud.normals.push_back(poly.plane.normal);
            s.point_plane.push_back(id);
          }
      }
  s.partition_input.points_bbox = box;
  return s;
}

void check_solid(const VoxelSet& solid, bool has_holes, const std::string& name) {
  const Eigen::Matrix3d rotations[2] = {
      Eigen::Matrix3d::Identity(),
      Eigen::AngleAxisd(0.37, Vec3(1, 2, 3).normalized()).toRotationMatrix()};
  for (int r = 0; r < 2; ++r)
    for (Partitioner method : {Partitioner::Exhaustive, Partitioner::Bsp}) {
      SCOPED_TRACE(name + (r ? " rotated " : " axis-aligned ") + partitioner_name(method));
      const Scene scene = make_scene(solid, rotations[r], 6);
      PartitionParams pp;
      pp.method = method;
      const CellComplex cx = run_partition(scene.partition_input, pp);
      const ValidationReport report = validate(cx);
      EXPECT_TRUE(report.ok) << (report.problems.empty() ? "" : report.problems.front());
      ExtractionInput in;
      in.complex = &cx;
      in.cloud = &scene.cloud;
      in.point_plane = &scene.point_plane;
      in.spacing = scene.spacing;
      const ExtractionResult res = run_extraction(in, {});
      EXPECT_EQ(res.voting_points, scene.cloud.size());
      // The inside cells are exactly the solid: their exact volumes add up to it.
      Rational inside_volume = 0;
      for (std::size_t c = 0; c < cx.cells.size(); ++c)
        if (res.inside[c]) inside_volume += cx.cells[c].volume;
      // Exact for axis-aligned planes; rotated planes are rounded to doubles, so only close there.
      if (r == 0) EXPECT_EQ(inside_volume, Rational(static_cast<long>(solid.size())));
      EXPECT_NEAR(inside_volume.get_d(), double(solid.size()), 1e-9);
      EXPECT_TRUE(test::closed_and_oriented(res.mesh));
      EXPECT_TRUE(test::vertices_are_manifold(res.mesh));
      EXPECT_EQ(res.non_manifold_edges, 0u);
      EXPECT_EQ(res.non_manifold_vertices, 0u);
      EXPECT_EQ(res.repaired_cells, 0u);
      EXPECT_NEAR(test::enclosed_volume(res.mesh), double(solid.size()), 1e-9);
      for (const auto& f : res.mesh.faces) EXPECT_FALSE(test::has_repeated_vertex(f));
      if (r == 0) {
        for (const auto& f : res.mesh.faces) EXPECT_TRUE(test::face_is_simple(res.mesh, f));
        EXPECT_TRUE(test::t_junction_free(res.mesh));
      }
      if (!has_holes) EXPECT_EQ(res.mesh.faces.size(), test::expected_face_count(solid));
    }
}

TEST(ExtractionOnPartition, Cube) { check_solid({{0, 0, 0}}, false, "cube"); }

TEST(ExtractionOnPartition, ExtrudedL) { check_solid({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, false, "L"); }

TEST(ExtractionOnPartition, Staircase) {
  check_solid({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {0, 0, 1}, {1, 0, 1}, {0, 0, 2}, {0, 1, 0}, {1, 1, 0}, {2, 1, 0}}, false,
              "staircase");
}

TEST(ExtractionOnPartition, RingWithHole) {
  VoxelSet ring;
  for (int x = 0; x < 3; ++x)
    for (int y = 0; y < 3; ++y)
      if (x != 1 || y != 1) ring.insert({x, y, 0});
  check_solid(ring, true, "ring");
}

}  // namespace
}  // namespace hsr
