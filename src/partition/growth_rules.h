// Internal to src/partition: the stopping rules of kinetic growth (kinetic_growth.h), one small function per
// partitioner, and the bounds rule of the hierarchical partition (also used by bsp's extension, partition.h).
#pragma once

#include "partition/growth_arrangement.h"
#include "partition/growth_time.h"

#include <vector>

namespace hsr::partition_internal {

/// A line of an adjacent polygon that bounds a polygon's expected extent, and the side (+1/-1) of the line
/// the polygon's centre is on.
struct Bound {
  int line = -1;
  int side = 0;
};

/// The bounds rule (docs/DECISIONS.md #11). A polygon's bounds are the lines of its adjacent polygons
/// (`adjacent_line[l]` true) that stay out of the inner half of its initial shape: the gauge is >= 1/2 all
/// along the line (a line through the middle is a T-junction, not an end of the polygon). Their halfplanes
/// on the centre's side intersect in the region where the polygon's true edges are expected.
std::vector<Bound> find_bounds(const ArrivalTime& time, const std::vector<Line>& lines,
                               const std::vector<char>& adjacent_line);
/// True when every vertex of the face is on the centre's side (or on) every bound; false without bounds.
bool inside_bounds(const std::vector<Bound>& bounds, const std::vector<Line>& lines, const Face& face);
/// The convex polygon `section` (the domain's section) clipped to the bounds' halfplanes.
std::vector<P2> clip_to_bounds(std::vector<P2> section, const std::vector<Bound>& bounds,
                               const std::vector<Line>& lines);

/// What a growing polygon remembers between collisions.
struct StopState {
  int budget = 1;             ///< kinetic: collisions it may still survive, plus one (k at the start)
  std::vector<int> paid;      ///< sorted: polygons whose plane it has crossed (re-crossing is free)
  std::vector<Bound> bounds;  ///< hierarchical
};

/// One collision of a growing polygon P with the polygons `present` on an arrangement edge (their regions
/// cover it on both sides), `unpaid` of them not yet crossed by P (non-empty).
struct Collision {
  const std::vector<int>& present;
  const std::vector<int>& unpaid;
  bool on_the_way = false;  ///< hierarchical: the face left is inside P's bounds and the line is not a bound
};

/// kinetic (KSR): P stops when the c = |unpaid| planes exhaust its budget (c >= budget), else the budget
/// drops by c.
bool kinetic_stops(StopState& st, const Collision& c);

/// hierarchical (paper §3.5): a present polygon adjacent to P stops it (events C); non-adjacent ones
/// (events B) are crossed while P is on its way to its bounds, and stop it beyond them; and P stops when it
/// would have crossed more than `max_crossings` distinct planes. `adjacent`: sorted indices adjacent to P.
bool hierarchical_stops(const StopState& st, const Collision& c, const std::vector<int>& adjacent,
                        int max_crossings);

/// Records that P crossed the unpaid planes.
void pay(StopState& st, const std::vector<int>& unpaid);

}  // namespace hsr::partition_internal
