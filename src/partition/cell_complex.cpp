// validate(): every invariant of cell_complex.h, checked exactly and independently of how the complex was
// built (volumes by signed tetrahedra here, by facet fluxes in the builder).
#include "partition/cell_complex.h"

#include "core/error.h"
#include "partition/exact_geometry.h"

#include <algorithm>
#include <map>
#include <sstream>

namespace hsr {

using namespace partition_internal;

namespace {

class Problems {
 public:
  explicit Problems(ValidationReport& r) : report_(r) {}
  void add(const std::string& msg) {
    report_.ok = false;
    if (report_.problems.size() < kMaxProblems) report_.problems.push_back(msg);
    else if (report_.problems.size() == kMaxProblems) report_.problems.push_back("... (more problems omitted)");
  }

 private:
  static constexpr std::size_t kMaxProblems = 50;
  ValidationReport& report_;
};

Rational det3(const ExactPoint& a, const ExactPoint& b, const ExactPoint& c) {
  return a.x * (b.y * c.z - b.z * c.y) - a.y * (b.x * c.z - b.z * c.x) + a.z * (b.x * c.y - b.y * c.x);
}

ExactPoint minus(const ExactPoint& a, const ExactPoint& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }

std::string facet_name(std::size_t f) { return "facet " + std::to_string(f); }
std::string cell_name(std::size_t c) { return "cell " + std::to_string(c); }

// Checks the loop of one facet: on its plane, distinct, weakly convex (flat vertices allowed, in order),
// counter-clockwise seen from the plane's positive side, positive area. Returns false on any problem.
bool check_facet_loop(const CellComplex& cx, std::size_t f, Problems& problems) {
  const Facet& g = cx.facets[f];
  const std::size_t n = g.vertices.size();
  if (n < 3) { problems.add(facet_name(f) + ": fewer than 3 vertices"); return false; }
  for (auto v : g.vertices)
    if (v >= cx.vertices.size()) { problems.add(facet_name(f) + ": vertex index out of range"); return false; }
  std::vector<std::uint32_t> sorted = g.vertices;
  std::sort(sorted.begin(), sorted.end());
  if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) {
    problems.add(facet_name(f) + ": repeated vertex in its loop");
    return false;
  }
  const ExactPlane& plane = cx.planes[g.plane].exact;
  for (auto v : g.vertices)
    if (side(plane, cx.vertices[v]) != 0) {
      problems.add(facet_name(f) + ": vertex " + std::to_string(v) + " is not exactly on its plane");
      return false;
    }
  const PlaneFrame fr = frame_of(plane);
  std::vector<P2> poly;
  for (auto v : g.vertices) poly.push_back(to_2d(fr, cx.vertices[v]));
  for (std::size_t i = 0; i < n; ++i) {
    const P2& a = poly[i];
    const P2& b = poly[(i + 1) % n];
    for (std::size_t k = 0; k < n; ++k)
      if (k != i && k != (i + 1) % n && orient_sign(a, b, poly[k]) < 0) {
        problems.add(facet_name(f) + ": loop is not convex counter-clockwise seen from the plane's positive side");
        return false;
      }
    const P2& c = poly[(i + 2) % n];
    if (orient_sign(a, b, c) == 0 && sgn((b.u - a.u) * (c.u - b.u) + (b.v - a.v) * (c.v - b.v)) <= 0) {
      problems.add(facet_name(f) + ": loop folds back on itself");
      return false;
    }
  }
  // Weakly convex and never folding back, the loop has positive area iff some corner is strictly convex.
  bool positive_corner = false;
  for (std::size_t i = 0; i < n && !positive_corner; ++i)
    positive_corner = orient_sign(poly[i], poly[(i + 1) % n], poly[(i + 2) % n]) > 0;
  if (!positive_corner) {
    problems.add(facet_name(f) + ": zero or negative area (collinear loop)");
    return false;
  }
  return true;
}

}  // namespace

Rational box_volume(const CellComplex& cx) {
  return (cx.box_max.x - cx.box_min.x) * (cx.box_max.y - cx.box_min.y) * (cx.box_max.z - cx.box_min.z);
}

ValidationReport validate(const CellComplex& cx, const std::vector<ConvexPolygon>* inputs) {
  ValidationReport report;
  Problems problems(report);
  const std::size_t nv = cx.vertices.size(), nf = cx.facets.size(), nc = cx.cells.size();

  // Box and vertices.
  if (!(cx.box_min.x < cx.box_max.x && cx.box_min.y < cx.box_max.y && cx.box_min.z < cx.box_max.z))
    problems.add("box has non-positive extent");
  if (cx.vertices_approx.size() != nv) problems.add("vertices_approx and vertices differ in size");
  {
    std::vector<std::uint32_t> order(nv);
    for (std::size_t i = 0; i < nv; ++i) order[i] = static_cast<std::uint32_t>(i);
    ExactPointLess less;
    std::sort(order.begin(), order.end(),
              [&](std::uint32_t a, std::uint32_t b) { return less(cx.vertices[a], cx.vertices[b]); });
    for (std::size_t i = 1; i < nv; ++i)
      if (cx.vertices[order[i - 1]] == cx.vertices[order[i]])
        problems.add("vertices " + std::to_string(order[i - 1]) + " and " + std::to_string(order[i]) +
                     " are equal");
    for (std::size_t i = 0; i < nv && i < cx.vertices_approx.size(); ++i) {
      const Vec3 exact = to_double(cx.vertices[i]);
      if ((exact - cx.vertices_approx[i]).norm() > 1e-9 * (1.0 + exact.norm()))
        problems.add("vertex " + std::to_string(i) + ": approximate coordinates disagree with the exact ones");
      const ExactPoint& p = cx.vertices[i];
      if (p.x < cx.box_min.x || p.y < cx.box_min.y || p.z < cx.box_min.z || p.x > cx.box_max.x ||
          p.y > cx.box_max.y || p.z > cx.box_max.z)
        problems.add("vertex " + std::to_string(i) + " is outside the box");
    }
  }
  for (std::size_t p = 0; p < cx.planes.size(); ++p) {
    const ExactPlane& e = cx.planes[p].exact;
    if (e.a == 0 && e.b == 0 && e.c == 0) problems.add("plane " + std::to_string(p) + " has a zero normal");
  }
  if (!report.ok) return report;

  // Facets.
  std::vector<bool> loop_ok(nf, false);
  for (std::size_t f = 0; f < nf; ++f) {
    const Facet& g = cx.facets[f];
    if (g.plane < 0 || static_cast<std::size_t>(g.plane) >= cx.planes.size()) {
      problems.add(facet_name(f) + ": plane index out of range");
      continue;
    }
    loop_ok[f] = check_facet_loop(cx, f, problems);
    const SupportPlane& sp = cx.planes[g.plane];
    if (sp.kind == SupportPlane::Kind::BoxSide) {
      // Low sides have the box on their positive side, high sides on their negative side.
      const int outside = sp.box_side % 2 == 0 ? 1 : 0;
      if (g.cells[outside] != -1 || g.cells[1 - outside] < 0 || g.cells[1 - outside] >= static_cast<int>(nc))
        problems.add(facet_name(f) + ": a box-side facet must have one cell inside and -1 outside");
    } else {
      if (g.cells[0] < 0 || g.cells[1] < 0 || g.cells[0] >= static_cast<int>(nc) ||
          g.cells[1] >= static_cast<int>(nc) || g.cells[0] == g.cells[1])
        problems.add(facet_name(f) + ": an interior facet must separate two distinct cells");
    }
  }
  if (!report.ok) return report;

  // Cross references: each facet is listed by exactly the cells it names.
  std::vector<int> listed(nf, 0);
  for (std::size_t c = 0; c < nc; ++c) {
    std::vector<std::uint32_t> fs = cx.cells[c].facets;
    std::sort(fs.begin(), fs.end());
    if (std::adjacent_find(fs.begin(), fs.end()) != fs.end()) problems.add(cell_name(c) + ": facet listed twice");
    for (auto f : fs) {
      if (f >= nf) { problems.add(cell_name(c) + ": facet index out of range"); continue; }
      if (cx.facets[f].cells[0] != static_cast<int>(c) && cx.facets[f].cells[1] != static_cast<int>(c))
        problems.add(cell_name(c) + " lists " + facet_name(f) + ", which does not name it");
      ++listed[f];
    }
  }
  for (std::size_t f = 0; f < nf; ++f) {
    const int expected = (cx.facets[f].cells[0] >= 0) + (cx.facets[f].cells[1] >= 0);
    if (listed[f] != expected) problems.add(facet_name(f) + " is not listed by each cell it names");
  }
  if (!report.ok) return report;

  // Cells: closed, convex, positive exact volume equal to the stored one.
  Rational total = 0;
  for (std::size_t c = 0; c < nc; ++c) {
    const Cell& cell = cx.cells[c];
    if (cell.facets.size() < 4) { problems.add(cell_name(c) + ": fewer than 4 facets"); continue; }
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
    std::vector<std::uint32_t> cell_vertices;
    for (auto f : cell.facets) {
      const Facet& g = cx.facets[f];
      const bool reverse = g.cells[0] == static_cast<int>(c);  // positive side: outward is -normal
      const std::size_t n = g.vertices.size();
      for (std::size_t i = 0; i < n; ++i) {
        std::uint32_t a = g.vertices[i], b = g.vertices[(i + 1) % n];
        if (reverse) std::swap(a, b);
        ++directed[{a, b}];
        cell_vertices.push_back(a);
      }
    }
    bool closed = true;
    for (const auto& [edge, count] : directed) {
      auto rev = directed.find({edge.second, edge.first});
      if (count != 1 || rev == directed.end() || rev->second != 1) closed = false;
    }
    if (!closed) problems.add(cell_name(c) + ": not closed (an edge is not used exactly once in each direction)");
    std::sort(cell_vertices.begin(), cell_vertices.end());
    cell_vertices.erase(std::unique(cell_vertices.begin(), cell_vertices.end()), cell_vertices.end());
    bool convex = true;
    for (auto f : cell.facets) {
      const Facet& g = cx.facets[f];
      const int inner = g.cells[0] == static_cast<int>(c) ? 1 : -1;
      for (auto v : cell_vertices) {
        if (std::find(g.vertices.begin(), g.vertices.end(), v) != g.vertices.end()) continue;  // on it (checked)
        if (side(cx.planes[g.plane].exact, cx.vertices[v]) * inner < 0) convex = false;
      }
    }
    if (!convex) problems.add(cell_name(c) + ": not convex (a vertex is on the outer side of one of its facets)");
    const ExactPoint& ref = cx.vertices[cell_vertices.front()];
    Rational six_volume = 0;
    for (auto f : cell.facets) {
      const Facet& g = cx.facets[f];
      const bool reverse = g.cells[0] == static_cast<int>(c);
      const std::size_t n = g.vertices.size();
      const ExactPoint a = minus(cx.vertices[g.vertices[0]], ref);
      for (std::size_t i = 1; i + 1 < n; ++i) {
        Rational t = det3(a, minus(cx.vertices[g.vertices[i]], ref), minus(cx.vertices[g.vertices[i + 1]], ref));
        six_volume += reverse ? -t : t;
      }
    }
    Rational volume = six_volume / 6;
    if (sgn(volume) <= 0) problems.add(cell_name(c) + ": non-positive volume");
    if (cx.exact_volumes && volume != cell.volume)
      problems.add(cell_name(c) + ": stored volume differs from its exact volume");
    total += volume;
  }
  if (total != box_volume(cx))
    problems.add("cell volumes sum to " + std::to_string(total.get_d()) + ", box volume is " +
                 std::to_string(box_volume(cx).get_d()));

  // Edge conformity across the whole complex (no T-junctions): no facet edge contains another edge's
  // endpoint in its interior. Edges are grouped by their exact supporting line (canonical direction with
  // first non-zero component 1, and the line's point where that coordinate is 0), then checked as
  // intervals of that coordinate.
  {
    struct LineKey {
      ExactPoint dir, base;
      bool operator<(const LineKey& o) const {
        ExactPointLess less;
        if (less(dir, o.dir)) return true;
        if (less(o.dir, dir)) return false;
        return less(base, o.base);
      }
    };
    auto component = [](const ExactPoint& p, int k) -> const Rational& { return k == 0 ? p.x : k == 1 ? p.y : p.z; };
    std::map<LineKey, std::vector<std::pair<Rational, Rational>>> lines;
    std::map<std::pair<std::uint32_t, std::uint32_t>, bool> seen;
    for (std::size_t f = 0; f < nf; ++f) {
      const auto& loop = cx.facets[f].vertices;
      for (std::size_t i = 0; i < loop.size(); ++i) {
        std::uint32_t u = loop[i], v = loop[(i + 1) % loop.size()];
        if (u > v) std::swap(u, v);
        if (!seen.emplace(std::make_pair(u, v), true).second) continue;
        const ExactPoint& p = cx.vertices[u];
        ExactPoint d = minus(cx.vertices[v], p);
        const int k = d.x != 0 ? 0 : d.y != 0 ? 1 : 2;
        const Rational lead = component(d, k);
        d = {d.x / lead, d.y / lead, d.z / lead};
        const Rational t = component(p, k);
        ExactPoint base{p.x - t * d.x, p.y - t * d.y, p.z - t * d.z};
        Rational t1 = t, t2 = component(cx.vertices[v], k);
        if (t2 < t1) std::swap(t1, t2);
        lines[{d, base}].emplace_back(std::move(t1), std::move(t2));
      }
    }
    for (auto& [key, intervals] : lines) {
      std::vector<Rational> ends;
      for (const auto& [a, b] : intervals) { ends.push_back(a); ends.push_back(b); }
      std::sort(ends.begin(), ends.end());
      ends.erase(std::unique(ends.begin(), ends.end()), ends.end());
      for (const auto& [a, b] : intervals) {
        auto it = std::upper_bound(ends.begin(), ends.end(), a);
        if (it != ends.end() && *it < b) {
          problems.add("T-junction: a facet edge has another edge's endpoint in its interior (line through " +
                       std::to_string(key.base.x.get_d()) + ", " + std::to_string(key.base.y.get_d()) + ", " +
                       std::to_string(key.base.z.get_d()) + ")");
          break;
        }
      }
    }
  }

  // Facets of one plane do not overlap (exact separating-axis test on pairs whose 2D bboxes overlap).
  std::vector<std::vector<std::uint32_t>> by_plane(cx.planes.size());
  for (std::size_t f = 0; f < nf; ++f)
    if (loop_ok[f]) by_plane[cx.facets[f].plane].push_back(static_cast<std::uint32_t>(f));
  std::vector<std::vector<P2>> poly2d(nf);
  for (std::size_t p = 0; p < cx.planes.size(); ++p) {
    const PlaneFrame fr = frame_of(cx.planes[p].exact);
    struct Box2 { Rational umin, umax, vmin, vmax; std::uint32_t f; };
    std::vector<Box2> boxes;
    for (auto f : by_plane[p]) {
      for (auto v : cx.facets[f].vertices) poly2d[f].push_back(to_2d(fr, cx.vertices[v]));
      Box2 b{poly2d[f][0].u, poly2d[f][0].u, poly2d[f][0].v, poly2d[f][0].v, f};
      for (const P2& q : poly2d[f]) {
        if (q.u < b.umin) b.umin = q.u;
        if (q.u > b.umax) b.umax = q.u;
        if (q.v < b.vmin) b.vmin = q.v;
        if (q.v > b.vmax) b.vmax = q.v;
      }
      boxes.push_back(std::move(b));
    }
    std::sort(boxes.begin(), boxes.end(), [](const Box2& a, const Box2& b) { return a.umin < b.umin; });
    for (std::size_t i = 0; i < boxes.size(); ++i)
      for (std::size_t j = i + 1; j < boxes.size() && boxes[j].umin < boxes[i].umax; ++j) {
        if (!(boxes[j].vmin < boxes[i].vmax && boxes[i].vmin < boxes[j].vmax)) continue;
        if (interiors_overlap(poly2d[boxes[i].f], poly2d[boxes[j].f]))
          problems.add("facets " + std::to_string(boxes[i].f) + " and " + std::to_string(boxes[j].f) +
                       " of plane " + std::to_string(p) + " overlap");
      }
  }

  // Coverage: exact. Facets of one plane do not overlap (checked above), so the area of the union of
  // their intersections with the polygon is the sum of those areas; it must equal the area of the
  // polygon clipped to the box.
  if (inputs) {
    for (std::size_t i = 0; i < inputs->size(); ++i) {
      const ConvexPolygon& poly = (*inputs)[i];
      const std::string name = "input polygon " + std::to_string(i);
      ExactPlane plane;
      try {
        plane = canonical_plane(poly.plane);
      } catch (const Error& e) {
        problems.add(name + ": " + e.what());
        continue;
      }
      int found = -1;
      for (std::size_t p = 0; p < cx.planes.size() && found < 0; ++p)
        if (same_plane(cx.planes[p].exact, plane)) found = static_cast<int>(p);
      if (found < 0) { problems.add(name + ": its plane is not a support plane of the complex"); continue; }
      const auto& ids = cx.planes[found].input_planes;
      if (std::find(ids.begin(), ids.end(), poly.plane_id) == ids.end())
        problems.add(name + ": its support plane does not list plane id " + std::to_string(poly.plane_id));
      const PlaneFrame fr = frame_of(plane);
      std::vector<P2> p2 = project_polygon(poly, plane, fr);
      if (p2.empty()) continue;  // degenerate polygon: nothing to cover
      const Rational target = twice_area(clip_to_box(p2, plane, fr, cx.box_min, cx.box_max));
      Rational covered = 0;
      for (auto f : by_plane[found]) covered += twice_area(clip_convex(poly2d[f], p2));
      if (covered != target) {
        std::ostringstream msg;
        msg << name << ": facets of its plane cover " << covered.get_d() / 2 << " of its area " << target.get_d() / 2
            << " (2D, in the plane's frame)";
        problems.add(msg.str());
      }
    }
  }
  return report;
}

}  // namespace hsr
