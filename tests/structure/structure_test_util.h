// Tiny synthetic samplers for the structure tests (independent of src/synth).
#pragma once

#include "core/types.h"

#include <Eigen/Geometry>

#include <algorithm>

#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

namespace hsr::test {

inline double uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }
inline double gauss(std::mt19937_64& rng) {
  const double u1 = std::max(uniform01(rng), 1e-300), u2 = uniform01(rng);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2);
}

struct TruthPlane {
  Plane plane;
  Vec3 lo, hi;  // extent of the face (axis-aligned box face)
};

struct Sampled {
  PointCloud cloud;
  std::vector<int> point_face;
  std::vector<TruthPlane> faces;
};

/// Samples the 6 faces of an axis-aligned box uniformly (density `per_area` points per unit area), with
/// Gaussian noise of std `noise` along the face normal, and outward normals (optional).
inline void sample_box(Sampled& out, const Vec3& lo, const Vec3& hi, double per_area, double noise,
                       std::uint64_t seed, bool with_normals = true) {
  std::mt19937_64 rng(seed);
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
      TruthPlane f;
      f.plane.normal = Vec3::Zero();
      f.plane.normal(axis) = side ? 1.0 : -1.0;
      const double c = side ? hi(axis) : lo(axis);
      f.plane.offset = -f.plane.normal(axis) * c;
      f.lo = lo; f.hi = hi;
      f.lo(axis) = f.hi(axis) = c;
      const int face = static_cast<int>(out.faces.size());
      out.faces.push_back(f);
      const double area = (hi(a1) - lo(a1)) * (hi(a2) - lo(a2));
      const int count = static_cast<int>(std::lround(area * per_area));
      for (int i = 0; i < count; ++i) {
        Vec3 p;
        p(axis) = c + noise * gauss(rng);
        p(a1) = lo(a1) + (hi(a1) - lo(a1)) * uniform01(rng);
        p(a2) = lo(a2) + (hi(a2) - lo(a2)) * uniform01(rng);
        out.cloud.points.push_back(p);
        if (with_normals) out.cloud.normals.push_back(f.plane.normal);
        out.point_face.push_back(face);
      }
    }
}

/// A rectangle in the plane z = z0 (one face).
inline void sample_rect(Sampled& out, double x0, double x1, double y0, double y1, double z0, double per_area,
                        double noise, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  TruthPlane f;
  f.plane.normal = Vec3::UnitZ();
  f.plane.offset = -z0;
  f.lo = Vec3(x0, y0, z0); f.hi = Vec3(x1, y1, z0);
  const int face = static_cast<int>(out.faces.size());
  out.faces.push_back(f);
  const int count = static_cast<int>(std::lround((x1 - x0) * (y1 - y0) * per_area));
  for (int i = 0; i < count; ++i) {
    out.cloud.points.emplace_back(x0 + (x1 - x0) * uniform01(rng), y0 + (y1 - y0) * uniform01(rng),
                                  z0 + noise * gauss(rng));
    out.point_face.push_back(face);
  }
}

/// Distance from p to the segment [a, b].
inline double distance_to_segment(const Vec3& a, const Vec3& b, const Vec3& p) {
  const Vec3 d = b - a;
  const double t = std::clamp((p - a).dot(d) / d.squaredNorm(), 0.0, 1.0);
  return (a + t * d - p).norm();
}

/// The 4 edges of an axis-aligned rectangular face, in order around it.
inline std::array<std::pair<Vec3, Vec3>, 4> face_edges(const TruthPlane& f) {
  int axis = 0;
  for (int a = 0; a < 3; ++a) if (f.lo(a) == f.hi(a)) axis = a;
  const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
  Vec3 c01 = f.lo, c10 = f.lo;
  c01(a2) = f.hi(a2);
  c10(a1) = f.hi(a1);
  return {{{f.lo, c10}, {c10, f.hi}, {f.hi, c01}, {c01, f.lo}}};
}

/// Distance from p to the boundary (4 edges) of an axis-aligned rectangular face.
inline double distance_to_face_edges(const TruthPlane& f, const Vec3& p) {
  double best = 1e300;
  for (const auto& [a, b] : face_edges(f)) best = std::min(best, distance_to_segment(a, b, p));
  return best;
}

}  // namespace hsr::test
