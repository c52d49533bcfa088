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

/// An exact time n / d (d > 0, not reduced) with an interval around it. Event times are compared through the
/// intervals, and exactly (cross-multiplied, no gcd) only when those overlap (ties, filters off).
struct Time {
  mpz_class n = 0, d = 1;
  Interval approx = Interval::whole();
  static Time of(const Rational& t);
  static Time fraction(mpz_class n, mpz_class d);  ///< d > 0
};
/// -1, 0, +1 as a < b, a = b, a > b.
int compare(const Time& a, const Time& b);

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
  /// Only the minimum gauge of min_on_segment (no point: cheaper).
  Rational min_gauge_on_segment(const P2& a, const P2& b) const;
  /// time_of_gauge of that minimum, and whether the minimum is below 1 (the segment meets the interior of the
  /// initial polygon), without reducing any fraction.
  Time arrival_on_segment(const P2& a, const P2& b, bool& inside) const;

  /// The minimum of g over a whole line not through c (at one of its crossings with the rays from c
  /// through the vertices of K); false when the line passes through c (then it is 0).
  bool min_on_line(const Line& line, Rational& out) const;

 private:
  /// A fraction n / d with d > 0, not reduced: exact candidates are compared without any gcd and only the
  /// minimum is canonicalised.
  struct Fraction {
    mpz_class n, d;
  };
  struct Candidate {
    Fraction gauge, lambda;  ///< lambda: where on the segment (0 at a, 1 at b)
  };
  Interval gauge_interval(const Interval& u, const Interval& v) const;
  /// g at the point with homogeneous coordinates x, over the terms whose interval may reach the maximum.
  Fraction gauge_fraction(const mpz_class (&x)[3], const Interval& u, const Interval& v) const;
  /// The minimum of g on [a, b] (first point from a), exact.
  Candidate segment_minimum(const P2& a, const P2& b) const;

  P2 centre_;
  Rational time_scale_;
  std::vector<P2> rays_;                         // vertex - centre
  std::vector<std::array<Rational, 3>> edges_;   // (A_i, B_i, C_i)
  std::vector<std::array<Interval, 3>> iedges_;  // their intervals
  std::vector<std::array<Interval, 2>> irays_;
  Interval icu_, icv_;
  // Integer forms: edge i's term is (a u + b v + c) / d with d > 0; the centre and the rays in homogeneous
  // coordinates (W > 0).
  std::vector<std::array<mpz_class, 4>> zedges_;
  mpz_class hcentre_[3];
  std::vector<std::array<mpz_class, 3>> hrays_;
};

}  // namespace hsr::partition_internal
