#include "partition/kinetic_growth.h"

#include "core/error.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <queue>
#include <set>

namespace hsr::partition_internal {

namespace {

// A line a u + b v + c = 0 of a plane's arrangement, normalised so the first non-zero of (a, b) is 1
// (identical lines from several planes are stored once, with every owner).
struct Line {
  Rational a, b, c;
  mpz_class za, zb, zc;  // (a, b, c) times the positive lcm of their denominators: integer, same line and sides
  double da = 0, db = 0, dc = 0, dnorm = 1;
  std::vector<int> owners;  // polygon indices whose plane cuts this plane along the line
};

// Sets the integer coefficients of a line from its rational ones.
void set_integer_coefficients(Line& l) {
  mpz_class m = 1;
  for (const Rational* r : {&l.a, &l.b, &l.c}) mpz_lcm(m.get_mpz_t(), m.get_mpz_t(), r->get_den_mpz_t());
  l.za = l.a.get_num() * (m / l.a.get_den());
  l.zb = l.b.get_num() * (m / l.b.get_den());
  l.zc = l.c.get_num() * (m / l.c.get_den());
}

struct V2 {
  P2 p;
  double u = 0, v = 0;
};

V2 make_v2(P2 p) {
  V2 out;
  out.u = p.u.get_d();
  out.v = p.v.get_d();
  out.p = std::move(p);
  return out;
}

// A convex face; edge i joins vs[i] and vs[i+1] and lies on line edge_line[i] (an index of State::all_lines:
// the arrangement's lines, then the domain's walls).
struct Face {
  std::vector<V2> vs;
  std::vector<int> edge_line;
};

using EdgeKey = std::pair<ExactPoint, ExactPoint>;
struct EdgeKeyLess {
  bool operator()(const EdgeKey& a, const EdgeKey& b) const {
    ExactPointLess less;
    if (less(a.first, b.first)) return true;
    if (less(b.first, a.first)) return false;
    return less(a.second, b.second);
  }
};

int line_sign_exact(const Line& l, const P2& p) { return sgn(l.a * p.u + l.b * p.v + l.c); }

// Exact sign of the line at a vertex, decided in doubles when the rigorous-enough bound allows.
int line_sign(const Line& l, const V2& q) {
  const double tu = l.da * q.u, tv = l.db * q.v;
  const double value = tu + tv + l.dc;
  const double bound = 1e-12 * (std::abs(tu) + std::abs(tv) + std::abs(l.dc));
  if (value > bound) return 1;
  if (value < -bound) return -1;
  return line_sign_exact(l, q.p);
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
      if (sj < 0) {
        out.edge_line.push_back(face.edge_line[i]);
        out.vs.push_back(crossing(i, j));
        out.edge_line.push_back(line_id);
      } else {
        out.edge_line.push_back(face.edge_line[i]);
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

// Gauge of the initial convex polygon about its vertex average: g(x) = max_i (A_i u + B_i v + C_i).
struct Gauge {
  P2 centre;
  std::vector<P2> rays;  // vertex - centre
  std::vector<std::array<Rational, 3>> edges;

  explicit Gauge(const std::vector<P2>& shape) {
    Rational su = 0, sv = 0;
    for (const P2& p : shape) { su += p.u; sv += p.v; }
    const Rational n(static_cast<long>(shape.size()));
    centre = {su / n, sv / n};
    for (std::size_t i = 0; i < shape.size(); ++i) {
      const P2& a = shape[i];
      const P2& b = shape[(i + 1) % shape.size()];
      rays.push_back({a.u - centre.u, a.v - centre.v});
      // Outward normal of a CCW edge: (dv, -du); scaled so the edge's line has value 1.
      const Rational nu = b.v - a.v, nv = -(b.u - a.u);
      const Rational h = nu * (a.u - centre.u) + nv * (a.v - centre.v);
      HSR_ASSERT(sgn(h) > 0, "gauge: the centre must be inside the polygon");
      const Rational A = nu / h, B = nv / h;
      edges.push_back({A, B, -(A * centre.u + B * centre.v)});
    }
    prepare_doubles();
  }
  // Doubles of the coefficients, to decide in doubles which terms can be the maximum / minimum.
  std::vector<std::array<double, 3>> dedges;
  double cu = 0, cv = 0;
  std::vector<std::array<double, 2>> drays;

  void prepare_doubles() {
    cu = centre.u.get_d();
    cv = centre.v.get_d();
    for (const auto& e : edges) dedges.push_back({e[0].get_d(), e[1].get_d(), e[2].get_d()});
    for (const P2& w : rays) drays.push_back({w.u.get_d(), w.v.get_d()});
  }
  // Double value of g at (u, v) and a bound on its error; exact value computed only for the terms that
  // can be the maximum.
  Rational at(const P2& x) const {
    const double u = x.u.get_d(), v = x.v.get_d();
    std::vector<double> val(dedges.size()), err(dedges.size());
    double best = -1e300;
    for (std::size_t i = 0; i < dedges.size(); ++i) {
      const double a = dedges[i][0] * u, b = dedges[i][1] * v;
      val[i] = a + b + dedges[i][2];
      err[i] = 1e-10 * (std::abs(a) + std::abs(b) + std::abs(dedges[i][2])) + 1e-300;
      best = std::max(best, val[i] - err[i]);
    }
    bool have = false;
    Rational result;
    for (std::size_t i = 0; i < edges.size(); ++i) {
      if (val[i] + err[i] < best) continue;  // certainly below the maximum
      Rational g = edges[i][0] * x.u + edges[i][1] * x.v + edges[i][2];
      if (!have || g > result) result = std::move(g);
      have = true;
    }
    return result;
  }
  // Minimum of g over the segment [a, b]: at an endpoint or where the segment crosses a ray from the centre
  // through a vertex (where g is the ray parameter). Candidates that doubles show to be clearly above the
  // minimum are skipped; the others are evaluated exactly.
  Rational min_on_segment(const P2& a, const P2& b) const {
    const double au = a.u.get_d(), av = a.v.get_d(), bu = b.u.get_d(), bv = b.v.get_d();
    const double eu = bu - au, ev = bv - av, ru = au - cu, rv = av - cv;
    auto approx_g = [&](double u, double v) {
      double best = -1e300;
      for (const auto& e : dedges) best = std::max(best, e[0] * u + e[1] * v + e[2]);
      return best;
    };
    // Candidates: 0 = a, 1 = b, 2 + j = ray j (approximate value, or skipped when clearly off the segment).
    std::vector<double> approx(2 + drays.size(), 1e300);
    approx[0] = approx_g(au, av);
    approx[1] = approx_g(bu, bv);
    for (std::size_t j = 0; j < drays.size(); ++j) {
      const double den = drays[j][0] * ev - drays[j][1] * eu;
      const double scale = (std::abs(drays[j][0]) + std::abs(drays[j][1])) * (std::abs(eu) + std::abs(ev));
      if (std::abs(den) <= 1e-9 * scale) {
        approx[2 + j] = -1e300;  // nearly parallel: decide exactly
        continue;
      }
      const double s = (ru * ev - rv * eu) / den;
      const double lambda = (ru * drays[j][1] - rv * drays[j][0]) / den;
      if (s < -1e-9 * (1 + std::abs(s)) || lambda < -1e-9 || lambda > 1 + 1e-9) continue;
      approx[2 + j] = s;
    }
    double lowest = 1e300;
    for (double x : approx) lowest = std::min(lowest, x);
    const double tol = 1e-8 * (1 + std::abs(lowest));
    bool have = false;
    Rational best;
    auto offer = [&](Rational g) {
      if (!have || g < best) best = std::move(g);
      have = true;
    };
    if (approx[0] <= lowest + tol) offer(at(a));
    if (approx[1] <= lowest + tol) offer(at(b));
    const Rational reu = b.u - a.u, rev = b.v - a.v;
    const Rational rru = a.u - centre.u, rrv = a.v - centre.v;
    for (std::size_t j = 0; j < rays.size(); ++j) {
      if (approx[2 + j] > lowest + tol) continue;
      const P2& w = rays[j];
      const Rational den = w.u * rev - w.v * reu;  // w x e
      if (sgn(den) == 0) continue;
      Rational sj = (rru * rev - rrv * reu) / den;
      if (sgn(sj) < 0) continue;
      const Rational lambda = (rru * w.v - rrv * w.u) / den;  // (r x w) / (w x e)
      if (sgn(lambda) < 0 || lambda > 1) continue;
      offer(std::move(sj));
    }
    if (!have) {  // every candidate was filtered out by rounding: evaluate the endpoints exactly
      offer(at(a));
      offer(at(b));
    }
    return best;
  }
};

struct Event {
  Rational time;
  bool free = false;  // the edge meets the interior of the initial polygon
  int polygon = 0, face = 0, edge = 0;
};
struct EventLater {
  bool operator()(const Event& a, const Event& b) const {
    const int c = cmp(a.time, b.time);
    if (c != 0) return c > 0;
    if (a.free != b.free) return !a.free;
    if (a.polygon != b.polygon) return a.polygon > b.polygon;
    if (a.face != b.face) return a.face > b.face;
    return a.edge > b.edge;
  }
};

struct State {
  const GrowthPolygon* in = nullptr;
  std::vector<Line> lines;      // the arrangement's lines (other planes)
  std::vector<Line> all_lines;  // lines, then the domain's walls (one per domain edge; interior positive)
  Face domain;
  Gauge gauge;
  std::vector<Face> faces;
  std::vector<std::vector<ExactPoint>> faces3d;
  std::map<std::pair<int, int>, P2> crossings;  // exact intersection of two lines (smaller id first)
  std::map<std::pair<P2, P2>, int> face_index;  // (smallest vertex, next vertex CCW) -> face
  std::map<EdgeKey, int, EdgeKeyLess> coverage;  // region faces on each edge (2 = both sides)
  std::vector<int> paid;  // sorted polygon indices already paid for
  int budget = 1;
  // hierarchical: the polygon's bounds, lines of adjacent polygons that stay out of the inner half of its
  // initial polygon, with the sign of the centre's side (see the file comment of kinetic_growth.h).
  std::vector<std::pair<int, int>> bounds;
  std::vector<char> face_inside;  // per face: inside every bound
  explicit State(const GrowthPolygon& p) : in(&p), gauge(p.shape) {}
};

EdgeKey edge_key(const ExactPoint& a, const ExactPoint& b) {
  if (ExactPointLess()(b, a)) return {b, a};
  return {a, b};
}

const Rational& coefficient(const ExactPlane& p, int axis) { return axis == 0 ? p.a : axis == 1 ? p.b : p.c; }

// Line of plane `other` in the frame of polygon `self`'s plane, or false if the planes are parallel or the
// line certainly misses the interior of the domain (all domain vertices clearly on one side, in doubles).
// On self's plane, x_drop = -(a_i x_i + a_j x_j + d) / a_drop, so other's equation restricted to it is
// affine in the two kept coordinates.
bool line_between(const GrowthPolygon& self, const std::vector<std::array<double, 2>>& domain,
                  const ExactPlane& other, Line& out) {
  const int drop = self.frame.drop;
  int ku = (drop + 1) % 3, kv = (drop + 2) % 3;  // as exact_geometry's frames: (u, v) = (x_ku, x_kv) ...
  if (self.frame.swap) std::swap(ku, kv);          // ... or swapped
  const ExactPlane& p = self.plane;
  // Doubles first: reject lines that clearly miss the domain.
  {
    const double pd = coefficient(p, drop).get_d(), od = coefficient(other, drop).get_d();
    const double r = od / pd;
    const double a = coefficient(other, ku).get_d() - r * coefficient(p, ku).get_d();
    const double b = coefficient(other, kv).get_d() - r * coefficient(p, kv).get_d();
    const double c = other.d.get_d() - r * p.d.get_d();
    bool pos = false, neg = false;
    for (const auto& q : domain) {
      const double ta = a * q[0], tb = b * q[1];
      const double v = ta + tb + c;
      const double tol = 1e-9 * (std::abs(ta) + std::abs(tb) + std::abs(c) + std::abs(r) *
                                 (std::abs(coefficient(p, ku).get_d() * q[0]) +
                                  std::abs(coefficient(p, kv).get_d() * q[1]) + std::abs(p.d.get_d())));
      pos |= v > -tol;
      neg |= v < tol;
    }
    if (!pos || !neg) return false;
  }
  const Rational ratio = coefficient(other, drop) / coefficient(p, drop);
  Rational a = coefficient(other, ku) - ratio * coefficient(p, ku);
  Rational b = coefficient(other, kv) - ratio * coefficient(p, kv);
  Rational c = other.d - ratio * p.d;
  if (sgn(a) == 0 && sgn(b) == 0) return false;
  const Rational lead = sgn(a) != 0 ? a : b;
  out.a = a / lead;  // signed: opposite orientations of one line get one key
  out.b = b / lead;
  out.c = c / lead;
  out.da = out.a.get_d();
  out.db = out.b.get_d();
  out.dc = out.c.get_d();
  out.dnorm = std::hypot(out.da, out.db);
  set_integer_coefficients(out);
  return true;
}

// Cramer's rule on the integer coefficients: one canonicalisation per coordinate instead of one per
// rational operation (this is the growth's hottest exact construction).
bool intersect_lines(const Line& l1, const Line& l2, P2& out) {
  const mpz_class det = l1.za * l2.zb - l2.za * l1.zb;
  if (sgn(det) == 0) return false;
  out.u = Rational(l1.zb * l2.zc - l2.zb * l1.zc, det);
  out.v = Rational(l1.zc * l2.za - l2.zc * l1.za, det);
  out.u.canonicalize();
  out.v.canonicalize();
  return true;
}

}  // namespace

bool point_in_convex(const P2& p, const std::vector<P2>& polygon) {
  const std::size_t n = polygon.size();
  for (std::size_t i = 0; i < n; ++i)
    if (orient_sign(polygon[i], polygon[(i + 1) % n], p) < 0) return false;
  return n >= 3;
}

std::vector<GrownRegion> grow_regions(const std::vector<GrowthPolygon>& polygons, const GrowthRules& rules) {
  const int n = static_cast<int>(polygons.size());
  std::vector<State> states;
  states.reserve(polygons.size());
  for (const GrowthPolygon& p : polygons) states.emplace_back(p);

  // 1. Lines of each plane's arrangement that cross the interior of its domain section.
  for (int i = 0; i < n; ++i) {
    State& st = states[i];
    for (const P2& q : st.in->domain) {
      st.domain.vs.push_back(make_v2(q));
      st.domain.edge_line.push_back(-1);
    }
    std::map<std::array<Rational, 3>, int> by_coefficients;
    std::vector<std::array<double, 2>> domain_approx;
    for (const V2& q : st.domain.vs) domain_approx.push_back({q.u, q.v});
    for (int j = 0; j < n; ++j) {
      if (j == i) continue;
      Line line;
      if (!line_between(*st.in, domain_approx, polygons[j].plane, line)) continue;
      bool pos = false, neg = false;
      for (const V2& q : st.domain.vs) {
        const int s = line_sign(line, q);
        pos |= s > 0;
        neg |= s < 0;
      }
      if (!pos || !neg) continue;
      std::array<Rational, 3> key{line.a, line.b, line.c};
      auto it = by_coefficients.find(key);
      if (it != by_coefficients.end()) {
        st.lines[it->second].owners.push_back(j);
        continue;
      }
      line.owners.push_back(j);
      by_coefficients.emplace(key, static_cast<int>(st.lines.size()));
      st.lines.push_back(std::move(line));
    }
    if (rules.hierarchical) {
      const auto& adj = rules.adjacent[i];
      for (std::size_t l = 0; l < st.lines.size(); ++l) {
        const Line& line = st.lines[l];
        if (std::none_of(line.owners.begin(), line.owners.end(),
                         [&](int q) { return std::binary_search(adj.begin(), adj.end(), q); }))
          continue;
        // Smallest gauge on the line: the line meets the ray centre + t * ray_i at t = -L(centre) / (a . ray_i)
        // and g = t there; the minimum over the line is at one of these crossings.
        const Rational at_centre = line.a * st.gauge.centre.u + line.b * st.gauge.centre.v + line.c;
        if (sgn(at_centre) == 0) continue;
        bool deep = false;
        for (const P2& ray : st.gauge.rays) {
          const Rational slope = line.a * ray.u + line.b * ray.v;
          if (sgn(slope) == 0 || sgn(slope) == sgn(at_centre)) continue;  // parallel, or moving away
          if (-at_centre / slope * 2 < 1) deep = true;
        }
        if (deep) continue;  // through the inner half of the polygon (a T-junction): not a bound of its extent
        st.bounds.emplace_back(static_cast<int>(l), sgn(at_centre));
      }
    }
    st.all_lines = st.lines;
    const std::size_t m = st.domain.vs.size();
    for (std::size_t e = 0; e < m; ++e) {
      const P2& p = st.domain.vs[e].p;
      const P2& q = st.domain.vs[(e + 1) % m].p;
      Line wall;  // cross(q - p, x - p) >= 0 inside
      wall.a = p.v - q.v;
      wall.b = q.u - p.u;
      wall.c = -(wall.a * p.u + wall.b * p.v);
      wall.da = wall.a.get_d();
      wall.db = wall.b.get_d();
      wall.dc = wall.c.get_d();
      wall.dnorm = std::hypot(wall.da, wall.db);
      set_integer_coefficients(wall);
      st.domain.edge_line[e] = static_cast<int>(st.all_lines.size());
      st.all_lines.push_back(std::move(wall));
    }
  }

  std::priority_queue<Event, std::vector<Event>, EventLater> queue;

  // The face of polygon i's arrangement containing point p, where a line through p is resolved by the
  // side `tie(line)` (+1/-1) of a symbolic perturbation. Fast path: clip in doubles to learn which lines
  // bound the face, build its vertices exactly as intersections of consecutive bounding lines, and accept
  // them only if exactly every vertex is on the kept side of every line and the area is positive (then the
  // polygon is the face). Otherwise clip exactly.
  auto locate = [&](State& st, const P2& p, auto&& tie) {
    const std::size_t n_lines = st.lines.size();
    const std::size_t n_all = st.all_lines.size();
    const V2 pv = make_v2(p);
    std::vector<int> keep(n_all, 1);  // walls: the domain is on their positive side
    for (std::size_t l = 0; l < n_lines; ++l) {
      int s = line_sign(st.lines[l], pv);
      if (s == 0) s = tie(static_cast<int>(l));
      keep[l] = s;
    }
    // Approximate clip.
    std::vector<std::array<double, 2>> poly, next;
    std::vector<int> lab, next_lab;
    for (std::size_t i = 0; i < st.domain.vs.size(); ++i) {
      poly.push_back({st.domain.vs[i].u, st.domain.vs[i].v});
      lab.push_back(st.domain.edge_line[i]);
    }
    std::vector<double> val;
    for (std::size_t l = 0; l < n_lines && poly.size() >= 3; ++l) {
      const Line& line = st.lines[l];
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
          next_lab.push_back(val[j] < 0 && val[i] == 0 ? static_cast<int>(l) : lab[i]);
          if (val[i] > 0 && val[j] < 0) {
            const double t = val[i] / (val[i] - val[j]);
            next.push_back({poly[i][0] + t * (poly[j][0] - poly[i][0]), poly[i][1] + t * (poly[j][1] - poly[i][1])});
            next_lab.push_back(static_cast<int>(l));
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
    if (ok) {
      const std::size_t k = lab.size();
      for (std::size_t i = 0; i < k && ok; ++i) {
        // A vertex is shared by up to four faces: intersections are cached per pair of lines.
        const int l1 = lab[(i + k - 1) % k], l2 = lab[i];
        const std::pair<int, int> pair_key{std::min(l1, l2), std::max(l1, l2)};
        auto it = st.crossings.find(pair_key);
        if (it == st.crossings.end()) {
          P2 q;
          ok = intersect_lines(st.all_lines[l1], st.all_lines[l2], q);
          if (!ok) break;
          it = st.crossings.emplace(pair_key, std::move(q)).first;
        }
        face.vs.push_back(make_v2(it->second));
        face.edge_line.push_back(lab[i]);
      }
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
      for (std::size_t l = 0; l < n_all && ok; ++l)
        for (const V2& q : face.vs)
          if (keep[l] * line_sign(st.all_lines[l], q) < 0) { ok = false; break; }
      if (ok) {
        double area2 = 0, mag = 0;
        const std::size_t k = face.vs.size();
        for (std::size_t i = 0; i < k; ++i) {
          const V2& a = face.vs[i];
          const V2& b = face.vs[(i + 1) % k];
          area2 += a.u * b.v - b.u * a.v;
          mag += std::abs(a.u * b.v) + std::abs(b.u * a.v);
        }
        if (!(area2 > 1e-12 * mag)) {
          std::vector<P2> pts;
          for (const V2& q : face.vs) pts.push_back(q.p);
          ok = sgn(twice_area(pts)) > 0;
        }
      }
    }
    if (ok) return face;
    // Exact fallback: clip the domain by every line, nearest first.
    std::vector<std::pair<double, int>> order;
    order.reserve(n_lines);
    for (std::size_t l = 0; l < n_lines; ++l) {
      const Line& line = st.lines[l];
      order.emplace_back(std::abs(line.da * pv.u + line.db * pv.v + line.dc) / line.dnorm, static_cast<int>(l));
    }
    std::sort(order.begin(), order.end());
    face = st.domain;
    for (const auto& [dist, l] : order) {
      clip_face(face, st.lines[l], l, keep[l]);
      HSR_ASSERT(!face.vs.empty(), "kinetic: located face is empty");
    }
    return face;
  };

  auto add_face = [&](int i, Face face) {
    State& st = states[i];
    // Canonical rotation (smallest vertex first): edge indices, hence event order among equal times, do
    // not depend on how the face was computed; (first, second vertex) identifies the face.
    std::size_t first = 0;
    for (std::size_t e = 1; e < face.vs.size(); ++e)
      if (face.vs[e].p < face.vs[first].p) first = e;
    std::rotate(face.vs.begin(), face.vs.begin() + static_cast<std::ptrdiff_t>(first), face.vs.end());
    std::rotate(face.edge_line.begin(), face.edge_line.begin() + static_cast<std::ptrdiff_t>(first), face.edge_line.end());
    std::pair<P2, P2> key{face.vs[0].p, face.vs[1].p};
    if (st.face_index.count(key)) return;
    const int id = static_cast<int>(st.faces.size());
    st.face_index.emplace(std::move(key), id);
    std::vector<ExactPoint> lifted;
    lifted.reserve(face.vs.size());
    for (const V2& q : face.vs) lifted.push_back(lift(st.in->plane, st.in->frame, q.p));
    const std::size_t m = face.vs.size();
    for (std::size_t e = 0; e < m; ++e) {
      const EdgeKey k = edge_key(lifted[e], lifted[(e + 1) % m]);
      const int count = ++st.coverage[k];
      if (face.edge_line[e] >= static_cast<int>(st.lines.size()) || count >= 2) continue;  // wall
      const Rational g = st.gauge.min_on_segment(face.vs[e].p, face.vs[(e + 1) % m].p);
      Event ev;
      ev.free = g < 1;
      ev.time = ev.free ? Rational(0) : Rational(st.in->time_scale * (g - 1));
      ev.polygon = i;
      ev.face = id;
      ev.edge = static_cast<int>(e);
      queue.push(std::move(ev));
    }
    bool inside = !st.bounds.empty();  // no bound: no evidence where the polygon ends, no events B
    for (const auto& [l, side] : st.bounds)
      for (const V2& q : face.vs)
        if (side * line_sign(st.lines[l], q) < 0) inside = false;
    st.face_inside.push_back(inside);
    st.faces.push_back(std::move(face));
    st.faces3d.push_back(std::move(lifted));
  };

  // 2. Initial faces: the face containing a point inside the start polygon; the free events then flood
  // every face the initial polygon overlaps.
  for (int i = 0; i < n; ++i) {
    State& st = states[i];
    st.budget = rules.k;
    const P2& seed = st.in->seed;
    // Perturbation seed + eps (1, eps): a line through the seed keeps the side its gradient points to.
    Face f = locate(st, seed, [&](int l) {
      const Line& line = st.lines[l];
      return sgn(line.a) != 0 ? sgn(line.a) : sgn(line.b);
    });
    add_face(i, std::move(f));
  }

  std::vector<GrownRegion> out(polygons.size());
  // 3. Events.
  while (!queue.empty()) {
    const Event ev = queue.top();
    queue.pop();
    State& st = states[ev.polygon];
    const std::vector<ExactPoint>& f3 = st.faces3d[ev.face];
    const std::size_t m = f3.size();
    const EdgeKey key = edge_key(f3[ev.edge], f3[(ev.edge + 1) % m]);
    if (st.coverage[key] >= 2) continue;  // the face beyond is already in the region
    const int line_id = st.faces[ev.face].edge_line[ev.edge];
    const Line& line = st.lines[line_id];
    if (!ev.free) {
      std::vector<int> present;
      for (int q : line.owners) {
        auto it = states[q].coverage.find(key);
        if (it != states[q].coverage.end() && it->second >= 2) present.push_back(q);
      }
      std::vector<int> unpaid;
      for (int q : present)
        if (!std::binary_search(st.paid.begin(), st.paid.end(), q)) unpaid.push_back(q);
      if (!unpaid.empty()) {
        bool stop = false;
        if (!rules.hierarchical) {
          const int c = static_cast<int>(unpaid.size());
          if (c >= st.budget) stop = true;
          else st.budget -= c;
        } else {
          const auto& adj = rules.adjacent[ev.polygon];
          for (int q : present)
            if (std::binary_search(adj.begin(), adj.end(), q)) stop = true;  // events C
          // Events B are crossed only on the way to the polygon's bounds (the face beyond stays inside).
          const bool towards_bounds =
              st.face_inside[ev.face] && std::none_of(st.bounds.begin(), st.bounds.end(),
                                                      [&](const auto& b) { return b.first == line_id; });
          if (!towards_bounds) stop = true;
          if (st.paid.size() + unpaid.size() > static_cast<std::size_t>(rules.max_crossings)) stop = true;
        }
        if (stop) {
          ++out[ev.polygon].stops;
          continue;
        }
        ++out[ev.polygon].crossings;
        st.paid.insert(st.paid.end(), unpaid.begin(), unpaid.end());
        std::sort(st.paid.begin(), st.paid.end());
      }
    }
    // Cross: the face beyond the edge, located from the edge's midpoint pushed across the line.
    const Face& from = st.faces[ev.face];
    const P2& a = from.vs[ev.edge].p;
    const P2& b = from.vs[(ev.edge + 1) % from.vs.size()].p;
    const P2 mid{(a.u + b.u) / 2, (a.v + b.v) / 2};
    int face_side = 0;  // side of the line the face is on: any vertex off the line tells
    for (std::size_t q = 0; q < from.vs.size() && face_side == 0; ++q) face_side = line_sign(line, from.vs[q]);
    HSR_ASSERT(face_side != 0, "kinetic: face on its own edge line");
    Face beyond = locate(st, mid, [&](int l) {
      HSR_ASSERT(l == line_id, "kinetic: a second line through an edge's midpoint");
      return -face_side;
    });
    add_face(ev.polygon, std::move(beyond));
  }

  for (int i = 0; i < n; ++i)
    for (const Face& f : states[i].faces) {
      std::vector<P2> poly;
      poly.reserve(f.vs.size());
      for (const V2& q : f.vs) poly.push_back(q.p);
      out[i].faces.push_back(std::move(poly));
    }
  return out;
}

}  // namespace hsr::partition_internal
