// First-hit ray casting for the simulated scanner: an AABB tree over the fan triangles of the model's
// convex faces. The hit distance is recomputed from the face's own plane so that noise-free points lie on
// the truth to rounding precision.
#include "synth/synth_internal.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <Eigen/Geometry>

#include <cmath>

namespace hsr::synth_detail {
namespace {
using Epick = CGAL::Exact_predicates_inexact_constructions_kernel;
using Triangle = Epick::Triangle_3;
using TriangleIt = std::vector<Triangle>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<Epick, TriangleIt>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Epick, Primitive>>;
Epick::Point_3 to_point(const Vec3& p) { return {p.x(), p.y(), p.z()}; }
}  // namespace

struct RayCaster::Impl {
  std::vector<Triangle> triangles;
  std::vector<int> triangle_face;
  std::vector<Plane> face_planes;
  Tree tree;
};

RayCaster::RayCaster(const PolygonMesh& mesh, const std::vector<Plane>& face_planes) : impl_(new Impl) {
  impl_->face_planes = face_planes;
  const double min_area = 1e-14 * std::pow(bounding_box(mesh.vertices).diagonal(), 2);
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    const auto& loop = mesh.faces[f];
    for (std::size_t i = 1; i + 1 < loop.size(); ++i) {
      const Vec3& a = mesh.vertices[loop[0]];
      const Vec3& b = mesh.vertices[loop[i]];
      const Vec3& c = mesh.vertices[loop[i + 1]];
      if ((b - a).cross(c - a).norm() < min_area) continue;  // collinear T-vertex: zero-area fan triangle
      impl_->triangles.emplace_back(to_point(a), to_point(b), to_point(c));
      impl_->triangle_face.push_back(static_cast<int>(f));
    }
  }
  impl_->tree.insert(impl_->triangles.cbegin(), impl_->triangles.cend());
  impl_->tree.build();
}

RayCaster::~RayCaster() = default;

std::optional<RayCaster::Hit> RayCaster::first_hit(const Vec3& origin, const Vec3& dir) const {
  const Epick::Ray_3 ray(to_point(origin), Epick::Vector_3(dir.x(), dir.y(), dir.z()));
  auto prim = impl_->tree.first_intersected_primitive(ray);
  if (!prim) return std::nullopt;
  const int tri = static_cast<int>(*prim - impl_->triangles.cbegin());
  const int face = impl_->triangle_face[tri];
  const Plane& pl = impl_->face_planes[face];
  const double denom = pl.normal.dot(dir);
  if (std::abs(denom) < 1e-12) return std::nullopt;  // ray in the face's plane
  const double t = -pl.signed_distance(origin) / denom;
  if (!(t > 0)) return std::nullopt;
  return Hit{face, t};
}

}  // namespace hsr::synth_detail
