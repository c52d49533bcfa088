// Internal to src/partition: the arrangement locator of kinetic growth (kinetic_growth.h), one per growing
// polygon. On the polygon's support plane, the lines where the other polygons' planes cut it, clipped to the
// domain's section, form a 2D arrangement; the locator builds its faces lazily (only those a region reaches)
// and gives each an id. Exact: faces are exact convex polygons; every predicate is an exact sign, filtered
// first by filtered_sign (exact_geometry.h).
#pragma once

#include "partition/exact_geometry.h"

#include <array>
#include <cstdint>
#include <deque>
#include <map>
#include <unordered_map>
#include <utility>
#include <vector>

namespace hsr::partition_internal {

/// A line a u + b v + c = 0 of a plane's 2D frame with integer coefficients, no common factor (identical lines
/// from several planes are stored once, with every owner). Lines between planes have the first non-zero of
/// (a, b) positive; only ratios and signs of the coefficients mean anything.
struct Line {
  mpz_class a, b, c;
  double da = 0, db = 0, dc = 0, dnorm = 1;  ///< mpz_get_d images of a, b, c (truncated) and |(da, db)|
  bool trusted = false;     ///< da, db, dc are trusted_double images (filtered_sign may use them)
  std::vector<int> owners;  ///< indices of the polygons whose plane cuts this plane along the line
};

/// The line of plane `other` in the frame of `plane`, or false if the planes are parallel or the line
/// certainly misses the interior of the convex polygon `domain` (in the frame; decided with intervals, so
/// a line that meets it is never dropped; the caller still checks exactly). On `plane`,
/// x_drop = -(a_i x_i + a_j x_j + d) / a_drop, so other's equation restricted to it is affine in (u, v):
/// times a_drop, integer coefficients.
bool line_between(const IntPlane& plane, const PlaneFrame& frame, const IntPlane& other,
                  const std::vector<P2>& domain, Line& out);
/// The same with the domain's vertices as intervals (Interval::of of each coordinate), computed once by a
/// caller that asks for many lines.
bool line_between(const IntPlane& plane, const PlaneFrame& frame, const IntPlane& other,
                  const std::vector<std::array<Interval, 2>>& domain, Line& out);
/// The line through p and q (p != q), positive on the left of p -> q.
Line line_through(const P2& p, const P2& q);

/// A face vertex: exact point and its double image.
struct V2 {
  P2 p;
  double u = 0, v = 0;
  bool trusted = false;  ///< u, v are trusted_double images
};
V2 make_v2(P2 p);

/// Exact sign of the line at a vertex (filtered_sign first).
int line_sign(const Line& l, const V2& q);
int line_sign(const Line& l, const P2& p);

/// A convex face, CCW; edge i joins vs[i] and vs[i+1] and lies on line edge_line[i] (an index of
/// ArrangementLocator::line: the arrangement's lines first, then the domain's walls).
struct Face {
  std::vector<V2> vs;
  std::vector<int> edge_line;
};

/// The exact 3D points of the arrangements of one domain, each stored once with an id (the growers of a domain
/// key their edges by pairs of ids). Not thread-safe: one registry per domain, which grows on one thread.
class PointRegistry {
 public:
  std::uint32_t id(ExactPoint p) {
    const std::size_t h = ExactPointHash()(p);
    const std::int64_t found = index_.find(p, h, points_);
    if (found >= 0) return static_cast<std::uint32_t>(found);
    const auto id = static_cast<std::uint32_t>(points_.size());
    index_.insert(h, id);
    points_.push_back(std::move(p));
    return id;
  }
  const ExactPoint& point(std::uint32_t id) const { return points_[id]; }

 private:
  std::deque<ExactPoint> points_;  // (a deque: no copies when it grows)
  ExactPointIndex index_;
};

class ArrangementLocator {
 public:
  /// The arrangement of `planes[self]` inside `domain` (its section of the domain: convex CCW, positive
  /// area, in `frame`): lines of every other plane that crosses the domain's interior, then one wall line
  /// per domain edge (positive inside).
  ArrangementLocator(const IntPlane& plane, const PlaneFrame& frame, const std::vector<P2>& domain,
                     const std::vector<IntPlane>& planes, int self, PointRegistry& points);

  int num_lines() const { return num_lines_; }  ///< the arrangement's lines (ids 0 .. num_lines() - 1)
  bool is_wall(int line) const { return line >= num_lines_; }
  const Line& line(int id) const { return all_lines_[id]; }
  const std::vector<Line>& lines() const { return all_lines_; }  ///< the arrangement's lines, then the walls

  /// Id of the face containing point p, where a line through p is resolved by the side `tie(line)` (+1/-1)
  /// of a symbolic perturbation; `added` tells whether the face is new.
  template <class Tie>
  int locate(const P2& p, Tie&& tie, bool& added) {
    std::vector<int> keep(all_lines_.size(), 1);  // walls: the domain is on their positive side
    const V2 pv = make_v2(p);
    for (int l = 0; l < num_lines_; ++l) {
      int s = line_sign(all_lines_[l], pv);
      if (s == 0) s = tie(l);
      keep[l] = s;
    }
    return add(face_of(pv, keep), added);
  }
  /// Id of the face across edge `edge` of face `face` (the edge's line is not a wall).
  int beyond(int face, int edge, bool& added);

  const Face& face(int id) const { return faces_[id]; }
  /// The ids (in the domain's PointRegistry) of the face's vertices lifted to 3D, in face order.
  const std::vector<std::uint32_t>& face_points(int id) const { return faces3d_[id]; }
  int num_faces() const { return static_cast<int>(faces_.size()); }

 private:
  Face face_of(const V2& p, const std::vector<int>& keep);
  Face face_of_exact(const V2& p, const std::vector<int>& keep) const;
  int add(Face face, bool& added);

  IntPlane plane_;
  PlaneFrame frame_;
  std::vector<Line> all_lines_;  // arrangement lines, then walls
  int num_lines_ = 0;
  Face domain_;
  std::map<std::pair<int, int>, V2> crossings_;  // exact intersection of two lines (smaller id first)
  std::map<std::pair<int, int>, std::uint32_t> lifted_;  // its 3D point's registry id, once a face needed it
  std::vector<Face> faces_;
  std::vector<std::vector<std::uint32_t>> faces3d_;
  PointRegistry* points_;
  std::unordered_map<std::uint64_t, int> face_index_;  // (lines of the last, first and second edges) -> face
};

}  // namespace hsr::partition_internal
