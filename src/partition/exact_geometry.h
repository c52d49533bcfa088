// The partition's exact geometry (GMP rationals), a public header of src/partition: the partitioners and
// validate() use all of it; other stages may use it to decide on the complex's exact vertices as the partition
// does. src/extraction does (surface.cpp, simple_polygons.cpp: straight vertices and the proof that output
// polygons are simple, DECISIONS #29) with P2, PlaneFrame / frame_of / to_2d, orient_sign and IntPlane /
// int_plane / side_exact. The namespace keeps its name, partition_internal, so the partition's code is unchanged.
// No CGAL: every predicate is a sign of a rational polynomial, evaluated exactly: by a double filter
// with a proven error bound when it decides, else on integers without any gcd (see "gcd-free exact arithmetic").
//
// Plane frames. A point of a plane is described in 2D by two of its 3D coordinates: the axis with the
// largest |normal component| is dropped (ties -> lowest axis) and the two others are kept, swapped when
// needed so that counter-clockwise in 2D means counter-clockwise seen from the plane's positive side.
// Projecting and lifting are exact and affine, so 2D orientation, interpolation and (scaled) area are
// exact images of the 3D ones.
#pragma once

#include "partition/cell_complex.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>
#include <vector>

namespace hsr::partition_internal {

struct P2 {
  Rational u, v;
  bool operator==(const P2& o) const { return u == o.u && v == o.v; }
  bool operator<(const P2& o) const { return u < o.u || (u == o.u && v < o.v); }
};

/// The double images (mpq_get_d) of a 2D point, computed once per polygon for the orientation filter.
struct D2 {
  double u = 0, v = 0;
};
inline D2 approx(const P2& p) { return {p.u.get_d(), p.v.get_d()}; }
std::vector<D2> approx(const std::vector<P2>& polygon);

struct ExactPointLess {
  bool operator()(const ExactPoint& a, const ExactPoint& b) const {
    int c = cmp(a.x, b.x);
    if (c != 0) return c < 0;
    c = cmp(a.y, b.y);
    if (c != 0) return c < 0;
    return cmp(a.z, b.z) < 0;
  }
};

/// Allocator of the partition's large hash tables (the edge map, the vertex index): blocks of 2 MiB and more are
/// 2 MiB-aligned and advised to transparent huge pages. Their lookups are random over up to a few hundred MB, and
/// with 4 KiB pages nearly each one missed the TLB as well as the cache (1,000 dense rectangles: cells step -20 %
/// with huge pages). Only where the kernel allows it (THP "madvise" or "always"); nothing else changes.
void* allocate_table(std::size_t bytes);
void free_table(void* p, std::size_t bytes) noexcept;
template <class T>
struct TableAllocator {
  using value_type = T;
  TableAllocator() = default;
  template <class U>
  TableAllocator(const TableAllocator<U>&) {}
  T* allocate(std::size_t n) { return static_cast<T*>(allocate_table(n * sizeof(T))); }
  void deallocate(T* p, std::size_t n) noexcept { free_table(p, n * sizeof(T)); }
  template <class U>
  bool operator==(const TableAllocator<U>&) const { return true; }
  template <class U>
  bool operator!=(const TableAllocator<U>&) const { return false; }
};

/// Hash of an exact point (its canonical limbs), for unordered containers keyed by exact value.
struct ExactPointHash {
  std::size_t operator()(const ExactPoint& p) const;
};

/// Ids of exact points kept by the caller (points[id]), looked up by value through their hash: the points are not
/// copied into the index. Open addressing with linear probing over (hash, id) pairs, 16 bytes a slot (a node-based
/// multimap cost a cache miss per node and was a tenth of a large partition's cell construction).
class ExactPointIndex {
 public:
  /// The id of the point equal to p, or -1 (Points: a random-access container of ExactPoint).
  template <class Points>
  std::int64_t find(const ExactPoint& p, std::size_t hash, const Points& points) const {
    if (slots_.empty()) return -1;
    const std::size_t mask = slots_.size() - 1;
    for (std::size_t i = home(hash); slots_[i].id != kEmpty; i = (i + 1) & mask)
      if (slots_[i].hash == hash && points[slots_[i].id] == p) return slots_[i].id;
    return -1;
  }
  /// Records a new id (its point not yet indexed).
  void insert(std::size_t hash, std::uint32_t id) {
    if (2 * (used_ + 1) > slots_.size()) grow();
    place(hash, id);
  }

 private:
  static constexpr std::uint32_t kEmpty = ~std::uint32_t{0};
  struct Slot {
    std::uint64_t hash = 0;
    std::uint32_t id = kEmpty;
  };
  std::size_t home(std::uint64_t hash) const {  // splitmix64 finaliser: ExactPointHash's low bits are weak
    std::uint64_t z = hash + 0x9e3779b97f4a7c15ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return static_cast<std::size_t>(z ^ (z >> 31)) & (slots_.size() - 1);
  }
  void place(std::uint64_t hash, std::uint32_t id) {
    std::size_t i = home(hash);
    while (slots_[i].id != kEmpty) i = (i + 1) & (slots_.size() - 1);
    slots_[i] = {hash, id};
    ++used_;
  }
  void grow() {
    std::vector<Slot, TableAllocator<Slot>> old = std::move(slots_);
    slots_.assign(old.empty() ? 256 : 2 * old.size(), Slot{});
    used_ = 0;
    for (const Slot& s : old)
      if (s.id != kEmpty) place(s.hash, s.id);
  }
  std::vector<Slot, TableAllocator<Slot>> slots_;
  std::size_t used_ = 0;
};

// ------------------------------------------------------------------------------------------- filters
// Every decision of the partition is the sign of an exact rational expression. Two kinds of double filters
// decide most of them first; each is provably conservative (it answers only when the exact sign is certain,
// and says "undecided" otherwise, so the caller evaluates exactly):
//  * a static error bound for short sums of products of *trusted* doubles (filtered_sign), the hot path;
//  * interval arithmetic (Interval) for longer chains (quotients, maxima), where a static bound is awkward.

/// The filters' switch (issue 25): off, every filter below answers "undecided" (trusted_double false, Interval::of
/// the whole line, filtered_sign 0, the builder's and the growth's double tests "may"), so every decision comes
/// from the exact evaluation. On by default; tests turn it off to compare (process-wide: not while partitioning).
void set_filters(bool on);
bool filters_on();

/// A double image d = q.get_d() of a rational q (or mpz_get_d(z) of an integer z) that a static filter may use: d
/// is a normal double, or d is 0 and q is exactly 0. (mpq_get_d and mpz_get_d truncate, so a normal d is within a
/// relative 2^-52 of q; a subnormal or zero image of a non-zero q, or an infinite one, has no relative error bound.)
inline bool trusted_double(const Rational& q, double d) {
  return filters_on() && (d == 0 ? sgn(q) == 0 : std::isnormal(d));
}
inline bool trusted_double(const mpz_class& z, double d) {
  return filters_on() && (d == 0 ? sgn(z) == 0 : std::isnormal(d));
}

/// Sign of an exact sum S = sum of at most 8 terms, each a product of at most three exact factors, from its
/// double evaluation `value` (every factor replaced by a trusted image, products and sums rounded to nearest,
/// in any order) and `magnitude` = the sum of the absolute values of the computed terms. +1 / -1 when certain,
/// 0 when undecided.
/// Proof: each trusted factor carries a relative error below 2^-52, each product or sum one rounding of at most
/// 2^-53 relative, and an underflowing product an absolute error below 2^-1074; so |value - S| <=
/// (3 * 2^-52 + 10 * 2^-53) * magnitude * (1 + 1e-15) + 8 * 2^-1074 < 1e-14 * magnitude + 1e-320. The threshold
/// 1e-12 * magnitude + 1e-300 is above that by orders of magnitude, and an overflow (infinite or NaN value or
/// magnitude) is undecided.
inline int filtered_sign(double value, double magnitude) {
  if (!filters_on()) return 0;
  const double bound = 1e-12 * magnitude + 1e-300;
  if (!(bound < std::numeric_limits<double>::infinity()) || !std::isfinite(value)) return 0;
  if (value > bound) return 1;
  if (value < -bound) return -1;
  return 0;
}

/// A closed interval [lo, hi] of doubles that contains an exact value, kept so by widening every rounded
/// result by one ulp outward (round-to-nearest puts the exact result of one operation within half an ulp of
/// the computed one). An operation that cannot be bounded (inf - inf, 0 * inf, a divisor containing 0) gives
/// the whole line, so every answer derived from an Interval is conservative.
struct Interval {
  double lo = -std::numeric_limits<double>::infinity(), hi = std::numeric_limits<double>::infinity();

  static Interval whole() { return {}; }
  /// Contains q: mpq_get_d truncates towards zero (q lies between d and the next double away from 0; an
  /// overflowing q gives an infinite d, an underflowing one 0).
  static Interval of(const Rational& q) {
    if (!filters_on()) return whole();
    const double d = q.get_d();
    return make(d, d);
  }
  static Interval of(const mpz_class& z) {  // mpz_get_d truncates too
    if (!filters_on()) return whole();
    const double d = z.get_d();
    return make(d, d);
  }
  /// [lo, hi] widened outward by at least one ulp: |x| 2^-52 >= ulp(x) (exact scaling), the smallest subnormal
  /// covers the subnormal range, and the rounded difference x - (|x| 2^-52 + 2^-1074) is at most the double below
  /// x (rounding is monotone). An infinite bound on the wrong side becomes NaN: the whole line.
  static Interval make(double lo, double hi) {
    constexpr double ulp = 0x1p-52, tiny = 0x1p-1074;
    Interval r;
    r.lo = lo - (std::abs(lo) * ulp + tiny);
    r.hi = hi + (std::abs(hi) * ulp + tiny);
    if (!(r.lo <= r.hi)) return whole();  // a NaN bound
    return r;
  }
  /// +1 / -1 when every value of the interval has that sign, 0 otherwise.
  int sign() const { return lo > 0 ? 1 : hi < 0 ? -1 : 0; }
};
inline Interval operator+(const Interval& a, const Interval& b) { return Interval::make(a.lo + b.lo, a.hi + b.hi); }
inline Interval operator-(const Interval& a, const Interval& b) { return Interval::make(a.lo - b.hi, a.hi - b.lo); }
/// The interval spanned by the four corner products (or quotients) of a * b (a / b); NaN: everything.
inline Interval span_of_corners(const double (&p)[4]) {
  double lo = p[0], hi = p[0];
  for (double x : p) {
    if (std::isnan(x)) return Interval::whole();
    lo = std::min(lo, x);
    hi = std::max(hi, x);
  }
  return Interval::make(lo, hi);
}
inline Interval operator*(const Interval& a, const Interval& b) {
  const double p[4] = {a.lo * b.lo, a.lo * b.hi, a.hi * b.lo, a.hi * b.hi};
  return span_of_corners(p);
}
inline Interval operator/(const Interval& a, const Interval& b) {
  if (!(b.lo > 0 || b.hi < 0)) return Interval::whole();
  const double p[4] = {a.lo / b.lo, a.lo / b.hi, a.hi / b.lo, a.hi / b.hi};
  return span_of_corners(p);
}
/// The interval of max(x, y) for x in a, y in b.
inline Interval max(const Interval& a, const Interval& b) { return {std::max(a.lo, b.lo), std::max(a.hi, b.hi)}; }

/// Exact plane of a double plane, canonical: the first non-zero of (a, b, c) is exactly 1, so two
/// coplanar planes (whatever their orientation) have identical coefficients. Throws BadInput on a zero
/// or non-finite normal.
ExactPlane canonical_plane(const Plane& plane);
/// Divides by the first non-zero normal coefficient (must exist).
void canonicalize(ExactPlane& plane);
bool same_plane(const ExactPlane& a, const ExactPlane& b);
/// Strict weak order on canonical planes (for maps).
bool plane_less(const ExactPlane& a, const ExactPlane& b);

Rational evaluate(const ExactPlane& plane, const ExactPoint& p);
int side(const ExactPlane& plane, const ExactPoint& p);  ///< -1, 0, +1 (exact, filtered_sign first)

// ------------------------------------------------------------------------------ gcd-free exact arithmetic
// A GMP rational operation ends with a gcd to keep its result canonical, and the partition's profile was
// mostly gcd (issue 25: 45 % of the instructions of 500 random rectangles). Signs need no canonical value:
// they are evaluated on integers, over positive common denominators, without any gcd. Constructions build
// each result coordinate as one fraction of integers and canonicalise it once.

/// A positive integer multiple of an exact plane (times the lcm of its denominators): the same plane, the same
/// sides, small integers (a canonical plane read from doubles has power-of-two denominators times its lead).
struct IntPlane {
  mpz_class a, b, c, d;
};
IntPlane int_plane(const ExactPlane& plane);
/// Exact side of `p` (-1, 0, +1), no gcd: the plane's value times the positive product of p's denominators.
int side_exact(const IntPlane& plane, const ExactPoint& p);
/// The common point of three planes, by Cramer's rule on their integer coefficients (one canonicalisation per
/// coordinate); false when their normals are linearly dependent.
bool meet_planes(const IntPlane& p, const IntPlane& q, const IntPlane& r, ExactPoint& out);
/// Homogeneous integer coordinates (U, V, W) of a 2D point, W > 0: (un vd, vn ud, ud vd), or (un, vn, w) when both
/// coordinates have the denominator w.
void homogeneous(const P2& p, mpz_class (&out)[3]);
/// Sign of a u + b v + c at (u, v) for integers a, b, c (no gcd).
int sign_at(const mpz_class& a, const mpz_class& b, const mpz_class& c, const Rational& u, const Rational& v);

/// How points of one plane are mapped to 2D (see the header comment).
struct PlaneFrame {
  int drop = 2;       ///< dropped axis
  bool swap = false;  ///< (u, v) = (second kept, first kept) instead of (first kept, second kept)
};
PlaneFrame frame_of(const ExactPlane& plane);
/// The same point's image in `frame` (to_2d of the point), without canonicalising the dropped coordinate.
bool meet_planes(const IntPlane& p, const IntPlane& q, const IntPlane& r, const PlaneFrame& frame, P2& out);
P2 to_2d(const PlaneFrame& frame, const ExactPoint& p);
/// The same for a double point (to_2d of to_double(p) is approx(to_2d(p))).
D2 to_2d(const PlaneFrame& frame, const Vec3& p);
/// The point of `plane` whose 2D image is `q`.
ExactPoint lift(const ExactPlane& plane, const PlaneFrame& frame, const P2& q);
/// The same point from the plane's integer coefficients (one canonicalisation).
ExactPoint lift(const IntPlane& plane, const PlaneFrame& frame, const P2& q);
/// Factor from 2D area to 3D area: |n| / |n_drop| (double, for ordering only).
double area_scale(const ExactPlane& plane, const PlaneFrame& frame);

/// Point of segment pq on `plane` (p and q strictly on opposite sides): homogeneous integer coordinates, one
/// canonicalisation per coordinate.
ExactPoint intersect_segment(const IntPlane& plane, const ExactPoint& p, const ExactPoint& q);


Rational orient(const P2& a, const P2& b, const P2& c);  ///< twice the signed area of abc
/// Exact sign of orient(a, b, c); a double evaluation with a rigorous error bound decides most cases,
/// the rational one the rest.
int orient_sign(const P2& a, const P2& b, const P2& c);
/// The same, with the points' double images given (da = approx(a) ...).
int orient_sign(const P2& a, const P2& b, const P2& c, const D2& da, const D2& db, const D2& dc);
/// The same sign from the exact evaluation alone (integers, no gcd).
int orient_sign_exact(const P2& a, const P2& b, const P2& c);
/// The same from homogeneous integer coordinates (homogeneous(), W > 0).
int orient_sign_homogeneous(const mpz_class (&a)[3], const mpz_class (&b)[3], const mpz_class (&c)[3]);
/// Convex hull, counter-clockwise, no duplicate or collinear vertices (empty if < 3 non-collinear points).
std::vector<P2> convex_hull(std::vector<P2> points);
/// Twice the signed area (shoelace).
Rational twice_area(const std::vector<P2>& polygon);
/// Two convex CCW polygons (collinear vertices allowed) have interiors that intersect (positive-area overlap).
bool interiors_overlap(const std::vector<P2>& a, const std::vector<P2>& b);
/// The same with the polygons' double images (approx).
bool interiors_overlap(const std::vector<P2>& a, const std::vector<D2>& da, const std::vector<P2>& b,
                       const std::vector<D2>& db);
/// Intersection of convex CCW `subject` with convex CCW `clipper` (may be empty or degenerate).
std::vector<P2> clip_convex(const std::vector<P2>& subject, const std::vector<P2>& clipper);
/// Keeps the part of the 2D polygon (on `plane`) where `halfspace` >= 0 (sign * halfspace evaluation).
std::vector<P2> clip_by_halfspace(const std::vector<P2>& polygon, const ExactPlane& plane, const PlaneFrame& frame,
                                  const ExactPlane& halfspace, int keep_sign);
/// Indices of `points` sorted counter-clockwise around their centroid. The points must be in convex
/// position (all on the boundary of their convex hull, which has positive area).
std::vector<int> sort_ccw(const std::vector<P2>& points);

/// The input polygon on its support plane: 2D convex hull (in `frame` of `plane`) of its vertices'
/// kept coordinates, i.e. the vertices projected onto the exact plane along the dropped axis.
std::vector<P2> project_polygon(const ConvexPolygon& polygon, const ExactPlane& plane, const PlaneFrame& frame);
/// `polygon2d` (on `plane`) clipped to the box [lo, hi].
std::vector<P2> clip_to_box(const std::vector<P2>& polygon2d, const ExactPlane& plane, const PlaneFrame& frame,
                            const ExactPoint& lo, const ExactPoint& hi);

/// The plane x_axis = value (canonical).
ExactPlane axis_plane(int axis, const Rational& value);

Vec3 to_double(const ExactPoint& p);

}  // namespace hsr::partition_internal
