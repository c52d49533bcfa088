// SMRF, the ground filter of tiles without classification (ground_filter.h: the method and its sources).
#include "city/ground_filter.h"

#include "city/city_internal.h"
#include "core/error.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>

namespace hsr {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::size_t idx(const HeightGrid& g, int i, int j) { return static_cast<std::size_t>(i) + static_cast<std::size_t>(g.nx) * j; }

/// Step 1: the lowest point per cell (NaN where a cell holds none).
HeightGrid minimum_surface(const std::vector<Vec3>& points, double cell) {
  BBox box = bounding_box(points);
  HeightGrid g;
  g.cell = cell;
  g.x0 = box.min.x();
  g.y0 = box.min.y();
  g.nx = static_cast<int>(std::floor((box.max.x() - g.x0) / cell)) + 1;
  g.ny = static_cast<int>(std::floor((box.max.y() - g.y0) / cell)) + 1;
  if (static_cast<double>(g.nx) * g.ny > 4e8)
    throw Error(Status::BadInput, kCityStage, "ground filter: the tile needs more than 4e8 cells of " + std::to_string(cell) +
                                              " (a larger SMRF cell, or a smaller tile)");
  g.z.assign(static_cast<std::size_t>(g.nx) * g.ny, kNaN);
  for (const Vec3& p : points) {
    const int i = std::min(g.nx - 1, static_cast<int>((p.x() - g.x0) / cell));
    const int j = std::min(g.ny - 1, static_cast<int>((p.y() - g.y0) / cell));
    double& z = g.z[idx(g, i, j)];
    if (std::isnan(z) || p.z() < z) z = p.z();
  }
  return g;
}

/// Fills the NaN cells: nearest filled cell first (breadth first, 4-neighbours, in index order: deterministic),
/// then `sweeps` Gauss-Seidel sweeps of the discrete Laplace equation over the filled-in cells (a harmonic
/// surface spanning each hole). A grid with no value at all stays NaN.
void inpaint(HeightGrid& g, int sweeps) {
  std::vector<std::size_t> holes;
  std::deque<std::size_t> queue;
  for (std::size_t k = 0; k < g.z.size(); ++k) {
    if (std::isnan(g.z[k])) holes.push_back(k);
    else queue.push_back(k);
  }
  if (holes.empty() || queue.empty()) return;
  while (!queue.empty()) {
    const std::size_t k = queue.front();
    queue.pop_front();
    const int i = static_cast<int>(k % g.nx), j = static_cast<int>(k / g.nx);
    const int di[4] = {-1, 1, 0, 0}, dj[4] = {0, 0, -1, 1};
    for (int d = 0; d < 4; ++d) {
      const int a = i + di[d], b = j + dj[d];
      if (a < 0 || b < 0 || a >= g.nx || b >= g.ny) continue;
      double& z = g.z[idx(g, a, b)];
      if (std::isnan(z)) {
        z = g.z[k];
        queue.push_back(idx(g, a, b));
      }
    }
  }
  for (int s = 0; s < sweeps; ++s)
    for (std::size_t k : holes) {
      const int i = static_cast<int>(k % g.nx), j = static_cast<int>(k / g.nx);
      double sum = 0;
      int n = 0;
      if (i > 0) sum += g.z[k - 1], ++n;
      if (i + 1 < g.nx) sum += g.z[k + 1], ++n;
      if (j > 0) sum += g.z[k - g.nx], ++n;
      if (j + 1 < g.ny) sum += g.z[k + g.nx], ++n;
      if (n) g.z[k] = sum / n;
    }
}

/// Running minimum (or maximum) over windows [i - r, i + r] of n values spaced `stride` apart, the window
/// truncated at the ends (van Herk / Gil-Werman: linear in n whatever r).
void running_extreme(double* v, std::size_t n, std::size_t stride, int r, bool minimum) {
  if (n == 0 || r <= 0) return;
  const std::size_t w = 2 * static_cast<std::size_t>(r) + 1;
  const double pad = minimum ? std::numeric_limits<double>::infinity() : -std::numeric_limits<double>::infinity();
  auto better = [minimum](double a, double b) { return minimum ? std::min(a, b) : std::max(a, b); };
  const std::size_t m = n + 2 * static_cast<std::size_t>(r);  // padded length
  std::vector<double> x(m, pad), g(m), h(m);
  for (std::size_t i = 0; i < n; ++i) x[i + r] = v[i * stride];
  for (std::size_t i = 0; i < m; ++i) g[i] = (i % w == 0) ? x[i] : better(g[i - 1], x[i]);
  for (std::size_t i = m; i-- > 0;) h[i] = (i + 1 == m || (i + 1) % w == 0) ? x[i] : better(h[i + 1], x[i]);
  for (std::size_t i = 0; i < n; ++i) v[i * stride] = better(h[i], g[i + 2 * r]);  // window [i, i + 2r] padded
}

/// Square-window erosion (minimum) or dilation (maximum) of radius r cells: rows, then columns.
void square_filter(HeightGrid& g, int r, bool minimum) {
  for (int j = 0; j < g.ny; ++j) running_extreme(&g.z[idx(g, 0, j)], static_cast<std::size_t>(g.nx), 1, r, minimum);
  for (int i = 0; i < g.nx; ++i)
    running_extreme(&g.z[idx(g, i, 0)], static_cast<std::size_t>(g.ny), static_cast<std::size_t>(g.nx), r, minimum);
}

/// Step 2: the progressive opening; per cell, 1 when it stands on an object.
std::vector<char> object_cells(const HeightGrid& surface, const SmrfParams& p) {
  std::vector<char> object(surface.z.size(), 0);
  HeightGrid last = surface;
  const int max_radius = std::max(1, static_cast<int>(std::ceil(p.max_window / p.cell)));
  for (int r = 1; r <= max_radius; ++r) {
    HeightGrid opened = last;
    square_filter(opened, r, true);
    square_filter(opened, r, false);
    const double threshold = p.slope * r * p.cell;
    for (std::size_t k = 0; k < object.size(); ++k)
      if (last.z[k] - opened.z[k] > threshold) object[k] = 1;
    last = std::move(opened);
  }
  return object;
}

}  // namespace

double HeightGrid::sample(double x, double y) const {
  const double u = std::clamp((x - x0) / cell - 0.5, 0.0, static_cast<double>(nx - 1));
  const double v = std::clamp((y - y0) / cell - 0.5, 0.0, static_cast<double>(ny - 1));
  const int i = std::min(nx - 2, static_cast<int>(u)), j = std::min(ny - 2, static_cast<int>(v));
  if (nx < 2 || ny < 2) {
    const int a = std::min(nx - 1, static_cast<int>(std::lround(u))), b = std::min(ny - 1, static_cast<int>(std::lround(v)));
    return at(a, b);
  }
  const double fu = u - i, fv = v - j;
  return (1 - fv) * ((1 - fu) * at(i, j) + fu * at(i + 1, j)) + fv * ((1 - fu) * at(i, j + 1) + fu * at(i + 1, j + 1));
}

double HeightGrid::slope(double x, double y) const {
  const int i = std::clamp(static_cast<int>((x - x0) / cell), 0, nx - 1);
  const int j = std::clamp(static_cast<int>((y - y0) / cell), 0, ny - 1);
  const int i0 = std::max(0, i - 1), i1 = std::min(nx - 1, i + 1), j0 = std::max(0, j - 1), j1 = std::min(ny - 1, j + 1);
  const double gx = i1 > i0 ? (at(i1, j) - at(i0, j)) / ((i1 - i0) * cell) : 0.0;
  const double gy = j1 > j0 ? (at(i, j1) - at(i, j0)) / ((j1 - j0) * cell) : 0.0;
  return std::sqrt(gx * gx + gy * gy);
}

HeightGrid ground_model_of(const std::vector<Vec3>& ground, const SmrfParams& p) {
  if (ground.empty()) throw Error(Status::BadInput, kCityStage, "ground model: no ground point");
  if (!(p.cell > 0)) throw Error(Status::BadInput, kCityStage, "ground model: the cell must be > 0");
  HeightGrid g = minimum_surface(ground, p.cell);
  inpaint(g, p.inpaint_sweeps);
  return g;
}

GroundFilterResult run_ground_filter(const std::vector<Vec3>& points, const SmrfParams& p) {
  if (points.empty()) throw Error(Status::BadInput, kCityStage, "ground filter: no point");
  if (!(p.cell > 0) || !(p.slope >= 0) || !(p.max_window >= p.cell) || !(p.elevation_threshold >= 0) ||
      !(p.elevation_scalar >= 0) || p.inpaint_sweeps < 0 || !std::isfinite(p.cell + p.slope + p.max_window))
    throw Error(Status::BadInput, kCityStage,
                "ground filter: SMRF parameters need cell > 0, slope >= 0, max_window >= cell, thresholds >= 0");
  GroundFilterResult out;
  HeightGrid surface = minimum_surface(points, p.cell);
  const std::vector<char> empty = [&] {
    std::vector<char> e(surface.z.size());
    for (std::size_t k = 0; k < e.size(); ++k) e[k] = std::isnan(surface.z[k]);
    return e;
  }();
  HeightGrid filled = surface;
  inpaint(filled, p.inpaint_sweeps);
  const std::vector<char> object = object_cells(filled, p);
  out.model = surface;  // step 3: objects and empty cells removed, then filled from the ground around them
  for (std::size_t k = 0; k < object.size(); ++k) {
    if (object[k] && !empty[k]) ++out.object_cells;
    if (object[k]) out.model.z[k] = kNaN;
  }
  inpaint(out.model, p.inpaint_sweeps);
  if (std::isnan(out.model.z.front())) out.model = filled;  // every cell an object: keep the minimum surface
  out.ground.assign(points.size(), 0);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3& q = points[i];
    const double tolerance = p.elevation_threshold + p.elevation_scalar * out.model.slope(q.x(), q.y());
    out.ground[i] = std::abs(q.z() - out.model.sample(q.x(), q.y())) <= tolerance;
  }
  return out;
}

}  // namespace hsr
