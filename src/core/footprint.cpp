// A footprint's plain checks (core/footprint.h). The errors keep the stage "partition", where the footprint's
// prism is built and where these checks were first made.
#include "core/footprint.h"

#include "core/error.h"

namespace hsr {

namespace {

constexpr const char* kStage = "partition";

void check_ring(const std::vector<Vec2>& ring) {
  if (ring.size() < 3) throw Error(Status::BadInput, kStage, "footprint: a ring has fewer than 3 vertices");
  for (const Vec2& p : ring)
    if (!p.allFinite()) throw Error(Status::BadInput, kStage, "footprint: a vertex is not finite");
  if (twice_ring_area(ring) == 0.0) throw Error(Status::BadInput, kStage, "footprint: a ring has no area");
}

}  // namespace

double twice_ring_area(const std::vector<Vec2>& ring) {
  double a = 0;
  for (std::size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++)
    a += ring[j].x() * ring[i].y() - ring[i].x() * ring[j].y();
  return a;
}

void check_footprint(const Footprint& footprint) {
  for (const FootprintPolygon& p : footprint) {
    check_ring(p.outer);
    for (const auto& h : p.holes) check_ring(h);
  }
}

}  // namespace hsr
