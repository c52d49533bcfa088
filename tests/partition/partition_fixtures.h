// Polygon fixtures shared by the partition test binaries (test_partition, test_kinetic): boxes,
// squares, random convex polygon sets. Header-only, each test binary gets its own copy.
#pragma once

#include "partition/partition.h"

#include <Eigen/Geometry>

#include <cmath>
#include <random>

namespace hsr {
namespace {


BBox unit_box() {
  BBox b;
  b.extend(Vec3(0, 0, 0));
  b.extend(Vec3(1, 1, 1));
  return b;
}

// Rectangle centred at `c`, spanned by unit vectors u, v (half sizes hu, hv), on the plane through c with
// normal u x v.
ConvexPolygon rectangle(int id, const Vec3& c, const Vec3& u, const Vec3& v, double hu, double hv) {
  ConvexPolygon p;
  p.plane_id = id;
  p.plane.normal = u.cross(v).normalized();
  p.plane.offset = -p.plane.normal.dot(c);
  p.vertices = {c - hu * u - hv * v, c + hu * u - hv * v, c + hu * u + hv * v, c - hu * u + hv * v};
  return p;
}

// Axis-aligned polygon x_axis = value, covering [lo, hi] in the two other axes.
ConvexPolygon axis_polygon(int id, int axis, double value, double lo = -10, double hi = 10) {
  ConvexPolygon p;
  p.plane_id = id;
  p.plane.normal = Vec3::Zero();
  p.plane.normal[axis] = 1.0;
  p.plane.offset = -value;
  const int i = (axis + 1) % 3, j = (axis + 2) % 3;
  for (auto [a, b] : {std::pair{lo, lo}, {hi, lo}, {hi, hi}, {lo, hi}}) {
    Vec3 q;
    q[axis] = value;
    q[i] = a;
    q[j] = b;
    p.vertices.push_back(q);
  }
  return p;
}

// Big square polygon on the plane n.x + d = 0 (n need not be unit), centred at the projection of `near`.
ConvexPolygon plane_polygon(int id, const Vec3& n_in, const Vec3& near, double half = 10) {
  const Vec3 n = n_in.normalized();
  Vec3 u = n.unitOrthogonal();
  Vec3 v = n.cross(u);
  ConvexPolygon p = rectangle(id, near, u, v, half, half);
  p.plane.normal = n;
  p.plane.offset = -n.dot(near);
  return p;
}

// Big square on the plane n.x + d = 0 with exactly these (not normalised) coefficients: the partition
// reads plane coefficients exactly, so planes meant to meet in one line or point really do.
ConvexPolygon exact_plane_polygon(int id, const Vec3& n, double d, double half = 10) {
  const Vec3 unit = n.normalized();
  const Vec3 u = unit.unitOrthogonal(), v = unit.cross(u);
  const Vec3 c = -d * n / n.squaredNorm();
  ConvexPolygon p = rectangle(id, c, u, v, half, half);
  p.plane.normal = n;
  p.plane.offset = d;
  return p;
}

double uniform(std::mt19937_64& rng, double lo, double hi) {
  return lo + (hi - lo) * (static_cast<double>(rng() >> 11) * 0x1.0p-53);
}

std::vector<ConvexPolygon> random_polygons(std::uint64_t seed, int count) {
  std::mt19937_64 rng(seed);
  std::vector<ConvexPolygon> out;
  for (int i = 0; i < count; ++i) {
    Vec3 n(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1));
    if (n.norm() < 1e-3) n = Vec3::UnitZ();
    n.normalize();
    const Vec3 c(uniform(rng, 0, 1), uniform(rng, 0, 1), uniform(rng, 0, 1));
    const Vec3 u = n.unitOrthogonal();
    const Vec3 v = n.cross(u);
    if (i % 2 == 0) {
      out.push_back(rectangle(i, c, u, v, uniform(rng, 0.05, 0.6), uniform(rng, 0.05, 0.6)));
    } else {  // a convex polygon: points on an ellipse
      ConvexPolygon p;
      p.plane_id = i;
      p.plane.normal = n;
      p.plane.offset = -n.dot(c);
      const int k = 3 + static_cast<int>(rng() % 6);
      const double a = uniform(rng, 0.05, 0.6), b = uniform(rng, 0.05, 0.6);
      for (int j = 0; j < k; ++j) {
        const double t = 2 * M_PI * (j + uniform(rng, 0, 0.5)) / k;
        p.vertices.push_back(c + a * std::cos(t) * u + b * std::sin(t) * v);
      }
      out.push_back(p);
    }
  }
  return out;
}

}  // namespace
}  // namespace hsr
