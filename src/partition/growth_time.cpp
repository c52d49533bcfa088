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
}

Interval ArrivalTime::gauge_interval(const Interval& u, const Interval& v) const {
  Interval best{-std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  for (const auto& e : iedges_) best = max(best, e[0] * u + e[1] * v + e[2]);
  return best;
}

Rational ArrivalTime::gauge(const P2& x) const {
  // Exact value only for the terms whose interval can reach the maximum.
  const Interval u = Interval::of(x.u), v = Interval::of(x.v);
  std::vector<Interval> term(iedges_.size());
  double floor = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < iedges_.size(); ++i) {
    term[i] = iedges_[i][0] * u + iedges_[i][1] * v + iedges_[i][2];
    floor = std::max(floor, term[i].lo);
  }
  bool have = false;
  Rational result;
  for (std::size_t i = 0; i < edges_.size(); ++i) {
    if (term[i].hi < floor) continue;  // certainly below another term
    Rational g = edges_[i][0] * x.u + edges_[i][1] * x.v + edges_[i][2];
    if (!have || g > result) result = std::move(g);
    have = true;
  }
  return result;
}

Rational ArrivalTime::time_of_gauge(const Rational& g) const {
  if (g <= 1) return 0;
  return time_scale_ * (g - 1);
}

ArrivalTime::SegmentMin ArrivalTime::min_on_segment(const P2& a, const P2& b) const {
  // Candidates: 0 = a, 1 = b, 2 + j = the crossing with ray j. Intervals (containing the exact values) give
  // each candidate's gauge; a candidate whose lower bound is above a certain candidate's upper bound cannot
  // be the minimum. The others are evaluated exactly.
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

  bool have = false;
  SegmentMin best;
  Rational best_lambda;
  auto offer = [&](Rational g, Rational lambda) {
    if (have && (g > best.gauge || (g == best.gauge && lambda >= best_lambda))) return;
    best.gauge = std::move(g);
    best_lambda = std::move(lambda);
    have = true;
  };
  if (value[0].lo <= upper) offer(gauge(a), Rational(0));
  if (value[1].lo <= upper) offer(gauge(b), Rational(1));
  Rational reu, rev, rru, rrv;  // exact differences, once some ray candidate needs them
  bool have_differences = false;
  for (std::size_t j = 0; j < n; ++j) {
    if (!possible[2 + j] || value[2 + j].lo > upper) continue;
    if (!have_differences) {
      reu = b.u - a.u;
      rev = b.v - a.v;
      rru = a.u - centre_.u;
      rrv = a.v - centre_.v;
      have_differences = true;
    }
    const P2& w = rays_[j];
    const Rational den = w.u * rev - w.v * reu;  // w x e
    if (sgn(den) == 0) continue;
    Rational sj = (rru * rev - rrv * reu) / den;
    if (sgn(sj) < 0) continue;
    Rational lambda = (rru * w.v - rrv * w.u) / den;  // (r x w) / (w x e)
    if (sgn(lambda) < 0 || lambda > 1) continue;
    offer(std::move(sj), std::move(lambda));
  }
  HSR_ASSERT(have, "gauge: no candidate minimum on a segment");
  if (sgn(best_lambda) == 0) best.point = a;
  else if (best_lambda == 1) best.point = b;
  else best.point = {a.u + best_lambda * (b.u - a.u), a.v + best_lambda * (b.v - a.v)};
  return best;
}

bool ArrivalTime::min_on_line(const Line& line, Rational& out) const {
  // The line meets the ray centre + t * ray_i at t = -L(centre) / (a . ray_i), where g = t.
  const Rational at_centre = line.a * centre_.u + line.b * centre_.v + line.c;
  if (sgn(at_centre) == 0) return false;
  bool have = false;
  for (const P2& ray : rays_) {
    const Rational slope = line.a * ray.u + line.b * ray.v;
    if (sgn(slope) == 0 || sgn(slope) == sgn(at_centre)) continue;  // parallel, or moving away
    Rational t = -at_centre / slope;
    if (!have || t < out) out = std::move(t);
    have = true;
  }
  HSR_ASSERT(have, "gauge: a line misses every ray of a bounded polygon");
  return true;
}

}  // namespace hsr::partition_internal
