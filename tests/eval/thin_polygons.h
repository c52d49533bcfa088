// The polygon class of the eval crash (issue 15): a piece of a coplanar region split around a hole, here
// a thin frame around a large hole cut open on one side, i.e. a "U"-shaped strip of width t, with
// vertices along every side (the flat corners that T-junction resolution adds), on a tilted plane. The corners are exact rationals on the plane
// z = a x + b y + c (with the axes permuted), rounded to doubles as extraction writes them. With a width
// near or below the coordinates' rounding, the rounded polygon may touch or cross itself although the
// rational one is simple; CGAL 5.5's PMP::triangulate_faces (Projection_traits_3 on Epick) walks off its
// triangulation on such polygons (SIGSEGV in insert_constraint / find_intersected_faces with assertions
// off): seeds 1511, 4017 and 4375 of the first 10,000 below did so when this was written, all with a width
// below the doubles' spacing (width_over_ulp < 1).
#pragma once

#include "core/types.h"

#include <gmpxx.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

namespace hsr::test {

struct ThinPolygon {
  std::vector<Vec3> loop;        ///< the rounded corners, counter-clockwise about their plane's normal
  double width_over_size = 0;    ///< width t of the strip / width of the U
  double width_over_ulp = 0;     ///< t / spacing of the doubles at the polygon's coordinates
};

inline double thin_uniform(std::mt19937_64& rng, double lo, double hi) {
  return lo + (hi - lo) * (static_cast<double>(rng() >> 11) * 0x1.0p-53);
}

/// One polygon of the class, deterministic for `seed`. The strip's width is 10^-e of the U's smaller side,
/// e uniform in [1, 15], so a few percent of the seeds have a width below the doubles' spacing.
inline ThinPolygon thin_u_polygon(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  mpq_class a(thin_uniform(rng, -3, 3)), b(thin_uniform(rng, -3, 3)), c(thin_uniform(rng, -100, 100));
  if (rng() % 3 == 0) a = 0;
  const int per_side = 3 + static_cast<int>(rng() % 12);
  const double w = thin_uniform(rng, 1, 100), h = thin_uniform(rng, 1, 100);
  const double t = std::pow(10.0, -thin_uniform(rng, 1, 15)) * std::min(w, h);
  const double o = thin_uniform(rng, -1000, 1000);
  const int perm = static_cast<int>(rng() % 3);
  const double xs[8][2] = {{o, o},         {o + w, o},     {o + w, o + h},     {o + w - t, o + h},
                           {o + w - t, o + t}, {o + t, o + t}, {o + t, o + h}, {o, o + h}};
  ThinPolygon out;
  for (int s = 0; s < 8; ++s) {
    const mpq_class x0(xs[s][0]), y0(xs[s][1]), x1(xs[(s + 1) % 8][0]), y1(xs[(s + 1) % 8][1]);
    for (int i = 0; i < per_side; ++i) {
      const mpq_class f(i, per_side);
      const mpq_class x = x0 + f * (x1 - x0), y = y0 + f * (y1 - y0), z = a * x + b * y + c;
      const double p[3] = {x.get_d(), y.get_d(), z.get_d()};
      out.loop.emplace_back(p[perm], p[(perm + 1) % 3], p[(perm + 2) % 3]);
    }
  }
  out.width_over_size = t / w;
  out.width_over_ulp = t / (std::nextafter(std::abs(o) + w + h, INFINITY) - (std::abs(o) + w + h));
  return out;
}

}  // namespace hsr::test
