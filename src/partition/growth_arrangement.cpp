#include "partition/growth_arrangement.h"

#include "core/error.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace hsr::partition_internal {

namespace {

// Divides the coefficients by their common factor (gcd-free arithmetic keeps them small), and sets the double
// images.
void finish_line(Line& l) {
  mpz_class g;
  mpz_gcd(g.get_mpz_t(), l.a.get_mpz_t(), l.b.get_mpz_t());
  mpz_gcd(g.get_mpz_t(), g.get_mpz_t(), l.c.get_mpz_t());
  if (sgn(g) != 0 && g != 1)
    for (mpz_class* z : {&l.a, &l.b, &l.c}) mpz_divexact(z->get_mpz_t(), z->get_mpz_t(), g.get_mpz_t());
  l.da = l.a.get_d();
  l.db = l.b.get_d();
  l.dc = l.c.get_d();
  l.dnorm = std::hypot(l.da, l.db);
  l.trusted = trusted_double(l.a, l.da) && trusted_double(l.b, l.db) && trusted_double(l.c, l.dc);
}

const mpz_class& coefficient(const IntPlane& p, int axis) { return axis == 0 ? p.a : axis == 1 ? p.b : p.c; }

// Cramer's rule on the integer coefficients: one canonicalisation per coordinate instead of one per
// rational operation (this is the growth's hottest exact construction).
bool intersect_lines(const Line& l1, const Line& l2, P2& out) {
  const mpz_class det = l1.a * l2.b - l2.a * l1.b;
  if (sgn(det) == 0) return false;
  out.u = Rational(l1.b * l2.c - l2.b * l1.c, det);
  out.v = Rational(l1.c * l2.a - l2.c * l1.a, det);
  out.u.canonicalize();
  out.v.canonicalize();
  return true;
}

// Keeps the part of `face` where keep * line >= 0 (the result may be empty).
void clip_face(Face& face, const Line& line, int line_id, int keep) {
  const std::size_t n = face.vs.size();
  std::vector<int> s(n);
  bool any_out = false, any_in = false;
  for (std::size_t i = 0; i < n; ++i) {
    s[i] = keep * line_sign(line, face.vs[i]);
    any_out |= s[i] < 0;
    any_in |= s[i] > 0;
  }
  if (!any_out) return;
  if (!any_in) { face.vs.clear(); face.edge_line.clear(); return; }
  Face out;
  auto crossing = [&](std::size_t i, std::size_t j) {
    const P2& p = face.vs[i].p;
    const P2& q = face.vs[j].p;
    const Rational lp = line.a * p.u + line.b * p.v + line.c;
    const Rational lq = line.a * q.u + line.b * q.v + line.c;
    const Rational t = lp / (lp - lq);
    return make_v2({p.u + t * (q.u - p.u), p.v + t * (q.v - p.v)});
  };
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t j = (i + 1) % n;
    const int si = s[i], sj = s[j];
    if (si > 0) {
      out.vs.push_back(face.vs[i]);
      out.edge_line.push_back(face.edge_line[i]);
      if (sj < 0) {
        out.vs.push_back(crossing(i, j));
        out.edge_line.push_back(line_id);
      }
    } else if (si == 0) {
      out.vs.push_back(face.vs[i]);
      out.edge_line.push_back(sj < 0 ? line_id : face.edge_line[i]);
    } else if (sj > 0) {
      out.vs.push_back(crossing(i, j));
      out.edge_line.push_back(face.edge_line[i]);
    }
  }
  face = std::move(out);
  if (face.vs.size() < 3) { face.vs.clear(); face.edge_line.clear(); }
}

// Exact sign of twice the area of a face with positive area or a degenerate one (filtered_sign first).
int area_sign(const Face& face) {
  const std::size_t k = face.vs.size();
  bool trusted = true;
  double area2 = 0, mag = 0;
  for (std::size_t i = 0; i < k; ++i) {
    const V2& a = face.vs[i];
    const V2& b = face.vs[(i + 1) % k];
    trusted &= a.trusted;
    area2 += a.u * b.v - b.u * a.v;
    mag += std::abs(a.u * b.v) + std::abs(b.u * a.v);
  }
  // filtered_sign covers sums of 8 terms; a longer sum adds one rounding per term: 1e-12 stays far above
  // (2 k + 8) * 2^-53 for any face the growth builds (k < 10^3).
  if (trusted && k <= 500)
    if (int s = filtered_sign(area2, mag)) return s;
  std::vector<P2> pts;
  pts.reserve(k);
  for (const V2& q : face.vs) pts.push_back(q.p);
  return sgn(twice_area(pts));
}

}  // namespace

V2 make_v2(P2 p) {
  V2 out;
  out.u = p.u.get_d();
  out.v = p.v.get_d();
  out.trusted = trusted_double(p.u, out.u) && trusted_double(p.v, out.v);
  out.p = std::move(p);
  return out;
}

int line_sign(const Line& l, const V2& q) {
  if (l.trusted && q.trusted) {
    const double tu = l.da * q.u, tv = l.db * q.v;
    if (int s = filtered_sign(tu + tv + l.dc, std::abs(tu) + std::abs(tv) + std::abs(l.dc))) return s;
  }
  return sign_at(l.a, l.b, l.c, q.p.u, q.p.v);
}

int line_sign(const Line& l, const P2& p) { return line_sign(l, make_v2(p)); }

bool line_between(const IntPlane& plane, const PlaneFrame& frame, const IntPlane& other,
                  const std::vector<P2>& domain, Line& out) {
  std::vector<std::array<Interval, 2>> boxes;
  for (const P2& q : domain) boxes.push_back({Interval::of(q.u), Interval::of(q.v)});
  return line_between(plane, frame, other, boxes, out);
}

bool line_between(const IntPlane& plane, const PlaneFrame& frame, const IntPlane& other,
                  const std::vector<std::array<Interval, 2>>& domain, Line& out) {
  const int drop = frame.drop;
  int ku = (drop + 1) % 3, kv = (drop + 2) % 3;  // as exact_geometry's frames: (u, v) = (x_ku, x_kv) ...
  if (frame.swap) std::swap(ku, kv);            // ... or swapped
  // other restricted to plane, times plane's a_drop: integer coefficients.
  const mpz_class& pd = coefficient(plane, drop);
  const mpz_class& od = coefficient(other, drop);
  Line l;
  l.a = coefficient(other, ku) * pd - od * coefficient(plane, ku);
  l.b = coefficient(other, kv) * pd - od * coefficient(plane, kv);
  l.c = other.d * pd - od * plane.d;
  if (sgn(l.a) == 0 && sgn(l.b) == 0) return false;
  {  // Intervals first: drop a line that certainly misses the domain's interior.
    const Interval a = Interval::of(l.a), b = Interval::of(l.b), c = Interval::of(l.c);
    bool pos = false, neg = false;
    for (const auto& q : domain) {
      const int s = (a * q[0] + b * q[1] + c).sign();
      pos |= s >= 0;  // 0: undecided, counts on both sides
      neg |= s <= 0;
    }
    if (!pos || !neg) return false;
  }
  // Signed: the first non-zero of (a, b) positive, so opposite orientations of one line get one key.
  if (sgn(sgn(l.a) != 0 ? l.a : l.b) < 0)
    for (mpz_class* z : {&l.a, &l.b, &l.c}) mpz_neg(z->get_mpz_t(), z->get_mpz_t());
  finish_line(l);
  out = std::move(l);
  return true;
}

Line line_through(const P2& p, const P2& q) {
  // The cross product of the homogeneous points (W > 0): positive on the left.
  mpz_class P[3], Q[3];
  homogeneous(p, P);
  homogeneous(q, Q);
  Line l;
  l.a = P[1] * Q[2] - P[2] * Q[1];
  l.b = P[2] * Q[0] - P[0] * Q[2];
  l.c = P[0] * Q[1] - P[1] * Q[0];
  finish_line(l);
  return l;
}

ArrangementLocator::ArrangementLocator(const IntPlane& plane, const PlaneFrame& frame,
                                       const std::vector<P2>& domain, const std::vector<IntPlane>& planes,
                                       int self, PointRegistry& points)
    : plane_(plane), frame_(frame), points_(&points) {
  for (const P2& q : domain) {
    domain_.vs.push_back(make_v2(q));
    domain_.edge_line.push_back(-1);
  }
  std::map<std::array<mpz_class, 3>, int> by_coefficients;
  std::vector<std::array<Interval, 2>> domain_intervals;
  for (const V2& q : domain_.vs) domain_intervals.push_back({Interval::of(q.p.u), Interval::of(q.p.v)});
  for (int j = 0; j < static_cast<int>(planes.size()); ++j) {
    if (j == self) continue;
    Line line;
    if (!line_between(plane, frame, planes[j], domain_intervals, line)) continue;
    bool pos = false, neg = false;
    for (const V2& q : domain_.vs) {
      const int s = line_sign(line, q);
      pos |= s > 0;
      neg |= s < 0;
    }
    if (!pos || !neg) continue;
    std::array<mpz_class, 3> key{line.a, line.b, line.c};
    auto it = by_coefficients.find(key);
    if (it != by_coefficients.end()) {
      all_lines_[it->second].owners.push_back(j);
      continue;
    }
    line.owners.push_back(j);
    by_coefficients.emplace(key, static_cast<int>(all_lines_.size()));
    all_lines_.push_back(std::move(line));
  }
  num_lines_ = static_cast<int>(all_lines_.size());
  const std::size_t m = domain.size();
  HSR_ASSERT(all_lines_.size() + m < (std::size_t{1} << 21), "kinetic: too many lines for face keys");
  for (std::size_t e = 0; e < m; ++e) {
    domain_.edge_line[e] = static_cast<int>(all_lines_.size());
    all_lines_.push_back(line_through(domain[e], domain[(e + 1) % m]));
  }
}

// Fast path: clip in doubles to learn which lines bound the face, build its vertices exactly as intersections
// of consecutive bounding lines, and accept them only if exactly every vertex is on the kept side of every
// line and the area is positive (then the polygon is the face). Otherwise clip exactly.
Face ArrangementLocator::face_of(const V2& p, const std::vector<int>& keep) {
  if (!filters_on()) return face_of_exact(p, keep);
  std::vector<std::array<double, 2>> poly, next;
  std::vector<int> lab, next_lab;
  for (std::size_t i = 0; i < domain_.vs.size(); ++i) {
    poly.push_back({domain_.vs[i].u, domain_.vs[i].v});
    lab.push_back(domain_.edge_line[i]);
  }
  std::vector<double> val;
  for (int l = 0; l < num_lines_ && poly.size() >= 3; ++l) {
    const Line& line = all_lines_[l];
    const std::size_t n = poly.size();
    val.resize(n);
    bool any_out = false;
    for (std::size_t i = 0; i < n; ++i) {
      val[i] = keep[l] * (line.da * poly[i][0] + line.db * poly[i][1] + line.dc);
      any_out |= val[i] < 0;
    }
    if (!any_out) continue;
    next.clear();
    next_lab.clear();
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t j = (i + 1) % n;
      if (val[i] >= 0) {
        next.push_back(poly[i]);
        next_lab.push_back(val[j] < 0 && val[i] == 0 ? l : lab[i]);
        if (val[i] > 0 && val[j] < 0) {
          const double t = val[i] / (val[i] - val[j]);
          next.push_back({poly[i][0] + t * (poly[j][0] - poly[i][0]), poly[i][1] + t * (poly[j][1] - poly[i][1])});
          next_lab.push_back(l);
        }
      } else if (val[j] > 0) {
        const double t = val[i] / (val[i] - val[j]);
        next.push_back({poly[i][0] + t * (poly[j][0] - poly[i][0]), poly[i][1] + t * (poly[j][1] - poly[i][1])});
        next_lab.push_back(lab[i]);
      }
    }
    poly.swap(next);
    lab.swap(next_lab);
  }
  Face face;
  bool ok = lab.size() >= 3;
  const std::size_t k = lab.size();
  for (std::size_t i = 0; i < k && ok; ++i) {
    // A vertex is shared by up to four faces: intersections are cached per pair of lines.
    const int l1 = lab[(i + k - 1) % k], l2 = lab[i];
    const std::pair<int, int> pair_key{std::min(l1, l2), std::max(l1, l2)};
    auto it = crossings_.find(pair_key);
    if (it == crossings_.end()) {
      P2 q;
      ok = intersect_lines(all_lines_[l1], all_lines_[l2], q);
      if (!ok) break;
      it = crossings_.emplace(pair_key, make_v2(std::move(q))).first;
    }
    face.vs.push_back(it->second);
    face.edge_line.push_back(lab[i]);
  }
  if (ok) {
    // Drop zero-length edges (several lines through one vertex).
    for (bool again = true; again && face.vs.size() >= 3;) {
      again = false;
      for (std::size_t i = 0; i < face.vs.size(); ++i)
        if (face.vs[i].p == face.vs[(i + 1) % face.vs.size()].p) {
          face.vs.erase(face.vs.begin() + static_cast<std::ptrdiff_t>(i));
          face.edge_line.erase(face.edge_line.begin() + static_cast<std::ptrdiff_t>(i));
          again = true;
          break;
        }
    }
    ok = face.vs.size() >= 3;
    // Vertex i is exactly on the lines of edges i - 1 and i (their crossing): only the other lines are tested.
    const std::size_t m = face.vs.size();
    for (std::size_t l = 0; l < all_lines_.size() && ok; ++l)
      for (std::size_t i = 0; i < m; ++i) {
        const int id = static_cast<int>(l);
        if (id == face.edge_line[i] || id == face.edge_line[(i + m - 1) % m]) continue;
        if (keep[l] * line_sign(all_lines_[l], face.vs[i]) < 0) { ok = false; break; }
      }
    ok = ok && area_sign(face) > 0;
  }
  return ok ? face : face_of_exact(p, keep);
}

// Exact: clip the domain by every line, nearest first.
Face ArrangementLocator::face_of_exact(const V2& p, const std::vector<int>& keep) const {
  std::vector<std::pair<double, int>> order;
  order.reserve(static_cast<std::size_t>(num_lines_));
  for (int l = 0; l < num_lines_; ++l) {
    const Line& line = all_lines_[l];
    order.emplace_back(std::abs(line.da * p.u + line.db * p.v + line.dc) / line.dnorm, l);
  }
  std::sort(order.begin(), order.end());
  Face face = domain_;
  for (const auto& [dist, l] : order) {
    clip_face(face, all_lines_[l], l, keep[l]);
    HSR_ASSERT(!face.vs.empty(), "kinetic: located face is empty");
  }
  return face;
}

int ArrangementLocator::add(Face face, bool& added) {
  // Canonical rotation (smallest vertex first): edge indices, hence event order among equal times, do
  // not depend on how the face was computed; (first, second vertex) identifies the face.
  std::size_t first = 0;
  for (std::size_t e = 1; e < face.vs.size(); ++e)
    if (face.vs[e].p < face.vs[first].p) first = e;
  std::rotate(face.vs.begin(), face.vs.begin() + static_cast<std::ptrdiff_t>(first), face.vs.end());
  std::rotate(face.edge_line.begin(), face.edge_line.begin() + static_cast<std::ptrdiff_t>(first),
              face.edge_line.end());
  // The directed edge from the first vertex to the second identifies the face; it is the edge on line
  // edge_line[0] between its crossings with edge_line[k - 1] and edge_line[1] (distinct lines meet once).
  const std::size_t n = face.vs.size();
  const std::uint64_t key = (static_cast<std::uint64_t>(face.edge_line[n - 1]) << 42) |
                            (static_cast<std::uint64_t>(face.edge_line[0]) << 21) |
                            static_cast<std::uint64_t>(face.edge_line[1]);
  auto it = face_index_.find(key);
  added = it == face_index_.end();
  if (!added) return it->second;
  const int id = static_cast<int>(faces_.size());
  face_index_.emplace(key, id);
  // Vertex i is the crossing of the lines of edges i - 1 and i: lifted once per pair of lines.
  std::vector<std::uint32_t> lifted;
  const std::size_t k = face.vs.size();
  lifted.reserve(k);
  for (std::size_t i = 0; i < k; ++i) {
    const int l1 = face.edge_line[(i + k - 1) % k], l2 = face.edge_line[i];
    const std::pair<int, int> pair_key{std::min(l1, l2), std::max(l1, l2)};
    auto it = lifted_.find(pair_key);
    if (it == lifted_.end()) it = lifted_.emplace(pair_key, points_->id(lift(plane_, frame_, face.vs[i].p))).first;
    lifted.push_back(it->second);
  }
  faces_.push_back(std::move(face));
  faces3d_.push_back(std::move(lifted));
  return id;
}

int ArrangementLocator::beyond(int face_id, int edge, bool& added) {
  // The face beyond, located from the edge's midpoint pushed across the line.
  const Face& from = faces_[face_id];
  const int line_id = from.edge_line[edge];
  const Line& line = all_lines_[line_id];
  const P2& a = from.vs[edge].p;
  const P2& b = from.vs[(edge + 1) % from.vs.size()].p;
  P2 mid{a.u + b.u, a.v + b.v};
  mpq_div_2exp(mid.u.get_mpq_t(), mid.u.get_mpq_t(), 1);  // halving: no gcd (a rational division has one)
  mpq_div_2exp(mid.v.get_mpq_t(), mid.v.get_mpq_t(), 1);
  int face_side = 0;  // side of the line the face is on: any vertex off the line tells
  for (std::size_t q = 0; q < from.vs.size() && face_side == 0; ++q) face_side = line_sign(line, from.vs[q]);
  HSR_ASSERT(face_side != 0, "kinetic: face on its own edge line");
  return locate(mid, [&](int l) {
    HSR_ASSERT(l == line_id, "kinetic: a second line through an edge's midpoint");
    return -face_side;
  }, added);
}

}  // namespace hsr::partition_internal
