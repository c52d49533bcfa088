// Tiles of one survey (survey.h).
#include "city/survey.h"

#include <algorithm>
#include <cmath>
#include <limits>

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

}  // namespace hsr
