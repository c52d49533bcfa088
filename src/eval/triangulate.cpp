// Triangulation of polygon faces (eval.h): ear clipping with exact orientation predicates.
//
// Why not CGAL's PMP::triangulate_faces: it inserts the face into a constrained Delaunay triangulation
// with Projection_traits_3 on Epick, whose predicates project along a double normal inexactly. On a face
// whose two boundary parts come closer than the coordinates' rounding (a thin piece of a coplanar region
// split around a hole, exactly simple on the partition's rationals), the triangulation's predicates
// disagree with each other and insert_constraint walks off the triangulation (SIGSEGV with assertions
// off). Here the face is projected by dropping a coordinate (exact, no arithmetic) and every orientation
// is CGAL's filtered exact orientation of the projected doubles, so the clipping is exact for the face as
// written: a face whose projection is simple always yields loop.size() - 2 positive triangles, and any
// other face ends after at most loop.size()^2 ear tests with a fan and `false`.
#include "eval/eval.h"

#include "core/face_class.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

namespace hsr {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using P2 = K::Point_2;

/// The loop projected along coordinate `axis`, mirrored when `flip` < 0 (exact: no arithmetic but negation).
std::vector<P2> project_loop(const std::vector<Vec3>& loop, int axis, double flip) {
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;
  std::vector<P2> out;
  out.reserve(loop.size());
  for (const Vec3& p : loop) out.emplace_back(p[u], flip * p[v]);
  return out;
}

/// Ear clipping on a circular list. An ear is a strictly convex corner b (neighbours a, c) whose closed
/// triangle holds no other vertex of the remaining polygon; for a simple polygon one always exists and
/// clipping it leaves a simple polygon of positive area (two-ears theorem), so only non-simple or
/// zero-area input can run out of ears.
/// Robust ears first: a face written from exact rational vertices has corners that were exactly collinear
/// or exactly on a diagonal before rounding; an ear through such a corner is a sliver that the rounding
/// pushes slightly out of the face (and then through its neighbour: a false self-intersection). So an
/// ear is taken only when its corner is clearly convex and no other vertex lies within a tolerance of its
/// triangle; only when no such ear is left does the exact test alone decide.
class EarClipper {
 public:
  explicit EarClipper(std::vector<P2> pts) : p_(std::move(pts)), prev_(p_.size()), next_(p_.size()) {
    const std::size_t n = p_.size();
    double lo_x = INFINITY, hi_x = -INFINITY, lo_y = INFINITY, hi_y = -INFINITY;
    for (std::size_t i = 0; i < n; ++i) {
      prev_[i] = static_cast<std::uint32_t>((i + n - 1) % n);
      next_[i] = static_cast<std::uint32_t>((i + 1) % n);
      lo_x = std::min(lo_x, p_[i].x());
      hi_x = std::max(hi_x, p_[i].x());
      lo_y = std::min(lo_y, p_[i].y());
      hi_y = std::max(hi_y, p_[i].y());
    }
    left_ = n;
    tolerance_ = 1e-10 * std::hypot(hi_x - lo_x, hi_y - lo_y);  // far above rounding, far below features
  }

  bool run(std::vector<std::array<std::uint32_t, 3>>& out) {
    std::uint32_t b = 0;
    while (left_ > 3) {
      std::uint32_t ear = 0;
      if (!find_ear(b, true, ear) && !find_ear(b, false, ear)) {  // not simple, or zero area
        fan_rest(b, out);
        return false;
      }
      out.push_back({prev_[ear], ear, next_[ear]});
      const std::uint32_t c = next_[ear];
      remove(ear);
      b = prev_[c];  // its corner changed: test it again first
    }
    const std::uint32_t a = prev_[b], c = next_[b];
    out.push_back({a, b, c});
    return CGAL::orientation(p_[a], p_[b], p_[c]) == CGAL::LEFT_TURN;
  }

 private:
  bool find_ear(std::uint32_t start, bool robust, std::uint32_t& ear) const {
    std::uint32_t b = start;
    for (std::size_t k = 0; k < left_; ++k, b = next_[b])
      if (is_ear(b, robust)) {
        ear = b;
        return true;
      }
    return false;
  }

  /// Distance from q to the segment [a, b] (doubles: only used against the tolerance).
  static double distance_to_segment(const P2& q, const P2& a, const P2& b) {
    const double ux = b.x() - a.x(), uy = b.y() - a.y(), wx = q.x() - a.x(), wy = q.y() - a.y();
    const double len2 = ux * ux + uy * uy;
    const double t = len2 > 0 ? std::clamp((wx * ux + wy * uy) / len2, 0.0, 1.0) : 0.0;
    return std::hypot(wx - t * ux, wy - t * uy);
  }

  bool is_ear(std::uint32_t b, bool robust) const {
    const std::uint32_t a = prev_[b], c = next_[b];
    const P2 &pa = p_[a], &pb = p_[b], &pc = p_[c];
    if (CGAL::orientation(pa, pb, pc) != CGAL::LEFT_TURN) return false;
    const double margin = robust ? tolerance_ : 0.0;
    if (robust) {  // clearly convex: the corner's distance to the line a c above the tolerance
      const double ux = pc.x() - pa.x(), uy = pc.y() - pa.y();
      const double twice_area = (pb.x() - pa.x()) * uy - (pb.y() - pa.y()) * ux;
      if (twice_area <= margin * std::hypot(ux, uy)) return false;
    }
    const double lo_x = std::min({pa.x(), pb.x(), pc.x()}) - margin, hi_x = std::max({pa.x(), pb.x(), pc.x()}) + margin;
    const double lo_y = std::min({pa.y(), pb.y(), pc.y()}) - margin, hi_y = std::max({pa.y(), pb.y(), pc.y()}) + margin;
    for (std::uint32_t j = next_[c]; j != a; j = next_[j]) {
      const P2& q = p_[j];
      if (q.x() < lo_x || q.x() > hi_x || q.y() < lo_y || q.y() > hi_y) continue;  // bbox filter
      if (CGAL::orientation(pa, pb, q) != CGAL::RIGHT_TURN && CGAL::orientation(pb, pc, q) != CGAL::RIGHT_TURN &&
          CGAL::orientation(pc, pa, q) != CGAL::RIGHT_TURN)
        return false;  // in the closed triangle
      if (robust && (distance_to_segment(q, pa, pb) <= margin || distance_to_segment(q, pb, pc) <= margin ||
                     distance_to_segment(q, pc, pa) <= margin))
        return false;  // next to it
    }
    return true;
  }
  void remove(std::uint32_t b) {
    next_[prev_[b]] = next_[b];
    prev_[next_[b]] = prev_[b];
    --left_;
  }
  /// Fan over what is left, from `first` (each triangle clips its middle corner, as ears do).
  void fan_rest(std::uint32_t first, std::vector<std::array<std::uint32_t, 3>>& out) {
    while (left_ >= 3) {
      const std::uint32_t b = next_[first];
      out.push_back({first, b, next_[b]});
      if (left_ == 3) break;
      remove(b);
    }
  }

  std::vector<P2> p_;
  std::vector<std::uint32_t> prev_, next_;
  std::size_t left_ = 0;
  double tolerance_ = 0;
};

}  // namespace

bool triangulate_polygon(const std::vector<Vec3>& loop, std::vector<std::array<std::uint32_t, 3>>& triangles) {
  triangles.clear();
  if (loop.size() < 3) return false;
  // Newell's vector about the first corner, so that its rounding follows the face's size, not its position.
  std::vector<Vec3> local;
  local.reserve(loop.size());
  for (const Vec3& p : loop) local.push_back(p - loop[0]);
  std::vector<std::uint32_t> order(loop.size());
  std::iota(order.begin(), order.end(), 0u);
  const Vec3 normal = newell_vector(local, order);
  if (!(normal.squaredNorm() > 0) || !normal.allFinite()) return false;
  // The dominant axis first, counter-clockwise as the normal says. A face only a few ulps wide has a
  // normal made of rounding: then the other projections (and orientations) are tried, and the face is
  // simple if one of them is (the wrong orientation always runs out of ears: its area stays negative).
  std::array<int, 3> axes = {0, 1, 2};
  std::sort(axes.begin(), axes.end(), [&](int a, int b) { return std::abs(normal[a]) > std::abs(normal[b]); });
  std::vector<std::array<std::uint32_t, 3>> first;
  for (int axis : axes)
    for (const double flip : {normal[axis] < 0 ? -1.0 : 1.0, normal[axis] < 0 ? 1.0 : -1.0}) {
      triangles.clear();
      triangles.reserve(loop.size() - 2);
      if (EarClipper(project_loop(loop, axis, flip)).run(triangles)) return true;
      if (first.empty()) first = triangles;
    }
  triangles = std::move(first);
  return false;
}

std::vector<std::array<std::uint32_t, 3>> triangulate_faces(const PolygonMesh& mesh) {
  std::vector<std::array<std::uint32_t, 3>> out, tris;
  std::vector<Vec3> loop;
  for (const auto& f : mesh.faces) {
    loop.clear();
    for (std::uint32_t v : f) loop.push_back(mesh.vertices[v]);
    triangulate_polygon(loop, tris);
    for (const auto& t : tris) out.push_back({f[t[0]], f[t[1]], f[t[2]]});
  }
  return out;
}

}  // namespace hsr
