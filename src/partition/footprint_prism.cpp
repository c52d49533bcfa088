// The footprint prism (footprint_prism.h): wall rectangles for the partition, the complex restricted to
// the cells inside, and the facade points that vote for the walls.
#include "partition/footprint_prism.h"

#include "core/error.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hsr {

namespace {

constexpr const char* kStage = "partition";

/// The vertical rectangle over the edge a -> b: corners in the order a low, b low, b high, a high; its
/// plane through the edge, normal to its left... either side serves (the partition normalises planes).
ConvexPolygon wall_rectangle(const Vec2& a, const Vec2& b, double z_lo, double z_hi, int id) {
  // One canonical direction per edge (lexicographically smaller end first): a wall shared by two buildings'
  // footprints, walked in opposite directions, gets the same double plane in both.
  const bool flip = b.x() < a.x() || (b.x() == a.x() && b.y() < a.y());
  const Vec2 p = flip ? b : a, q = flip ? a : b;
  const Vec2 d = (q - p).normalized();
  ConvexPolygon poly;
  poly.plane_id = id;
  poly.plane.normal = Vec3(d.y(), -d.x(), 0.0);
  poly.plane.offset = -(poly.plane.normal.x() * p.x() + poly.plane.normal.y() * p.y());
  poly.vertices = {{p.x(), p.y(), z_lo}, {q.x(), q.y(), z_lo}, {q.x(), q.y(), z_hi}, {p.x(), p.y(), z_hi}};
  poly.level = 1;
  poly.speed = 1.0;
  return poly;
}

/// The cell's distinct vertices' ids, sorted.
std::vector<std::uint32_t> cell_vertex_ids(const CellComplex& cx, const Cell& cell) {
  std::vector<std::uint32_t> ids;
  for (std::uint32_t f : cell.facets)
    for (std::uint32_t v : cx.facets[f].vertices) ids.push_back(v);
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  return ids;
}

/// Exact average of the cell's (distinct) vertices `ids`: strictly inside the convex cell.
void interior_point(const CellComplex& cx, const std::vector<std::uint32_t>& ids, Rational& x, Rational& y) {
  x = 0;
  y = 0;
  for (std::uint32_t v : ids) {
    x += cx.vertices[v].x;
    y += cx.vertices[v].y;
  }
  x /= static_cast<long>(ids.size());
  y /= static_cast<long>(ids.size());
}

/// How far, relative to 1 + the largest coordinate, the doubles' average of a cell's vertices must lie from every
/// footprint edge for its side to be the exact average's (cell_inside_footprint). The doubles' average is within
/// (n + 2) 2^-52 of the exact one relative to that scale (each vertex rounded once, n sums, one division), and the
/// even-odd test in doubles errs only within a few 2^-52 of an edge: 1e-9 is a million times both for any cell
/// of fewer than 10^6 vertices.
constexpr double kDoublesSideMargin = 1e-9;

/// Distance from p to the segment a-b, in doubles.
double distance_to_segment(const Vec2& p, const Vec2& a, const Vec2& b) {
  const Vec2 d = b - a;
  const double len2 = d.squaredNorm();
  const double t = len2 > 0 ? std::clamp((p - a).dot(d) / len2, 0.0, 1.0) : 0.0;
  return (p - (a + t * d)).norm();
}

/// Whether a cell of the complex lies inside the footprint (the prism's walls are planes of the complex, so a
/// cell is wholly inside or outside): decided at an interior point, in doubles where the doubles' average of its
/// vertices lies farther than kDoublesSideMargin from every edge (the exact average is then on the same side),
/// else at the exact average. Why: the exact average sums rationals of growing denominators, about 7 % of a
/// city building's run (issue 43); the same cells are kept.
bool cell_inside_footprint(const CellComplex& cx, const Cell& cell, const Footprint& footprint, double footprint_extent) {
  const std::vector<std::uint32_t> ids = cell_vertex_ids(cx, cell);
  Vec2 sum = Vec2::Zero();
  double extent = footprint_extent;
  for (std::uint32_t v : ids) {
    const Vec3& q = cx.vertices_approx[v];
    sum += q.head<2>();
    extent = std::max(extent, q.head<2>().cwiseAbs().maxCoeff());
  }
  const Vec2 p = sum / static_cast<double>(ids.size());
  const double margin = kDoublesSideMargin * (1.0 + extent);
  bool clear = std::isfinite(p.x()) && std::isfinite(p.y()) && ids.size() < 1000000;
  const auto edges_clear = [&](const std::vector<Vec2>& ring) {
    for (std::size_t i = 0, j = ring.size() - 1; i < ring.size() && clear; j = i++)
      clear = distance_to_segment(p, ring[j], ring[i]) > margin;
  };
  for (const FootprintPolygon& poly : footprint) {
    edges_clear(poly.outer);
    for (const auto& h : poly.holes) edges_clear(h);
  }
  if (clear) return inside_footprint(p.x(), p.y(), footprint);
  Rational x, y;
  interior_point(cx, ids, x, y);
  return inside_footprint(x, y, footprint);
}

/// Calls `edge(a, b)` for every edge a -> b of every ring (outer ring, then its holes, polygon by polygon),
/// zero-length edges skipped: the order of the walls' plane ids (footprint_wall_polygons, footprint_wall_points).
template <class EdgeFn>
void for_each_footprint_edge(const Footprint& footprint, EdgeFn&& edge) {
  const auto ring_edges = [&](const std::vector<Vec2>& ring) {
    for (std::size_t i = 0; i < ring.size(); ++i) {
      const Vec2& a = ring[i];
      const Vec2& b = ring[(i + 1) % ring.size()];
      if (a != b) edge(a, b);
    }
  };
  for (const FootprintPolygon& p : footprint) {
    ring_edges(p.outer);
    for (const auto& h : p.holes) ring_edges(h);
  }
}

/// The largest |x| or |y| of the footprint's rings.
double footprint_extent(const Footprint& footprint) {
  double extent = 0;
  for (const FootprintPolygon& p : footprint) {
    for (const Vec2& q : p.outer) extent = std::max(extent, q.cwiseAbs().maxCoeff());
    for (const auto& h : p.holes)
      for (const Vec2& q : h) extent = std::max(extent, q.cwiseAbs().maxCoeff());
  }
  return extent;
}

}  // namespace

std::vector<ConvexPolygon> footprint_wall_polygons(const Footprint& footprint, double z_lo, double z_hi, int first_id) {
  if (!(z_lo < z_hi) || !std::isfinite(z_lo) || !std::isfinite(z_hi))
    throw Error(Status::BadInput, kStage, "footprint walls: need a finite z range with z_lo < z_hi");
  check_footprint(footprint);
  const double same_offset = 1e-9 * (1.0 + footprint_extent(footprint));
  std::vector<ConvexPolygon> walls;
  for_each_footprint_edge(footprint, [&](const Vec2& a, const Vec2& b) {
    ConvexPolygon wall = wall_rectangle(a, b, z_lo, z_hi, first_id + static_cast<int>(walls.size()));
    // Edges on one line (collinear parts of an outline) share one plane, bit for bit: planes computed from
    // each edge's own corners differ by rounding, and the sliver between them (1e-9 wide) no grid can hold.
    for (const ConvexPolygon& w : walls)
      if (std::abs(w.plane.normal.dot(wall.plane.normal)) > 1.0 - 1e-12 &&
          std::abs(w.plane.signed_distance(wall.vertices[0])) < same_offset &&
          std::abs(w.plane.signed_distance(wall.vertices[1])) < same_offset) {
        wall.plane = w.plane;
        break;
      }
    walls.push_back(std::move(wall));
  });
  return walls;
}

CellComplex keep_cells_in_prism(const CellComplex& cx, const Footprint& footprint, std::size_t* removed) {
  std::vector<int> new_id(cx.cells.size(), -1);
  CellComplex out;
  out.vertices = cx.vertices;
  out.vertices_approx = cx.vertices_approx;
  out.planes = cx.planes;
  out.box_min = cx.box_min;
  out.box_max = cx.box_max;
  out.box = cx.box;
  out.exact_volumes = cx.exact_volumes;
  const double extent = footprint_extent(footprint);
  for (std::size_t c = 0; c < cx.cells.size(); ++c) {
    if (!cell_inside_footprint(cx, cx.cells[c], footprint, extent)) continue;
    new_id[c] = static_cast<int>(out.cells.size());
    out.cells.push_back(cx.cells[c]);
  }
  std::vector<std::int64_t> new_facet(cx.facets.size(), -1);
  for (std::size_t f = 0; f < cx.facets.size(); ++f) {
    Facet facet = cx.facets[f];
    for (int& c : facet.cells) c = c >= 0 ? new_id[static_cast<std::size_t>(c)] : -1;
    if (facet.cells[0] < 0 && facet.cells[1] < 0) continue;
    new_facet[f] = static_cast<std::int64_t>(out.facets.size());
    out.facets.push_back(std::move(facet));
  }
  for (Cell& cell : out.cells)
    for (std::uint32_t& f : cell.facets) {
      HSR_ASSERT(new_facet[f] >= 0, "a kept cell lost one of its facets");
      f = static_cast<std::uint32_t>(new_facet[f]);
    }
  if (removed) *removed = cx.cells.size() - out.cells.size();
  return out;
}

namespace {

/// Whether the vertical wall `w` stands for the footprint edge a -> b (walls_standing_for_footprint).
bool wall_stands_for_edge(const ConvexPolygon& w, const Vec2& a, const Vec2& b, const std::vector<Vec2>& points,
                          double max_offset, double cos_max_angle, double band, std::size_t min_points) {
  const double length = (b - a).norm();
  if (!(length > 0)) return false;
  const Vec2 along = (b - a) / length, normal(along.y(), -along.x());
  const Vec2 wall_normal = Vec2(w.plane.normal.x(), w.plane.normal.y()).normalized();
  if (std::abs(wall_normal.dot(normal)) < cos_max_angle) return false;
  // The wall's plan extent along the edge, and its vertices' offsets from the edge's line.
  double t_lo = std::numeric_limits<double>::infinity(), t_hi = -t_lo;
  for (const Vec3& v : w.vertices) {
    const Vec2 q = v.head<2>() - a;
    const double t = q.dot(along), off = q.dot(normal);
    if (std::abs(off) > max_offset || t < -max_offset || t > length + max_offset) return false;
    t_lo = std::min(t_lo, t);
    t_hi = std::max(t_hi, t);
  }
  // The strip over the wall's extent along the edge, between the wall's line (beyond its band) and the edge's:
  // a point there is on opposite sides of the two (their normals turned alike).
  const Vec3& n3 = w.plane.normal;
  const double n3_norm = Vec2(n3.x(), n3.y()).norm(), turn = wall_normal.dot(normal) > 0 ? 1.0 : -1.0;
  std::size_t held = 0;
  for (const Vec2& p : points) {
    const Vec2 q = p - a;
    const double t = q.dot(along);
    if (t < t_lo || t > t_hi) continue;
    const double to_wall = turn * (n3.x() * p.x() + n3.y() * p.y() + w.plane.offset) / n3_norm, to_edge = q.dot(normal);
    const bool between = (to_wall > band && to_edge < 0) || (to_wall < -band && to_edge > 0);
    if (between && ++held >= min_points) return false;
  }
  return true;
}

}  // namespace

std::vector<bool> walls_standing_for_footprint(const std::vector<ConvexPolygon>& polygons, const Footprint& footprint,
                                               const std::vector<Vec2>& points, double max_offset,
                                               double max_angle_deg, double band, std::size_t min_points) {
  std::vector<bool> standing(polygons.size(), false);
  if (!(max_offset > 0)) return standing;
  const double cos_max_angle = std::cos(max_angle_deg * M_PI / 180.0);
  auto for_each_edge = [&](auto&& f) {
    for (const FootprintPolygon& fp : footprint) {
      auto ring = [&](const std::vector<Vec2>& r) {
        for (std::size_t i = 0, j = r.size() - 1; i < r.size(); j = i++) f(r[j], r[i]);
      };
      ring(fp.outer);
      for (const auto& h : fp.holes) ring(h);
    }
  };
  for (std::size_t i = 0; i < polygons.size(); ++i) {
    const ConvexPolygon& w = polygons[i];
    if (w.plane.normal.z() != 0.0 || w.vertices.empty()) continue;
    for_each_edge([&](const Vec2& a, const Vec2& b) {
      if (!standing[i]) standing[i] = wall_stands_for_edge(w, a, b, points, max_offset, cos_max_angle, band, min_points);
    });
  }
  return standing;
}

std::size_t footprint_wall_points(const std::vector<Vec3>& points, const Footprint& footprint, int first_id,
                                  const std::vector<bool>& in_complex, double distance, double ground_z,
                                  std::vector<int>& point_plane, std::vector<Vec3>& normals) {
  struct Edge {
    Vec2 a, dir, out;
    double length;
    int id;
  };
  std::vector<Edge> edges;
  int id = first_id;
  for_each_footprint_edge(footprint, [&](const Vec2& a, const Vec2& b) {
    const double length = (b - a).norm();
    const Vec2 dir = (b - a) / length;
    Vec2 out(dir.y(), -dir.x());
    // a step off the edge's middle, a share of its length, tells which side is the footprint's inside
    constexpr double kSideProbe = 1e-6;
    const Vec2 mid = 0.5 * (a + b), probe = mid + kSideProbe * length * out;
    if (inside_footprint(probe.x(), probe.y(), footprint)) out = -out;
    edges.push_back({a, dir, out, length, id++});
  });
  std::size_t given = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const int own = point_plane[i];
    if (own >= 0 && static_cast<std::size_t>(own) < in_complex.size() && in_complex[static_cast<std::size_t>(own)]) continue;
    const Vec3& p = points[i];
    if (!(p.z() > ground_z + distance)) continue;
    const Edge* best = nullptr;
    double best_d = distance;
    for (const Edge& e : edges) {
      const Vec2 w = p.head<2>() - e.a;
      const double t = w.dot(e.dir);
      if (!(t > 0.0 && t < e.length)) continue;
      const double d = std::abs(w.dot(e.out));
      if (d <= best_d) {
        best_d = d;
        best = &e;
      }
    }
    if (!best) continue;
    point_plane[i] = best->id;
    normals[i] = Vec3(best->out.x(), best->out.y(), 0.0);
    ++given;
  }
  return given;
}

}  // namespace hsr
