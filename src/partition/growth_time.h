// Internal to src/partition: the time function of kinetic growth (kinetic_growth.h). A convex polygon P
// grows homothetically about the vertex average c of its initial shape K: it reaches point x of its plane at
//   T_P(x) = (R / s) * max(0, g(x) - 1),
// g the gauge of K about c (g = 1 on the boundary of K, g(c) = 0), R = sqrt(area / pi) and s the speed
// (R / s is the caller's time_scale). g(x) = max_i (A_i u + B_i v + C_i) over the edges i of K: convex and
// piecewise linear, exact for rational x. Everything here is exact; the doubles only filter, through
// intervals that always contain the exact values.
#pragma once

#include "partition/exact_geometry.h"
#include "partition/growth_arrangement.h"

#include <array>
#include <vector>

namespace hsr::partition_internal {

class ArrivalTime {
 public:
  /// `shape`: convex CCW, positive area. `time_scale` = R / s > 0.
  ArrivalTime(const std::vector<P2>& shape, Rational time_scale);

  const P2& centre() const { return centre_; }
  /// g(x), exact.
  Rational gauge(const P2& x) const;
  /// T for a gauge value: time_scale * max(0, g - 1).
  Rational time_of_gauge(const Rational& g) const;

  /// The minimum of g over the segment [a, b], and the first point of the segment (from a) where it is
  /// attained. g is convex and piecewise linear along the segment, so the minimum is at an endpoint or where
  /// the segment crosses a ray from c through a vertex of K (where g is the ray parameter).
  struct SegmentMin {
    Rational gauge;
    P2 point;
  };
  SegmentMin min_on_segment(const P2& a, const P2& b) const;

  /// The minimum of g over a whole line not through c (at one of its crossings with the rays from c
  /// through the vertices of K); false when the line passes through c (then it is 0).
  bool min_on_line(const Line& line, Rational& out) const;

 private:
  Interval gauge_interval(const Interval& u, const Interval& v) const;

  P2 centre_;
  Rational time_scale_;
  std::vector<P2> rays_;                         // vertex - centre
  std::vector<std::array<Rational, 3>> edges_;   // (A_i, B_i, C_i)
  std::vector<std::array<Interval, 3>> iedges_;  // their intervals
  std::vector<std::array<Interval, 2>> irays_;
  Interval icu_, icv_;
};

}  // namespace hsr::partition_internal
