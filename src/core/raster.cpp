#include "core/raster.h"

#include <algorithm>
#include <cmath>

namespace hsr {

bool Raster::sample(double x, double y, double& out) const {
  if (width <= 0 || height <= 0) return false;
  // Continuous cell coordinates of the point, 0 at the first cell's centre.
  const double u = (x - x0) / dx - 0.5, v = (y - y0) / dy - 0.5;
  if (!(u >= -0.5 && u <= width - 0.5 && v >= -0.5 && v <= height - 0.5)) return false;
  const double uc = std::clamp(u, 0.0, static_cast<double>(width - 1));
  const double vc = std::clamp(v, 0.0, static_cast<double>(height - 1));
  const int c0 = std::min(static_cast<int>(std::floor(uc)), width - 1), r0 = std::min(static_cast<int>(std::floor(vc)), height - 1);
  const int c1 = std::min(c0 + 1, width - 1), r1 = std::min(r0 + 1, height - 1);
  const double fu = uc - c0, fv = vc - r0;
  const auto at = [&](int c, int r) { return static_cast<double>(z[static_cast<std::size_t>(r) * static_cast<std::size_t>(width) + static_cast<std::size_t>(c)]); };
  const double a = at(c0, r0), b = at(c1, r0), c = at(c0, r1), d = at(c1, r1);
  // A missing neighbour is only acceptable when its weight is zero.
  const double wa = (1 - fu) * (1 - fv), wb = fu * (1 - fv), wc = (1 - fu) * fv, wd = fu * fv;
  double sum = 0, weight = 0;
  for (const auto& [h, w] : {std::pair{a, wa}, std::pair{b, wb}, std::pair{c, wc}, std::pair{d, wd}}) {
    if (w == 0) continue;
    if (!std::isfinite(h)) return false;
    sum += w * h;
    weight += w;
  }
  if (!(weight > 0)) return false;
  out = sum / weight;
  return true;
}

}  // namespace hsr
