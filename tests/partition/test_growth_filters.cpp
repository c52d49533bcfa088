// Exactness of the growth engine's double filters (issue 17): a filtered predicate must give the exact sign
// or defer to the exact evaluation. The case below is decided wrongly by an unguarded double filter (the one
// of kinetic_growth.cpp before be27529: value = da*u + db*v + dc against 1e-12 * magnitude, no check that the
// doubles are normal): with subnormal coordinates the rounding of each product and the truncation of
// mpq_get_d are whole ulps of 2^-1074, while the relative bound underflows to 0.
#include "partition/growth_arrangement.h"
#include "partition/growth_time.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace hsr::partition_internal {
namespace {

// 2^-1074, the smallest positive subnormal double, as an exact rational.
Rational subnormal_ulp() {
  mpz_class den;
  mpz_ui_pow_ui(den.get_mpz_t(), 2, 1074);
  return Rational(mpz_class(1), den);
}

// The line a u + b v + c = 0 (b != 0) through line_through: p on the line, q = p + (b, -a).
Line line_of(const Rational& a, const Rational& b, const Rational& c) {
  const P2 p{Rational(0), -c / b};
  const P2 q{b, p.v - a};
  return line_through(p, q);
}

// The line's integer coefficients are proportional to (a, b, c), with the same sides.
void expect_line(const Line& l, const Rational& a, const Rational& b, const Rational& c) {
  ASSERT_NE(sgn(a), 0);
  EXPECT_EQ(sgn(l.a), sgn(a));
  EXPECT_EQ(Rational(l.b) / Rational(l.a), b / a);
  EXPECT_EQ(Rational(l.c) / Rational(l.a), c / a);
}

TEST(GrowthFilters, SubnormalLineSignIsExact) {
  const Rational ulp = subnormal_ulp();
  const Rational a(1, 2), b(1, 2), c = Rational(-31, 10) * ulp;
  const Line l = line_of(a, b, c);
  expect_line(l, a, b, c);
  // At (3 ulp, 3 ulp) the exact value is 1.5 + 1.5 - 3.1 = -0.1 ulp. In doubles 0.5 * 3 ulp rounds to even
  // (2 ulp) twice and -3.1 ulp truncates to -3 ulp: +1 ulp, above a relative bound that underflowed to 0.
  const P2 x{3 * ulp, 3 * ulp};
  EXPECT_EQ(sgn(a * x.u + b * x.v + c), -1);
  const double tu = a.get_d() * x.u.get_d(), tv = b.get_d() * x.v.get_d(), dc = c.get_d();
  EXPECT_GT(tu + tv + dc, 1e-12 * (std::abs(tu) + std::abs(tv) + std::abs(dc)));  // the unguarded filter's "+1"
  EXPECT_EQ(line_sign(l, x), -1);
  EXPECT_EQ(line_sign(l, make_v2(x)), -1);
}

// The same with a line normalised as the rational arrangement stored them before issue 25 (a = 1):
// u + v/2 - 4.6 ulp at (3 ulp, 3 ulp) is -0.1 ulp; doubles give 3 + 2 - 4 = +1 ulp.
TEST(GrowthFilters, SubnormalNormalisedLineSignIsExact) {
  const Rational ulp = subnormal_ulp();
  const Rational a(1), b(1, 2), c = Rational(-46, 10) * ulp;
  const Line l = line_of(a, b, c);
  expect_line(l, a, b, c);
  const P2 x{3 * ulp, 3 * ulp};
  ASSERT_EQ(sgn(a * x.u + b * x.v + c), -1);
  const double tu = a.get_d() * x.u.get_d(), tv = b.get_d() * x.v.get_d();
  EXPECT_GT(tu + tv + c.get_d(), 0.0);
  EXPECT_EQ(line_sign(l, x), -1);
}

// Random points a few ulps around lines with subnormal offsets, and around the same lines scaled into the
// normal range: line_sign always agrees with the exact sign.
TEST(GrowthFilters, LineSignMatchesExactNearSubnormalAndNormalLines) {
  const Rational ulp = subnormal_ulp();
  std::mt19937 rng(17);
  std::uniform_int_distribution<int> small(-40, 40);
  int negative = 0, positive = 0, zero = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    const Rational scale = trial % 2 == 0 ? ulp : Rational(1, 1 << 20);
    const Line l = line_of(Rational(1, 2), Rational(1, 2), Rational(small(rng), 7) * scale);
    const P2 x{Rational(small(rng), 3) * scale, Rational(small(rng), 5) * scale};
    const int exact = sgn(l.a * x.u + l.b * x.v + l.c);
    ASSERT_EQ(line_sign(l, x), exact) << "trial " << trial;
    (exact < 0 ? negative : exact > 0 ? positive : zero)++;
  }
  EXPECT_GT(negative, 100);
  EXPECT_GT(positive, 100);
}

// ArrivalTime::min_on_segment on a segment almost parallel to one of the rays from the centre through a
// vertex of K. The double filter before be27529 marked such a ray "nearly parallel, decide exactly" with the
// value -1e300 and then kept only the candidates within 1e-8 * (1 + |lowest|) of the lowest value: every other
// candidate, the true minimum included, was dropped. K = the square (+-1, +-1), so g = max(|u|, |v|); the
// segment a = (2, 2 - d) -> b = (3, 3 + d), d = 2^-30, crosses the ray through (1, 1) at its middle (2.5, 2.5),
// where g = 5/2, with w x e = 2d below the old 1e-9 * |w| |e| threshold. The minimum is g(a) = 2. The old
// filter returned 5/2 (checked against a copy of it outside the tests), which also put this edge after an
// edge at gauge 9/4: a wrong event time and a wrong event order.
TEST(GrowthFilters, GaugeMinimumOnASegmentAlongARayIsExact) {
  const std::vector<P2> k{{Rational(-1), Rational(-1)}, {Rational(1), Rational(-1)},
                          {Rational(1), Rational(1)}, {Rational(-1), Rational(1)}};
  const ArrivalTime time(k, Rational(1));
  mpz_class den;
  mpz_ui_pow_ui(den.get_mpz_t(), 2, 30);
  const Rational d(mpz_class(1), den);
  const P2 a{Rational(2), Rational(2) - d}, b{Rational(3), Rational(3) + d};
  ASSERT_EQ(time.gauge(a), 2);
  ASSERT_EQ(time.gauge(P2{Rational(5, 2), Rational(5, 2)}), Rational(5, 2));
  const ArrivalTime::SegmentMin m = time.min_on_segment(a, b);
  EXPECT_EQ(m.gauge, 2);
  EXPECT_TRUE(m.point == a);
  EXPECT_EQ(time.min_on_segment(b, a).gauge, 2);
  // Order against an edge whose minimum is 9/4 (the vertical segment u = 9/4, |v| <= 1).
  const ArrivalTime::SegmentMin other = time.min_on_segment({Rational(9, 4), Rational(-1)}, {Rational(9, 4), Rational(1)});
  EXPECT_EQ(other.gauge, Rational(9, 4));
  EXPECT_LT(time.time_of_gauge(m.gauge), time.time_of_gauge(other.gauge));
}

}  // namespace
}  // namespace hsr::partition_internal
