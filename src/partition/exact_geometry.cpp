#include "partition/exact_geometry.h"

#include "core/error.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace hsr::partition_internal {

namespace {

const Rational& coef(const ExactPlane& p, int axis) { return axis == 0 ? p.a : axis == 1 ? p.b : p.c; }
const Rational& coord(const ExactPoint& p, int axis) { return axis == 0 ? p.x : axis == 1 ? p.y : p.z; }
Rational& coord(ExactPoint& p, int axis) { return axis == 0 ? p.x : axis == 1 ? p.y : p.z; }

// Kept axes (i, j) for a dropped axis, ordered so (e_i, e_j, e_drop) is right-handed.
void kept_axes(int drop, int& i, int& j) {
  i = (drop + 1) % 3;
  j = (drop + 2) % 3;
}

void remove_consecutive_duplicates(std::vector<P2>& poly) {
  std::vector<P2> out;
  out.reserve(poly.size());
  for (auto& p : poly)
    if (out.empty() || !(out.back() == p)) out.push_back(std::move(p));
  while (out.size() > 1 && out.front() == out.back()) out.pop_back();
  poly = std::move(out);
}

}  // namespace

void canonicalize(ExactPlane& plane) {
  Rational lead = plane.a != 0 ? plane.a : plane.b != 0 ? plane.b : plane.c;
  HSR_ASSERT(lead != 0, "canonicalize: zero normal");
  plane.a /= lead;
  plane.b /= lead;
  plane.c /= lead;
  plane.d /= lead;
}

ExactPlane canonical_plane(const Plane& plane) {
  const Vec3& n = plane.normal;
  if (!n.allFinite() || !std::isfinite(plane.offset))
    throw Error(Status::BadInput, "partition", "input polygon plane has a non-finite coefficient");
  if (n.x() == 0.0 && n.y() == 0.0 && n.z() == 0.0)
    throw Error(Status::BadInput, "partition", "input polygon plane has a zero normal");
  ExactPlane e{Rational(n.x()), Rational(n.y()), Rational(n.z()), Rational(plane.offset)};
  canonicalize(e);
  return e;
}

bool same_plane(const ExactPlane& a, const ExactPlane& b) {
  return a.a == b.a && a.b == b.b && a.c == b.c && a.d == b.d;
}

bool plane_less(const ExactPlane& a, const ExactPlane& b) {
  if (int c = cmp(a.a, b.a)) return c < 0;
  if (int c = cmp(a.b, b.b)) return c < 0;
  if (int c = cmp(a.c, b.c)) return c < 0;
  return cmp(a.d, b.d) < 0;
}

Rational evaluate(const ExactPlane& plane, const ExactPoint& p) {
  return plane.a * p.x + plane.b * p.y + plane.c * p.z + plane.d;
}

int side(const ExactPlane& plane, const ExactPoint& p) {
  const Rational* q[8] = {&plane.a, &p.x, &plane.b, &p.y, &plane.c, &p.z, &plane.d, nullptr};
  double d[7];
  bool trusted = true;
  for (int i = 0; i < 7; ++i) {
    d[i] = q[i]->get_d();
    trusted &= trusted_double(*q[i], d[i]);
  }
  if (trusted) {
    const double tx = d[0] * d[1], ty = d[2] * d[3], tz = d[4] * d[5];
    if (int s = filtered_sign(tx + ty + tz + d[6], std::abs(tx) + std::abs(ty) + std::abs(tz) + std::abs(d[6])))
      return s;
  }
  return sgn(evaluate(plane, p));
}

PlaneFrame frame_of(const ExactPlane& plane) {
  PlaneFrame f;
  Rational best = abs(plane.a);
  f.drop = 0;
  if (abs(plane.b) > best) { best = abs(plane.b); f.drop = 1; }
  if (abs(plane.c) > best) { best = abs(plane.c); f.drop = 2; }
  f.swap = sgn(coef(plane, f.drop)) < 0;
  return f;
}

P2 to_2d(const PlaneFrame& frame, const ExactPoint& p) {
  int i, j;
  kept_axes(frame.drop, i, j);
  if (frame.swap) return {coord(p, j), coord(p, i)};
  return {coord(p, i), coord(p, j)};
}

ExactPoint lift(const ExactPlane& plane, const PlaneFrame& frame, const P2& q) {
  int i, j;
  kept_axes(frame.drop, i, j);
  ExactPoint p;
  coord(p, i) = frame.swap ? q.v : q.u;
  coord(p, j) = frame.swap ? q.u : q.v;
  coord(p, frame.drop) = -(coef(plane, i) * coord(p, i) + coef(plane, j) * coord(p, j) + plane.d) /
                         coef(plane, frame.drop);
  return p;
}

double area_scale(const ExactPlane& plane, const PlaneFrame& frame) {
  double a = plane.a.get_d(), b = plane.b.get_d(), c = plane.c.get_d();
  return std::sqrt(a * a + b * b + c * c) / std::abs(coef(plane, frame.drop).get_d());
}

ExactPoint intersect_segment(const ExactPoint& p, const ExactPoint& q, const Rational& sp, const Rational& sq) {
  Rational t = sp / (sp - sq);
  return {p.x + t * (q.x - p.x), p.y + t * (q.y - p.y), p.z + t * (q.z - p.z)};
}

Rational orient(const P2& a, const P2& b, const P2& c) {
  return (b.u - a.u) * (c.v - a.v) - (b.v - a.v) * (c.u - a.u);
}

namespace {
// Sign of u1 v2 - v1 u2, filtered like side(): with |coordinates| <= m, the double error is below
// ~7e-15 m^2 (conversion, subtraction and product roundings), far below the 1e-12 m^2 threshold.
int filtered_cross_sign(double u1, double v1, double u2, double v2, double m) {
  if (m > 1e-100 && m < 1e100) {
    const double det = u1 * v2 - v1 * u2;
    const double bound = 1e-12 * m * m;
    if (det > bound) return 1;
    if (det < -bound) return -1;
  }
  return 0;  // undecided
}
}  // namespace

int orient_sign(const P2& a, const P2& b, const P2& c) {
  if (a == b || b == c || a == c) return 0;  // common in shared-vertex tests; saves the exact fallback
  const double au = a.u.get_d(), av = a.v.get_d(), bu = b.u.get_d(), bv = b.v.get_d(), cu = c.u.get_d(),
               cv = c.v.get_d();
  const double m = std::max({std::abs(au), std::abs(av), std::abs(bu), std::abs(bv), std::abs(cu), std::abs(cv)});
  if (int s = filtered_cross_sign(bu - au, bv - av, cu - au, cv - av, 2 * m)) return s;
  return sgn(orient(a, b, c));
}

std::vector<P2> convex_hull(std::vector<P2> pts) {
  std::sort(pts.begin(), pts.end());
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  if (pts.size() < 3) return {};
  std::vector<P2> hull(2 * pts.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    while (k >= 2 && orient_sign(hull[k - 2], hull[k - 1], pts[i]) <= 0) --k;
    hull[k++] = pts[i];
  }
  for (std::size_t i = pts.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && orient_sign(hull[k - 2], hull[k - 1], pts[i]) <= 0) --k;
    hull[k++] = pts[i];
  }
  hull.resize(k - 1);
  if (hull.size() < 3) return {};
  return hull;
}

Rational twice_area(const std::vector<P2>& poly) {
  // Shoelace on integers over a common denominator: far fewer gcds than summing rational products.
  const std::size_t n = poly.size();
  if (n < 3) return 0;
  mpz_class common = 1;
  for (const P2& p : poly) {
    mpz_lcm(common.get_mpz_t(), common.get_mpz_t(), p.u.get_den_mpz_t());
    mpz_lcm(common.get_mpz_t(), common.get_mpz_t(), p.v.get_den_mpz_t());
  }
  std::vector<mpz_class> U(n), V(n);
  mpz_class scale;
  for (std::size_t i = 0; i < n; ++i) {
    mpz_divexact(scale.get_mpz_t(), common.get_mpz_t(), poly[i].u.get_den_mpz_t());
    U[i] = poly[i].u.get_num() * scale;
    mpz_divexact(scale.get_mpz_t(), common.get_mpz_t(), poly[i].v.get_den_mpz_t());
    V[i] = poly[i].v.get_num() * scale;
  }
  mpz_class sum = 0;
  for (std::size_t i = 0; i < n; ++i) sum += U[i] * (V[(i + 1) % n] - V[(i + n - 1) % n]);
  Rational area(sum, common * common);
  area.canonicalize();
  return area;
}

namespace {
// True if some edge of `a` has every vertex of `b` on its closed right side (a separating axis).
bool has_separating_edge(const std::vector<P2>& a, const std::vector<P2>& b) {
  const std::size_t n = a.size();
  for (std::size_t i = 0; i < n; ++i) {
    const P2& p = a[i];
    const P2& q = a[(i + 1) % n];
    if (p == q) continue;
    bool all_right = true;
    for (const P2& r : b)
      if (orient_sign(p, q, r) > 0) { all_right = false; break; }
    if (all_right) return true;
  }
  return false;
}
}  // namespace

namespace {
// A convex CCW loop (collinear vertices allowed) has positive area iff it has a strictly convex corner.
bool has_positive_corner(const std::vector<P2>& poly) {
  const std::size_t n = poly.size();
  for (std::size_t i = 0; i < n; ++i)
    if (orient_sign(poly[i], poly[(i + 1) % n], poly[(i + 2) % n]) > 0) return true;
  return false;
}
}  // namespace

bool interiors_overlap(const std::vector<P2>& a, const std::vector<P2>& b) {
  if (a.size() < 3 || b.size() < 3) return false;
  if (!has_positive_corner(a) || !has_positive_corner(b)) return false;
  return !has_separating_edge(a, b) && !has_separating_edge(b, a);
}

std::vector<P2> clip_convex(const std::vector<P2>& subject, const std::vector<P2>& clipper) {
  std::vector<P2> poly = subject;
  const std::size_t m = clipper.size();
  for (std::size_t e = 0; e < m && !poly.empty(); ++e) {
    const P2& c1 = clipper[e];
    const P2& c2 = clipper[(e + 1) % m];
    if (c1 == c2) continue;
    std::vector<P2> out;
    const std::size_t n = poly.size();
    std::vector<int> sign(n);
    bool any_negative = false;
    for (std::size_t i = 0; i < n; ++i) {
      sign[i] = orient_sign(c1, c2, poly[i]);
      any_negative |= sign[i] < 0;
    }
    if (!any_negative) continue;
    for (std::size_t i = 0; i < n; ++i) {
      std::size_t j = (i + 1) % n;
      int si = sign[i], sj = sign[j];
      if (si >= 0) out.push_back(poly[i]);
      if (si * sj < 0) {
        const Rational oi = orient(c1, c2, poly[i]), oj = orient(c1, c2, poly[j]);
        Rational t = oi / (oi - oj);
        out.push_back({poly[i].u + t * (poly[j].u - poly[i].u), poly[i].v + t * (poly[j].v - poly[i].v)});
      }
    }
    remove_consecutive_duplicates(out);
    poly = std::move(out);
  }
  return poly;
}

std::vector<P2> clip_by_halfspace(const std::vector<P2>& poly, const ExactPlane& plane, const PlaneFrame& frame,
                                  const ExactPlane& halfspace, int keep_sign) {
  const std::size_t n = poly.size();
  std::vector<Rational> s(n);
  for (std::size_t i = 0; i < n; ++i) s[i] = keep_sign * evaluate(halfspace, lift(plane, frame, poly[i]));
  std::vector<P2> out;
  for (std::size_t i = 0; i < n; ++i) {
    std::size_t j = (i + 1) % n;
    int si = sgn(s[i]), sj = sgn(s[j]);
    if (si >= 0) out.push_back(poly[i]);
    if (si * sj < 0) {
      Rational t = s[i] / (s[i] - s[j]);
      out.push_back({poly[i].u + t * (poly[j].u - poly[i].u), poly[i].v + t * (poly[j].v - poly[i].v)});
    }
  }
  remove_consecutive_duplicates(out);
  return out;
}

std::vector<int> sort_ccw(const std::vector<P2>& pts) {
  const int n = static_cast<int>(pts.size());
  // Pivot: centroid of three non-collinear points, strictly inside the convex polygon.
  int third = -1;
  for (int k = 2; k < n && third < 0; ++k)
    if (orient_sign(pts[0], pts[1], pts[k]) != 0) third = k;
  HSR_ASSERT(third > 0, "sort_ccw: collinear points");
  P2 c{(pts[0].u + pts[1].u + pts[third].u) / 3, (pts[0].v + pts[1].v + pts[third].v) / 3};
  std::vector<P2> d(n);
  std::vector<int> half(n);
  for (int i = 0; i < n; ++i) {
    d[i] = {pts[i].u - c.u, pts[i].v - c.v};
    int sv = sgn(d[i].v);
    half[i] = (sv > 0 || (sv == 0 && sgn(d[i].u) > 0)) ? 0 : 1;
  }
  std::vector<int> idx(n);
  for (int i = 0; i < n; ++i) idx[i] = i;
  std::vector<std::array<double, 2>> dd(n);
  for (int i = 0; i < n; ++i) dd[i] = {d[i].u.get_d(), d[i].v.get_d()};
  std::sort(idx.begin(), idx.end(), [&](int a, int b) {
    if (half[a] != half[b]) return half[a] < half[b];
    const double m = std::max({std::abs(dd[a][0]), std::abs(dd[a][1]), std::abs(dd[b][0]), std::abs(dd[b][1])});
    if (int s = filtered_cross_sign(dd[a][0], dd[a][1], dd[b][0], dd[b][1], m)) return s > 0;
    return sgn(d[a].u * d[b].v - d[a].v * d[b].u) > 0;
  });
  return idx;
}

std::vector<P2> project_polygon(const ConvexPolygon& polygon, const ExactPlane& plane, const PlaneFrame& frame) {
  std::vector<P2> pts;
  pts.reserve(polygon.vertices.size());
  for (const Vec3& v : polygon.vertices) {
    if (!v.allFinite()) throw Error(Status::BadInput, "partition", "input polygon has a non-finite vertex");
    pts.push_back(to_2d(frame, ExactPoint{Rational(v.x()), Rational(v.y()), Rational(v.z())}));
  }
  (void)plane;  // the 2D image of a vertex is its kept coordinates: projection along the dropped axis
  return convex_hull(std::move(pts));
}

ExactPlane axis_plane(int axis, const Rational& value) {
  ExactPlane p{0, 0, 0, -value};
  (axis == 0 ? p.a : axis == 1 ? p.b : p.c) = 1;
  return p;
}

std::vector<P2> clip_to_box(const std::vector<P2>& polygon2d, const ExactPlane& plane, const PlaneFrame& frame,
                            const ExactPoint& lo, const ExactPoint& hi) {
  std::vector<P2> poly = polygon2d;
  for (int axis = 0; axis < 3 && poly.size() >= 3; ++axis) {
    poly = clip_by_halfspace(poly, plane, frame, axis_plane(axis, coord(lo, axis)), +1);
    if (poly.size() < 3) break;
    poly = clip_by_halfspace(poly, plane, frame, axis_plane(axis, coord(hi, axis)), -1);
  }
  if (poly.size() < 3) return {};
  return poly;
}

Vec3 to_double(const ExactPoint& p) { return {p.x.get_d(), p.y.get_d(), p.z.get_d()}; }

}  // namespace hsr::partition_internal
