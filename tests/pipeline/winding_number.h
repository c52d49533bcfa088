// Inside or outside a closed polygon mesh, for the pipeline's tests: the generalised winding number of a point
// (1 inside a closed outward-oriented solid, 0 outside), summed over the fan triangles of each face (Van Oosterom
// and Strackee's solid angle).
#pragma once

#include "core/types.h"

#include <cmath>
#include <cstddef>

namespace hsr::test {

inline double winding_number(const PolygonMesh& m, const Vec3& p) {
  double total = 0;
  for (const auto& f : m.faces)
    for (std::size_t i = 1; i + 1 < f.size(); ++i) {
      const Vec3 a = m.vertices[f[0]] - p, b = m.vertices[f[i]] - p, c = m.vertices[f[i + 1]] - p;
      const double la = a.norm(), lb = b.norm(), lc = c.norm();
      total += 2 * std::atan2(a.dot(b.cross(c)), la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb);
    }
  return total / (4 * M_PI);
}

}  // namespace hsr::test
