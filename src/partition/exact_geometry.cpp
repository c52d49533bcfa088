#include "partition/exact_geometry.h"

#include "core/error.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <new>

#include <sys/mman.h>

namespace hsr::partition_internal {

namespace {

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

namespace {
std::atomic<bool> g_filters{true};
}  // namespace

namespace {
void hash_limbs(std::size_t& h, mpz_srcptr z) {
  h = (h ^ static_cast<std::size_t>(z->_mp_size)) * 0x100000001b3ull;
  const std::size_t n = mpz_size(z);
  for (std::size_t i = 0; i < n; ++i) h = (h ^ static_cast<std::size_t>(mpz_getlimbn(z, static_cast<mp_size_t>(i)))) * 0x100000001b3ull;
}
}  // namespace

std::size_t ExactPointHash::operator()(const ExactPoint& p) const {
  std::size_t h = 0xcbf29ce484222325ull;
  for (const Rational* q : {&p.x, &p.y, &p.z}) {
    hash_limbs(h, q->get_num_mpz_t());
    hash_limbs(h, q->get_den_mpz_t());
  }
  return h ^ (h >> 29);
}

constexpr std::size_t kHuge = std::size_t{2} << 20;  ///< a transparent huge page

void* allocate_table(std::size_t bytes) {
  if (bytes < kHuge) return ::operator new(bytes);
  const std::size_t rounded = (bytes + kHuge - 1) / kHuge * kHuge;
  void* p = std::aligned_alloc(kHuge, rounded);
  if (!p) throw std::bad_alloc();
  (void)madvise(p, rounded, MADV_HUGEPAGE);  // advice only: refused (THP off), the table still works
  return p;
}

void free_table(void* p, std::size_t bytes) noexcept {
  if (bytes < kHuge) ::operator delete(p);
  else std::free(p);
}

void set_filters(bool on) { g_filters.store(on, std::memory_order_relaxed); }
bool filters_on() { return g_filters.load(std::memory_order_relaxed); }

IntPlane int_plane(const ExactPlane& plane) {
  mpz_class m = 1;
  for (const Rational* r : {&plane.a, &plane.b, &plane.c, &plane.d})
    if (mpz_cmp_ui(r->get_den_mpz_t(), 1) != 0) mpz_lcm(m.get_mpz_t(), m.get_mpz_t(), r->get_den_mpz_t());
  IntPlane out;
  mpz_class* z[4] = {&out.a, &out.b, &out.c, &out.d};
  const Rational* r[4] = {&plane.a, &plane.b, &plane.c, &plane.d};
  for (int k = 0; k < 4; ++k) {
    mpz_divexact(z[k]->get_mpz_t(), m.get_mpz_t(), r[k]->get_den_mpz_t());
    *z[k] *= r[k]->get_num();
  }
  return out;
}

int side_exact(const IntPlane& h, const ExactPoint& p) {
  // a x + b y + c z + d with x = xn / xd ..., times xd yd zd > 0:
  //   a xn yd zd + xd (b yn zd + c zn yd + d yd zd), or with one denominator w: a xn + b yn + c zn + d w.
  thread_local mpz_class s, t;
  const mpz_class &xn = p.x.get_num(), &yn = p.y.get_num(), &zn = p.z.get_num();
  const mpz_class &xd = p.x.get_den(), &yd = p.y.get_den(), &zd = p.z.get_den();
  if (xd == yd && yd == zd) {
    mpz_mul(s.get_mpz_t(), h.d.get_mpz_t(), xd.get_mpz_t());
    mpz_addmul(s.get_mpz_t(), h.a.get_mpz_t(), xn.get_mpz_t());
    mpz_addmul(s.get_mpz_t(), h.b.get_mpz_t(), yn.get_mpz_t());
    mpz_addmul(s.get_mpz_t(), h.c.get_mpz_t(), zn.get_mpz_t());
    return sgn(s);
  }
  mpz_mul(t.get_mpz_t(), yd.get_mpz_t(), zd.get_mpz_t());  // yd zd
  mpz_mul(s.get_mpz_t(), h.d.get_mpz_t(), t.get_mpz_t());  // d yd zd
  if (sgn(h.a) != 0) {
    t *= xn;
    t *= h.a;  // a xn yd zd
  } else {
    t = 0;
  }
  thread_local mpz_class u;
  if (sgn(h.b) != 0) {
    mpz_mul(u.get_mpz_t(), h.b.get_mpz_t(), yn.get_mpz_t());
    mpz_addmul(s.get_mpz_t(), u.get_mpz_t(), zd.get_mpz_t());
  }
  if (sgn(h.c) != 0) {
    mpz_mul(u.get_mpz_t(), h.c.get_mpz_t(), zn.get_mpz_t());
    mpz_addmul(s.get_mpz_t(), u.get_mpz_t(), yd.get_mpz_t());
  }
  s *= xd;
  s += t;
  return sgn(s);
}

namespace {
// out = n_p x n_q (the normals' cross product).
void cross(const IntPlane& p, const IntPlane& q, mpz_class (&out)[3]) {
  mpz_mul(out[0].get_mpz_t(), p.b.get_mpz_t(), q.c.get_mpz_t());
  mpz_submul(out[0].get_mpz_t(), p.c.get_mpz_t(), q.b.get_mpz_t());
  mpz_mul(out[1].get_mpz_t(), p.c.get_mpz_t(), q.a.get_mpz_t());
  mpz_submul(out[1].get_mpz_t(), p.a.get_mpz_t(), q.c.get_mpz_t());
  mpz_mul(out[2].get_mpz_t(), p.a.get_mpz_t(), q.b.get_mpz_t());
  mpz_submul(out[2].get_mpz_t(), p.b.get_mpz_t(), q.a.get_mpz_t());
}
}  // namespace

namespace {
/// Where three planes meet, x = -(d_p (n_q x n_r) + d_q (n_r x n_p) + d_r (n_p x n_q)) / (n_p . (n_q x n_r)):
/// the crossed normals and the determinant once (solve), then each coordinate wanted as a canonical rational
/// (coordinate). Kept thread_local by its users: no allocation per call.
struct PlaneMeeting {
  mpz_class qr[3], rp[3], pq[3], det;
  /// False when the planes do not meet in one point (determinant 0).
  bool solve(const IntPlane& p, const IntPlane& q, const IntPlane& r) {
    cross(q, r, qr);
    mpz_mul(det.get_mpz_t(), p.a.get_mpz_t(), qr[0].get_mpz_t());
    mpz_addmul(det.get_mpz_t(), p.b.get_mpz_t(), qr[1].get_mpz_t());
    mpz_addmul(det.get_mpz_t(), p.c.get_mpz_t(), qr[2].get_mpz_t());
    if (sgn(det) == 0) return false;
    cross(r, p, rp);
    cross(p, q, pq);
    return true;
  }
  /// Coordinate k (0: x, 1: y, 2: z) of the point, after solve().
  void coordinate(const IntPlane& p, const IntPlane& q, const IntPlane& r, int k, Rational& out) const {
    mpz_ptr num = mpq_numref(out.get_mpq_t());
    mpz_mul(num, p.d.get_mpz_t(), qr[k].get_mpz_t());
    mpz_addmul(num, q.d.get_mpz_t(), rp[k].get_mpz_t());
    mpz_addmul(num, r.d.get_mpz_t(), pq[k].get_mpz_t());
    mpz_neg(num, num);
    mpz_set(mpq_denref(out.get_mpq_t()), det.get_mpz_t());
    out.canonicalize();
  }
};
}  // namespace

bool meet_planes(const IntPlane& p, const IntPlane& q, const IntPlane& r, ExactPoint& out) {
  thread_local PlaneMeeting m;
  if (!m.solve(p, q, r)) return false;
  m.coordinate(p, q, r, 0, out.x);
  m.coordinate(p, q, r, 1, out.y);
  m.coordinate(p, q, r, 2, out.z);
  return true;
}

bool meet_planes(const IntPlane& p, const IntPlane& q, const IntPlane& r, const PlaneFrame& frame, P2& out) {
  // As above, for the two kept coordinates only (the dropped one's gcd saved).
  thread_local PlaneMeeting m;
  if (!m.solve(p, q, r)) return false;
  int i, j;
  kept_axes(frame.drop, i, j);
  m.coordinate(p, q, r, i, frame.swap ? out.v : out.u);
  m.coordinate(p, q, r, j, frame.swap ? out.u : out.v);
  return true;
}

void homogeneous(const P2& p, mpz_class (&h)[3]) {
  const mpz_class &un = p.u.get_num(), &vn = p.v.get_num(), &ud = p.u.get_den(), &vd = p.v.get_den();
  if (ud == vd) {
    h[0] = un;
    h[1] = vn;
    h[2] = ud;
  } else {
    h[0] = un * vd;
    h[1] = vn * ud;
    h[2] = ud * vd;
  }
}

int sign_at(const mpz_class& a, const mpz_class& b, const mpz_class& c, const Rational& u, const Rational& v) {
  thread_local mpz_class s, t;
  const mpz_class &un = u.get_num(), &vn = v.get_num(), &ud = u.get_den(), &vd = v.get_den();
  if (ud == vd) {  // a un + b vn + c w
    mpz_mul(s.get_mpz_t(), c.get_mpz_t(), ud.get_mpz_t());
    mpz_addmul(s.get_mpz_t(), a.get_mpz_t(), un.get_mpz_t());
    mpz_addmul(s.get_mpz_t(), b.get_mpz_t(), vn.get_mpz_t());
    return sgn(s);
  }
  // (a un + c ud) vd + b vn ud
  mpz_mul(s.get_mpz_t(), c.get_mpz_t(), ud.get_mpz_t());
  mpz_addmul(s.get_mpz_t(), a.get_mpz_t(), un.get_mpz_t());
  s *= vd;
  mpz_mul(t.get_mpz_t(), b.get_mpz_t(), vn.get_mpz_t());
  mpz_addmul(s.get_mpz_t(), t.get_mpz_t(), ud.get_mpz_t());
  return sgn(s);
}

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
  return side_exact(int_plane(plane), p);
}

PlaneFrame frame_of(const ExactPlane& plane) {
  PlaneFrame f;
  Rational best = abs(plane.a);
  f.drop = 0;
  if (abs(plane.b) > best) { best = abs(plane.b); f.drop = 1; }
  if (abs(plane.c) > best) { best = abs(plane.c); f.drop = 2; }
  f.swap = sgn(plane.coef(f.drop)) < 0;
  return f;
}

P2 to_2d(const PlaneFrame& frame, const ExactPoint& p) {
  int i, j;
  kept_axes(frame.drop, i, j);
  if (frame.swap) return {coord(p, j), coord(p, i)};
  return {coord(p, i), coord(p, j)};
}

D2 to_2d(const PlaneFrame& frame, const Vec3& p) {
  int i, j;
  kept_axes(frame.drop, i, j);
  if (frame.swap) return {p[j], p[i]};
  return {p[i], p[j]};
}

ExactPoint lift(const ExactPlane& plane, const PlaneFrame& frame, const P2& q) {
  int i, j;
  kept_axes(frame.drop, i, j);
  ExactPoint p;
  coord(p, i) = frame.swap ? q.v : q.u;
  coord(p, j) = frame.swap ? q.u : q.v;
  coord(p, frame.drop) = -(plane.coef(i) * coord(p, i) + plane.coef(j) * coord(p, j) + plane.d) /
                         plane.coef(frame.drop);
  return p;
}

ExactPoint lift(const IntPlane& plane, const PlaneFrame& frame, const P2& q) {
  int i, j;
  kept_axes(frame.drop, i, j);
  const mpz_class* coefs[3] = {&plane.a, &plane.b, &plane.c};
  ExactPoint p;
  Rational& xi = coord(p, i);
  Rational& xj = coord(p, j);
  xi = frame.swap ? q.v : q.u;
  xj = frame.swap ? q.u : q.v;
  // x_drop = -(A_i x_i + A_j x_j + D) / A_drop, as one fraction: x_i = pi / qi, x_j = pj / qj.
  const mpz_class &pi = xi.get_num(), &qi = xi.get_den(), &pj = xj.get_num(), &qj = xj.get_den();
  Rational& x = coord(p, frame.drop);
  mpz_class& num = x.get_num();
  mpz_class& den = x.get_den();
  if (qi == qj) {
    num = *coefs[i] * pi + *coefs[j] * pj + plane.d * qi;
    den = *coefs[frame.drop] * qi;
  } else {
    num = (*coefs[i] * pi + plane.d * qi) * qj + *coefs[j] * pj * qi;
    den = *coefs[frame.drop] * qi * qj;
  }
  num = -num;
  x.canonicalize();
  return p;
}

double area_scale(const ExactPlane& plane, const PlaneFrame& frame) {
  double a = plane.a.get_d(), b = plane.b.get_d(), c = plane.c.get_d();
  return std::sqrt(a * a + b * b + c * c) / std::abs(plane.coef(frame.drop).get_d());
}

ExactPoint intersect_segment(const IntPlane& h, const ExactPoint& p, const ExactPoint& q) {
  // Homogeneous (X, Y, Z, W), W > 0: with one denominator w, (xn, yn, zn, w); else (xn yd zd, yn xd zd, zn xd yd,
  // xd yd zd). The crossing is s(P) Q - s(Q) P, s(X) = a X + b Y + c Z + d W.
  auto homogeneous = [](const ExactPoint& x, mpz_class (&out)[4]) {
    const mpz_class &xd = x.x.get_den(), &yd = x.y.get_den(), &zd = x.z.get_den();
    if (xd == yd && yd == zd) {
      out[0] = x.x.get_num();
      out[1] = x.y.get_num();
      out[2] = x.z.get_num();
      out[3] = xd;
    } else {
      out[0] = x.x.get_num() * yd * zd;
      out[1] = x.y.get_num() * xd * zd;
      out[2] = x.z.get_num() * xd * yd;
      out[3] = xd * yd * zd;
    }
  };
  mpz_class P[4], Q[4];
  homogeneous(p, P);
  homogeneous(q, Q);
  const mpz_class sp = h.a * P[0] + h.b * P[1] + h.c * P[2] + h.d * P[3];
  const mpz_class sq = h.a * Q[0] + h.b * Q[1] + h.c * Q[2] + h.d * Q[3];
  const mpz_class w = sp * Q[3] - sq * P[3];
  ExactPoint out;
  Rational* coords[3] = {&out.x, &out.y, &out.z};
  for (int k = 0; k < 3; ++k) {
    coords[k]->get_num() = sp * Q[k] - sq * P[k];
    coords[k]->get_den() = w;
    coords[k]->canonicalize();
  }
  return out;
}

Rational orient(const P2& a, const P2& b, const P2& c) {
  return (b.u - a.u) * (c.v - a.v) - (b.v - a.v) * (c.u - a.u);
}

namespace {
// Sign of u1 v2 - v1 u2, filtered like side(): with |coordinates| <= m, the double error is below
// ~7e-15 m^2 (conversion, subtraction and product roundings), far below the 1e-12 m^2 threshold.
int filtered_cross_sign(double u1, double v1, double u2, double v2, double m) {
  if (filters_on() && m > 1e-100 && m < 1e100) {
    const double det = u1 * v2 - v1 * u2;
    const double bound = 1e-12 * m * m;
    if (det > bound) return 1;
    if (det < -bound) return -1;
  }
  return 0;  // undecided
}
}  // namespace

int orient_sign_homogeneous(const mpz_class (&A)[3], const mpz_class (&B)[3], const mpz_class (&C)[3]) {
  // With W > 0 the sign of det [A; B; C] is the sign of orient(a, b, c).
  thread_local mpz_class s, t;
  // A0 (B1 C2 - B2 C1) - A1 (B0 C2 - B2 C0) + A2 (B0 C1 - B1 C0)
  mpz_mul(t.get_mpz_t(), B[1].get_mpz_t(), C[2].get_mpz_t());
  mpz_submul(t.get_mpz_t(), B[2].get_mpz_t(), C[1].get_mpz_t());
  mpz_mul(s.get_mpz_t(), A[0].get_mpz_t(), t.get_mpz_t());
  mpz_mul(t.get_mpz_t(), B[0].get_mpz_t(), C[2].get_mpz_t());
  mpz_submul(t.get_mpz_t(), B[2].get_mpz_t(), C[0].get_mpz_t());
  mpz_submul(s.get_mpz_t(), A[1].get_mpz_t(), t.get_mpz_t());
  mpz_mul(t.get_mpz_t(), B[0].get_mpz_t(), C[1].get_mpz_t());
  mpz_submul(t.get_mpz_t(), B[1].get_mpz_t(), C[0].get_mpz_t());
  mpz_addmul(s.get_mpz_t(), A[2].get_mpz_t(), t.get_mpz_t());
  return sgn(s);
}

int orient_sign_exact(const P2& a, const P2& b, const P2& c) {
  thread_local mpz_class A[3], B[3], C[3];
  homogeneous(a, A);
  homogeneous(b, B);
  homogeneous(c, C);
  return orient_sign_homogeneous(A, B, C);
}

std::vector<D2> approx(const std::vector<P2>& polygon) {
  std::vector<D2> out;
  out.reserve(polygon.size());
  for (const P2& p : polygon) out.push_back(approx(p));
  return out;
}

int orient_sign(const P2& a, const P2& b, const P2& c, const D2& da, const D2& db, const D2& dc) {
  if (a == b || b == c || a == c) return 0;  // common in shared-vertex tests; saves the exact fallback
  const double m = std::max({std::abs(da.u), std::abs(da.v), std::abs(db.u), std::abs(db.v), std::abs(dc.u),
                             std::abs(dc.v)});
  if (int s = filtered_cross_sign(db.u - da.u, db.v - da.v, dc.u - da.u, dc.v - da.v, 2 * m)) return s;
  return orient_sign_exact(a, b, c);
}

int orient_sign(const P2& a, const P2& b, const P2& c) {
  if (a == b || b == c || a == c) return 0;
  return orient_sign(a, b, c, approx(a), approx(b), approx(c));
}

std::vector<P2> convex_hull(std::vector<P2> pts) {
  std::sort(pts.begin(), pts.end());
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  if (pts.size() < 3) return {};
  const std::vector<D2> d = approx(pts);
  std::vector<std::size_t> hull(2 * pts.size());  // indices into pts
  std::size_t k = 0;
  auto turns_left = [&](std::size_t i) {
    const std::size_t a = hull[k - 2], b = hull[k - 1];
    return orient_sign(pts[a], pts[b], pts[i], d[a], d[b], d[i]) > 0;
  };
  for (std::size_t i = 0; i < pts.size(); ++i) {
    while (k >= 2 && !turns_left(i)) --k;
    hull[k++] = i;
  }
  for (std::size_t i = pts.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && !turns_left(i)) --k;
    hull[k++] = i;
  }
  if (k - 1 < 3) return {};
  std::vector<P2> out;
  out.reserve(k - 1);
  for (std::size_t i = 0; i + 1 < k; ++i) out.push_back(pts[hull[i]]);
  return out;
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
bool has_separating_edge(const std::vector<P2>& a, const std::vector<D2>& da, const std::vector<P2>& b,
                         const std::vector<D2>& db) {
  const std::size_t n = a.size();
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t j = (i + 1) % n;
    if (a[i] == a[j]) continue;
    bool all_right = true;
    for (std::size_t r = 0; r < b.size(); ++r)
      if (orient_sign(a[i], a[j], b[r], da[i], da[j], db[r]) > 0) { all_right = false; break; }
    if (all_right) return true;
  }
  return false;
}

// A convex CCW loop (collinear vertices allowed) has positive area iff it has a strictly convex corner.
bool has_positive_corner(const std::vector<P2>& poly, const std::vector<D2>& d) {
  const std::size_t n = poly.size();
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t j = (i + 1) % n, k = (i + 2) % n;
    if (orient_sign(poly[i], poly[j], poly[k], d[i], d[j], d[k]) > 0) return true;
  }
  return false;
}
}  // namespace

bool interiors_overlap(const std::vector<P2>& a, const std::vector<P2>& b) {
  if (a.size() < 3 || b.size() < 3) return false;
  return interiors_overlap(a, approx(a), b, approx(b));
}

bool interiors_overlap(const std::vector<P2>& a, const std::vector<D2>& da, const std::vector<P2>& b,
                       const std::vector<D2>& db) {
  if (a.size() < 3 || b.size() < 3) return false;
  if (!has_positive_corner(a, da) || !has_positive_corner(b, db)) return false;
  return !has_separating_edge(a, da, b, db) && !has_separating_edge(b, db, a, da);
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

namespace {
// The pivot of sort_ccw, c = (a + b + d) / 3 for three non-collinear points, without reducing any fraction (the
// gcds of a canonical c were most of sort_ccw's time): its double image for the filters, and homogeneous integer
// coordinates (U, V, W), W > 0, made only when a filter cannot decide.
class Pivot {
 public:
  Pivot(const P2& a, const P2& b, const P2& d, const D2& da, const D2& db, const D2& dd) : points_{&a, &b, &d} {
    approx_ = {(da.u + db.u + dd.u) / 3, (da.v + db.v + dd.v) / 3};
    magnitude_ = std::max({std::abs(da.u), std::abs(da.v), std::abs(db.u), std::abs(db.v), std::abs(dd.u),
                           std::abs(dd.v)});
  }
  const D2& approx() const { return approx_; }
  /// The largest |double coordinate| of the three points: |c| <= it, and it bounds the error of approx().
  double magnitude() const { return magnitude_; }
  const mpz_class (&homogeneous())[3] {
    if (!made_) make();
    return h_;
  }

 private:
  void make() {
    mpz_class p[3][3];
    for (int k = 0; k < 3; ++k) partition_internal::homogeneous(*points_[k], p[k]);
    // (P0 / W0 + P1 / W1 + P2 / W2) / 3 = (P0 W1 W2 + P1 W0 W2 + P2 W0 W1) / (3 W0 W1 W2).
    const mpz_class w12 = p[1][2] * p[2][2], w02 = p[0][2] * p[2][2], w01 = p[0][2] * p[1][2];
    for (int c = 0; c < 2; ++c) h_[c] = p[0][c] * w12 + p[1][c] * w02 + p[2][c] * w01;
    h_[2] = 3 * p[0][2] * w12;
    made_ = true;
  }
  const P2* points_[3];
  D2 approx_;
  double magnitude_ = 0;
  bool made_ = false;
  mpz_class h_[3];
};

// The double image of the pivot: each point's image is within a relative 2^-52 of it (or 2^-1074 absolute), and the
// two sums and the division add three roundings, so |approx - c| < 2e-15 M + 1e-300, M = Pivot::magnitude().

// Sign of p.v - c.v, or when 0 of p.u - c.u (p's half-plane around the pivot): doubles first, the exact
// comparison when the difference is within 1e-12 of the magnitudes (far above the errors: 2^-52 |p| for p's image,
// 2e-15 M for the pivot's).
int half_of(const P2& p, const D2& dp, Pivot& c) {
  auto filtered = [&](double x, double cx) {
    if (!filters_on()) return 0;
    const double bound = 1e-12 * std::max(std::abs(x), c.magnitude()) + 1e-300;
    const double diff = x - cx;  // one more rounding, relative 2^-53
    if (!std::isfinite(diff) || !(bound < std::numeric_limits<double>::infinity())) return 0;
    return diff > bound ? 1 : diff < -bound ? -1 : 0;
  };
  auto exact = [&](const Rational& q, int coordinate) {  // sign(q - C_k / W) = sign(qn W - C_k qd)
    const mpz_class (&h)[3] = c.homogeneous();
    thread_local mpz_class s;
    mpz_mul(s.get_mpz_t(), q.get_num_mpz_t(), h[2].get_mpz_t());
    mpz_submul(s.get_mpz_t(), h[coordinate].get_mpz_t(), q.get_den_mpz_t());
    return sgn(s);
  };
  int sv = filtered(dp.v, c.approx().v);
  if (sv == 0) sv = exact(p.v, 1);
  if (sv != 0) return sv > 0 ? 0 : 1;
  int su = filtered(dp.u, c.approx().u);
  if (su == 0) su = exact(p.u, 0);
  return su > 0 ? 0 : 1;
}

// Sign of orient(c, a, b) about the pivot: the cross-product filter (its bound 1e-12 m^2 is far above the pivot's
// extra error, < 2e-15 M per coordinate, as m >= 2M), then the homogeneous determinant.
int orient_about(Pivot& c, const P2& a, const P2& b, const D2& da, const D2& db) {
  const D2& dc = c.approx();
  const double m = std::max({std::abs(da.u), std::abs(da.v), std::abs(db.u), std::abs(db.v), std::abs(dc.u),
                             std::abs(dc.v), c.magnitude()});
  if (int s = filtered_cross_sign(da.u - dc.u, da.v - dc.v, db.u - dc.u, db.v - dc.v, 2 * m)) return s;
  mpz_class A[3], B[3];
  homogeneous(a, A);
  homogeneous(b, B);
  return orient_sign_homogeneous(c.homogeneous(), A, B);
}
}  // namespace

std::vector<int> sort_ccw(const std::vector<P2>& pts) {
  const int n = static_cast<int>(pts.size());
  const std::vector<D2> d = approx(pts);
  // Pivot: centroid of three non-collinear points, strictly inside the convex polygon.
  int third = -1;
  for (int k = 2; k < n && third < 0; ++k)
    if (orient_sign(pts[0], pts[1], pts[k], d[0], d[1], d[k]) != 0) third = k;
  HSR_ASSERT(third > 0, "sort_ccw: collinear points");
  Pivot c(pts[0], pts[1], pts[third], d[0], d[1], d[third]);
  // Half 0: the directions from c with angle in [0, pi) (v > 0, or v = 0 and u > 0); then by orientation.
  std::vector<int> half(n);
  for (int i = 0; i < n; ++i) half[i] = half_of(pts[i], d[i], c);
  std::vector<int> idx(n);
  for (int i = 0; i < n; ++i) idx[i] = i;
  std::sort(idx.begin(), idx.end(), [&](int a, int b) {
    if (half[a] != half[b]) return half[a] < half[b];
    return orient_about(c, pts[a], pts[b], d[a], d[b]) > 0;
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
