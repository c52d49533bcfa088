// Stage 5 tests: the kinetic and hierarchical partitioners (DESIGN.md §2, paper §3.5). Every complex is
// checked by validate() with the input polygons (exact invariants and coverage); hand-made scenes check
// known cell counts and where regions stop.
#include "core/error.h"
#include "partition/partition.h"

#include <gtest/gtest.h>

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


std::string describe(const ValidationReport& r) {
  std::string s;
  for (const auto& p : r.problems) s += p + "\n";
  return s;
}

CellComplex run(const std::vector<ConvexPolygon>& polys, Partitioner method, int k = 1,
                std::vector<std::pair<int, int>> adjacency = {}, int max_per_domain = 40, double margin = 0.05,
                BBox box = unit_box()) {
  PartitionInput in{polys, box, std::move(adjacency)};
  PartitionParams params;
  params.method = method;
  params.kinetic_k = k;
  params.bbox_margin = margin;
  params.max_polygons_per_domain = max_per_domain;
  return run_partition(in, params);
}

// Validates with coverage and checks that volumes sum to the box.
void expect_valid(const CellComplex& cx, const std::vector<ConvexPolygon>& polys, const std::string& what) {
  ValidationReport r = validate(cx, &polys);
  EXPECT_TRUE(r.ok) << what << ":\n" << describe(r);
  Rational sum = 0;
  for (const Cell& c : cx.cells) sum += c.volume;
  EXPECT_EQ(sum, box_volume(cx)) << what;
}

TEST(Kinetic, SmokeRandom) {
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    auto polys = random_polygons(seed, 12);
    for (Partitioner m : {Partitioner::Kinetic, Partitioner::Hierarchical}) {
      CellComplex cx = run(polys, m);
      expect_valid(cx, polys, std::string(partitioner_name(m)) + " seed " + std::to_string(seed));
    }
  }
}

}  // namespace
}  // namespace hsr
