// Tiles of one survey (survey.h).
#include "city/survey.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace hsr {

namespace {

/// Plan distance from p to the rectangle (0 inside).
double plan_distance(const Vec2& p, const BBox& b) {
  const double dx = std::max({b.min.x() - p.x(), 0.0, p.x() - b.max.x()});
  const double dy = std::max({b.min.y() - p.y(), 0.0, p.y() - b.max.y()});
  return std::hypot(dx, dy);
}

bool plan_meets(const BBox& a, const BBox& b) {
  return a.min.x() <= b.max.x() && b.min.x() <= a.max.x() && a.min.y() <= b.max.y() && b.min.y() <= a.max.y();
}

}  // namespace

TileBlocks TileBlocks::over(const BBox& box, double block) {
  TileBlocks b;
  if (!box.valid()) return b;
  b.x0 = box.min.x();
  b.y0 = box.min.y();
  const double w = box.max.x() - box.min.x(), h = box.max.y() - box.min.y();
  if (block > 0 && std::isfinite(block)) {
    b.nx = static_cast<int>(std::clamp(std::round(w / block), 1.0, 1e4));
    b.ny = static_cast<int>(std::clamp(std::round(h / block), 1.0, 1e4));
  }
  b.width = w / b.nx;
  b.height = h / b.ny;
  return b;
}

int TileBlocks::of(const Vec2& p) const {
  const int i = width > 0 ? static_cast<int>(std::clamp(std::floor((p.x() - x0) / width), 0.0, nx - 1.0)) : 0;
  const int j = height > 0 ? static_cast<int>(std::clamp(std::floor((p.y() - y0) / height), 0.0, ny - 1.0)) : 0;
  return i + nx * j;
}

int owning_tile(const Vec2& p, const std::vector<BBox>& extents, double edge_tolerance) {
  int best = -1;
  double best_distance = std::numeric_limits<double>::infinity();
  for (std::size_t t = 0; t < extents.size(); ++t) {
    const double d = plan_distance(p, extents[t]);
    if (d <= edge_tolerance && d < best_distance) {
      best = static_cast<int>(t);
      best_distance = d;
    }
  }
  return best;
}

std::vector<int> tiles_meeting(const BBox& box, const std::vector<BBox>& extents, int self) {
  std::vector<int> out;
  for (std::size_t t = 0; t < extents.size(); ++t)
    if (static_cast<int>(t) != self && plan_meets(box, extents[t])) out.push_back(static_cast<int>(t));
  return out;
}

bool survey_beyond(const BBox& loaded, int side, double strip, const std::vector<BBox>& extents) {
  BBox s = loaded;
  switch (side) {
    case 0: s.max.x() = loaded.min.x(); s.min.x() = loaded.min.x() - strip; break;
    case 1: s.min.x() = loaded.max.x(); s.max.x() = loaded.max.x() + strip; break;
    case 2: s.max.y() = loaded.min.y(); s.min.y() = loaded.min.y() - strip; break;
    default: s.min.y() = loaded.max.y(); s.max.y() = loaded.max.y() + strip; break;
  }
  // Strictly beyond: a tile that only touches the side from inside does not count.
  for (const BBox& e : extents) {
    const bool meets = e.min.x() < s.max.x() && s.min.x() < e.max.x() && e.min.y() < s.max.y() && s.min.y() < e.max.y();
    if (meets) return true;
  }
  return false;
}

FootprintGrid::FootprintGrid(FootprintSet set) : set_(std::move(set)) {
  BBox all;
  for (const FootprintFeature& f : set_.features) {
    BBox b;
    for (const FootprintPolygon& poly : f.footprint)
      for (const Vec2& q : poly.outer) b.extend(Vec3(q.x(), q.y(), 0));
    boxes_.push_back(b);
    if (b.valid()) {
      all.extend(b.min);
      all.extend(b.max);
    }
  }
  if (!all.valid()) return;
  auto cell = [](double v) { return static_cast<std::int64_t>(std::floor(v / kCell)); };
  i0_ = cell(all.min.x());
  j0_ = cell(all.min.y());
  nx_ = cell(all.max.x()) - i0_ + 1;
  ny_ = cell(all.max.y()) - j0_ + 1;
  cells_.resize(static_cast<std::size_t>(nx_ * ny_));
  for (std::size_t f = 0; f < boxes_.size(); ++f) {
    const BBox& b = boxes_[f];
    if (!b.valid()) continue;
    for (std::int64_t j = cell(b.min.y()) - j0_; j <= cell(b.max.y()) - j0_; ++j)
      for (std::int64_t i = cell(b.min.x()) - i0_; i <= cell(b.max.x()) - i0_; ++i)
        cells_[static_cast<std::size_t>(i + nx_ * j)].push_back(static_cast<std::uint32_t>(f));
  }
}

std::vector<std::size_t> FootprintGrid::meeting(const BBox& rect) const {
  std::vector<std::size_t> out;
  if (!rect.valid() || cells_.empty()) return out;
  auto cell = [](double v) { return static_cast<std::int64_t>(std::floor(v / kCell)); };
  const std::int64_t a = std::max<std::int64_t>(0, cell(rect.min.x()) - i0_), b = std::min<std::int64_t>(nx_ - 1, cell(rect.max.x()) - i0_);
  const std::int64_t c = std::max<std::int64_t>(0, cell(rect.min.y()) - j0_), d = std::min<std::int64_t>(ny_ - 1, cell(rect.max.y()) - j0_);
  for (std::int64_t j = c; j <= d; ++j)
    for (std::int64_t i = a; i <= b; ++i)
      for (std::uint32_t f : cells_[static_cast<std::size_t>(i + nx_ * j)]) {
        const BBox& box = boxes_[f];
        if (box.min.x() <= rect.max.x() && rect.min.x() <= box.max.x() && box.min.y() <= rect.max.y() && rect.min.y() <= box.max.y())
          out.push_back(f);
      }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

}  // namespace hsr
