#include "partition/growth_time.h"

#include "core/error.h"

#include <algorithm>

namespace hsr::partition_internal {

ArrivalTime::ArrivalTime(const std::vector<P2>& shape, Rational time_scale) : time_scale_(std::move(time_scale)) {
  Rational su = 0, sv = 0;
  for (const P2& p : shape) { su += p.u; sv += p.v; }
  const Rational n(static_cast<long>(shape.size()));
  centre_ = {su / n, sv / n};
  for (std::size_t i = 0; i < shape.size(); ++i) {
    const P2& a = shape[i];
    const P2& b = shape[(i + 1) % shape.size()];
    rays_.push_back({a.u - centre_.u, a.v - centre_.v});
    // Outward normal of a CCW edge: (dv, -du); scaled so the edge's line has value 1.
    const Rational nu = b.v - a.v, nv = -(b.u - a.u);
    const Rational h = nu * (a.u - centre_.u) + nv * (a.v - centre_.v);
    HSR_ASSERT(sgn(h) > 0, "gauge: the centre must be inside the polygon");
    const Rational A = nu / h, B = nv / h;
    edges_.push_back({A, B, -(A * centre_.u + B * centre_.v)});
  }
  for (const auto& e : edges_) iedges_.push_back({Interval::of(e[0]), Interval::of(e[1]), Interval::of(e[2])});
  for (const P2& w : rays_) irays_.push_back({Interval::of(w.u), Interval::of(w.v)});
  icu_ = Interval::of(centre_.u);
  icv_ = Interval::of(centre_.v);
  for (const auto& e : edges_) {
    mpz_class d = 1;
    for (const Rational& q : e) mpz_lcm(d.get_mpz_t(), d.get_mpz_t(), q.get_den_mpz_t());
    std::array<mpz_class, 4> z;
    for (int k = 0; k < 3; ++k) {
      mpz_divexact(z[k].get_mpz_t(), d.get_mpz_t(), e[k].get_den_mpz_t());
      z[k] *= e[k].get_num();
    }
    z[3] = d;
    zedges_.push_back(std::move(z));
  }
  homogeneous(centre_, hcentre_);
  for (const P2& w : rays_) {
    mpz_class h[3];
    homogeneous(w, h);
    hrays_.push_back({h[0], h[1], h[2]});
  }
}

namespace {
// x < y for fractions with positive denominators.
int compare(const mpz_class& xn, const mpz_class& xd, const mpz_class& yn, const mpz_class& yd) {
  return cmp(xn * yd, yn * xd);
}
}  // namespace

ArrivalTime::Fraction ArrivalTime::gauge_fraction(const mpz_class (&x)[3], const Interval& u, const Interval& v) const {
  std::vector<Interval> term(iedges_.size());
  double floor = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < iedges_.size(); ++i) {
    term[i] = iedges_[i][0] * u + iedges_[i][1] * v + iedges_[i][2];
    floor = std::max(floor, term[i].lo);
  }
  bool have = false;
  Fraction best;
  mpz_class n, d;
  for (std::size_t i = 0; i < zedges_.size(); ++i) {
    if (term[i].hi < floor) continue;  // certainly below another term
    const auto& z = zedges_[i];
    n = z[0] * x[0] + z[1] * x[1] + z[2] * x[2];
    d = z[3] * x[2];
    if (!have || compare(n, d, best.n, best.d) > 0) {
      best.n = n;
      best.d = d;
    }
    have = true;
  }
  return best;
}

Interval ArrivalTime::gauge_interval(const Interval& u, const Interval& v) const {
  Interval best{-std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  for (const auto& e : iedges_) best = max(best, e[0] * u + e[1] * v + e[2]);
  return best;
}

Rational ArrivalTime::gauge(const P2& x) const {
  mpz_class h[3];
  homogeneous(x, h);
  Fraction f = gauge_fraction(h, Interval::of(x.u), Interval::of(x.v));
  Rational out;
  out.get_num() = std::move(f.n);
  out.get_den() = std::move(f.d);
  out.canonicalize();
  return out;
}

Rational ArrivalTime::time_of_gauge(const Rational& g) const {
  if (g <= 1) return 0;
  return time_scale_ * (g - 1);
}

ArrivalTime::Candidate ArrivalTime::segment_minimum(const P2& a, const P2& b) const {
  // Candidates: 0 = a, 1 = b, 2 + j = the crossing with ray j. Intervals (containing the exact values) give
  // each candidate's gauge; a candidate whose lower bound is above a certain candidate's upper bound cannot
  // be the minimum. The others are evaluated exactly, as fractions of integers (homogeneous coordinates).
  const Interval au = Interval::of(a.u), av = Interval::of(a.v), bu = Interval::of(b.u), bv = Interval::of(b.v);
  const Interval eu = bu - au, ev = bv - av, ru = au - icu_, rv = av - icv_;
  const std::size_t n = rays_.size();
  std::vector<Interval> value(2 + n);
  std::vector<char> certain(2 + n, 1), possible(2 + n, 1);
  value[0] = gauge_interval(au, av);
  value[1] = gauge_interval(bu, bv);
  for (std::size_t j = 0; j < n; ++j) {
    const Interval den = irays_[j][0] * ev - irays_[j][1] * eu;  // w x e
    const Interval s = (ru * ev - rv * eu) / den;                 // ray parameter at the crossing (= gauge)
    const Interval lambda = (ru * irays_[j][1] - rv * irays_[j][0]) / den;  // segment parameter
    value[2 + j] = s;
    if (s.hi < 0 || lambda.hi < 0 || lambda.lo > 1) possible[2 + j] = 0;
    certain[2 + j] = den.sign() != 0 && s.lo >= 0 && lambda.lo >= 0 && lambda.hi <= 1;
  }
  double upper = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < 2 + n; ++k)
    if (possible[k] && certain[k]) upper = std::min(upper, value[k].hi);

  mpz_class A[3], B[3];
  homogeneous(a, A);
  homogeneous(b, B);
  bool have = false;
  Candidate best;
  auto offer = [&](Fraction g, Fraction lambda) {
    if (have) {
      const int c = compare(g.n, g.d, best.gauge.n, best.gauge.d);
      if (c > 0 || (c == 0 && compare(lambda.n, lambda.d, best.lambda.n, best.lambda.d) >= 0)) return;
    }
    best.gauge = std::move(g);
    best.lambda = std::move(lambda);
    have = true;
  };
  if (value[0].lo <= upper) offer(gauge_fraction(A, au, av), {mpz_class(0), mpz_class(1)});
  if (value[1].lo <= upper) offer(gauge_fraction(B, bu, bv), {mpz_class(1), mpz_class(1)});
  // e = b - a = (E0, E1) / E2 and r = a - c = (R0, R1) / R2; ray w = (W0, W1) / W2. Then
  //   s = (r x e) / (w x e) = (R0 E1 - R1 E0) W2 / ((W0 E1 - W1 E0) R2),
  //   lambda = (r x w) / (w x e) = (R0 W1 - R1 W0) E2 / ((W0 E1 - W1 E0) R2).
  bool have_differences = false;
  mpz_class E[3], R[3], rxe;
  for (std::size_t j = 0; j < n; ++j) {
    if (!possible[2 + j] || value[2 + j].lo > upper) continue;
    if (!have_differences) {
      E[0] = B[0] * A[2] - A[0] * B[2];
      E[1] = B[1] * A[2] - A[1] * B[2];
      E[2] = A[2] * B[2];
      R[0] = A[0] * hcentre_[2] - hcentre_[0] * A[2];
      R[1] = A[1] * hcentre_[2] - hcentre_[1] * A[2];
      R[2] = A[2] * hcentre_[2];
      rxe = R[0] * E[1] - R[1] * E[0];
      have_differences = true;
    }
    const auto& w = hrays_[j];
    mpz_class den = (w[0] * E[1] - w[1] * E[0]) * R[2];
    if (sgn(den) == 0) continue;
    Fraction sj{rxe * w[2], den}, lambda{(R[0] * w[1] - R[1] * w[0]) * E[2], den};
    if (sgn(den) < 0) {
      mpz_neg(sj.n.get_mpz_t(), sj.n.get_mpz_t());
      mpz_neg(sj.d.get_mpz_t(), sj.d.get_mpz_t());
      mpz_neg(lambda.n.get_mpz_t(), lambda.n.get_mpz_t());
      mpz_neg(lambda.d.get_mpz_t(), lambda.d.get_mpz_t());
    }
    if (sgn(sj.n) < 0 || sgn(lambda.n) < 0 || lambda.n > lambda.d) continue;
    offer(std::move(sj), std::move(lambda));
  }
  HSR_ASSERT(have, "gauge: no candidate minimum on a segment");
  return best;
}

namespace {
Rational canonical(mpz_class n, mpz_class d) {
  Rational q;
  q.get_num() = std::move(n);
  q.get_den() = std::move(d);
  q.canonicalize();
  return q;
}
}  // namespace

ArrivalTime::SegmentMin ArrivalTime::min_on_segment(const P2& a, const P2& b) const {
  Candidate c = segment_minimum(a, b);
  SegmentMin best;
  best.gauge = canonical(std::move(c.gauge.n), std::move(c.gauge.d));
  const Rational lambda = canonical(std::move(c.lambda.n), std::move(c.lambda.d));
  if (sgn(lambda) == 0) best.point = a;
  else if (lambda == 1) best.point = b;
  else best.point = {a.u + lambda * (b.u - a.u), a.v + lambda * (b.v - a.v)};
  return best;
}

Rational ArrivalTime::min_gauge_on_segment(const P2& a, const P2& b) const {
  Candidate c = segment_minimum(a, b);
  return canonical(std::move(c.gauge.n), std::move(c.gauge.d));
}

Time ArrivalTime::arrival_on_segment(const P2& a, const P2& b, bool& inside) const {
  const Candidate c = segment_minimum(a, b);
  const int vs_one = cmp(c.gauge.n, c.gauge.d);  // g - 1, as the denominator is positive
  inside = vs_one < 0;
  if (vs_one <= 0) return Time::fraction(0, 1);
  // time_scale (g - 1) = tn (gn - gd) / (td gd)
  return Time::fraction(time_scale_.get_num() * (c.gauge.n - c.gauge.d), time_scale_.get_den() * c.gauge.d);
}

Time Time::of(const Rational& t) { return fraction(t.get_num(), t.get_den()); }

Time Time::fraction(mpz_class n, mpz_class d) {
  Time t;
  t.n = std::move(n);
  t.d = std::move(d);
  t.approx = sgn(t.n) == 0 ? Interval::make(0, 0) : Interval::of(t.n) / Interval::of(t.d);
  return t;
}

int compare(const Time& a, const Time& b) {
  if (sgn(a.n) == 0 && sgn(b.n) == 0) return 0;
  if (a.approx.hi < b.approx.lo) return -1;
  if (a.approx.lo > b.approx.hi) return 1;
  return cmp(a.n * b.d, b.n * a.d);
}

bool ArrivalTime::min_on_line(const Line& line, Rational& out) const {
  // The line meets the ray centre + t * ray_i at t = -L(centre) / (a . ray_i), where g = t. With the centre
  // (C0, C1, C2) and ray (W0, W1, W2) homogeneous: t = -(a C0 + b C1 + c C2) W2 / ((a W0 + b W1) C2).
  const mpz_class at_centre = line.a * hcentre_[0] + line.b * hcentre_[1] + line.c * hcentre_[2];
  if (sgn(at_centre) == 0) return false;
  bool have = false;
  mpz_class best_n, best_d;
  for (const auto& w : hrays_) {
    const mpz_class slope = line.a * w[0] + line.b * w[1];
    if (sgn(slope) == 0 || sgn(slope) == sgn(at_centre)) continue;  // parallel, or moving away
    mpz_class n = -at_centre * w[2], d = slope * hcentre_[2];
    if (sgn(d) < 0) {
      mpz_neg(n.get_mpz_t(), n.get_mpz_t());
      mpz_neg(d.get_mpz_t(), d.get_mpz_t());
    }
    if (!have || compare(n, d, best_n, best_d) < 0) {
      best_n = std::move(n);
      best_d = std::move(d);
    }
    have = true;
  }
  HSR_ASSERT(have, "gauge: a line misses every ray of a bounded polygon");
  out = canonical(std::move(best_n), std::move(best_d));
  return true;
}

}  // namespace hsr::partition_internal
