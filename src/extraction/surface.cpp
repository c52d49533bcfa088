// The surface of a labelling and its defects (surface.h).
#include "extraction/surface.h"

#include "extraction/near_edge_index.h"
#include "partition/exact_geometry.h"

#include <algorithm>
#include <array>
#include <map>
#include <tuple>

namespace hsr {
namespace {

struct ExactVec {
  Rational x, y, z;
};

ExactVec sub(const ExactPoint& a, const ExactPoint& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
Rational dot(const ExactVec& a, const ExactVec& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
bool cross_is_zero(const ExactVec& a, const ExactVec& b) {
  return a.y * b.z == a.z * b.y && a.z * b.x == a.x * b.z && a.x * b.y == a.y * b.x;
}

}  // namespace

bool on_open_segment(const ExactPoint& a, const ExactPoint& b, const ExactPoint& w) {
  const ExactVec d = sub(b, a), e = sub(w, a);
  if (!cross_is_zero(d, e)) return false;
  const Rational t = dot(e, d);
  return sgn(t) > 0 && t < dot(d, d);
}

bool is_straight(const ExactPoint& prev, const ExactPoint& v, const ExactPoint& next, const ExactPlane& plane) {
  // Collinear in 3D exactly when collinear in the plane's 2D frame (dropping an axis the plane is not
  // parallel to is injective on it): the partition's filtered, gcd-free orientation.
  using namespace partition_internal;
  const PlaneFrame frame = frame_of(plane);
  if (orient_sign(to_2d(frame, prev), to_2d(frame, v), to_2d(frame, next)) != 0) return false;
  // On one line every coordinate is an affine function of the position along it, so v lies strictly between
  // prev and next exactly when, in each coordinate, prev and next are on opposite sides of v or level with it.
  const auto opposite = [](const Rational& p, const Rational& c, const Rational& n) {
    const int sp = cmp(p, c), sn = cmp(n, c);  // gmpxx's cmp: any negative, zero or positive int
    return (sp < 0 && sn > 0) || (sp > 0 && sn < 0) || (sp == 0 && sn == 0);
  };
  return opposite(prev.x, v.x, next.x) && opposite(prev.y, v.y, next.y) && opposite(prev.z, v.z, next.z) &&
         !(prev == v);
}

void insert_t_junctions(const CellComplex& cx, std::vector<Loop>& loops) {
  std::vector<std::uint32_t> verts;
  for (const Loop& l : loops) verts.insert(verts.end(), l.begin(), l.end());
  std::sort(verts.begin(), verts.end());
  verts.erase(std::unique(verts.begin(), verts.end()), verts.end());
  const NearEdgeIndex index(cx.vertices_approx, verts);
  const double eps = 1e-9 * std::max(cx.box.diagonal(), 1e-30);
  for (Loop& loop : loops) {
    Loop out;
    const std::size_t n = loop.size();
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint32_t a = loop[i], b = loop[(i + 1) % n];
      out.push_back(a);
      const Vec3& pa = cx.vertices_approx[a];
      const Vec3& pb = cx.vertices_approx[b];
      std::vector<std::pair<Rational, std::uint32_t>> inner;
      index.for_each_in_edge_box(a, b, eps, [&](std::uint32_t w) {
        const Vec3& pw = cx.vertices_approx[w];
        // Cheap filter before the exact test: farther than eps from the line (rounding is far below eps).
        if ((pb - pa).cross(pw - pa).norm() > eps * (pb - pa).norm()) return;
        if (!on_open_segment(cx.vertices[a], cx.vertices[b], cx.vertices[w])) return;
        inner.push_back({dot(sub(cx.vertices[w], cx.vertices[a]), sub(cx.vertices[b], cx.vertices[a])), w});
      });
      std::sort(inner.begin(), inner.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
      for (const auto& [t, w] : inner) out.push_back(w);
    }
    loop = std::move(out);
  }
}

Surface surface_of(const CellComplex& cx, const std::vector<bool>& inside) {
  auto is_inside = [&](int c) { return c >= 0 && inside[c]; };
  Surface s;
  for (std::size_t f = 0; f < cx.facets.size(); ++f) {
    const Facet& facet = cx.facets[f];
    if (is_inside(facet.cells[0]) == is_inside(facet.cells[1])) continue;
    // The loop is CCW about the plane normal, which points to cells[0]: keep it when cells[0] is outside.
    Loop loop = facet.vertices;
    int sign = 1;
    if (is_inside(facet.cells[0])) {
      std::reverse(loop.begin(), loop.end());
      sign = -1;
    }
    s.loops.push_back(std::move(loop));
    s.facet.push_back(static_cast<int>(f));
    s.group.push_back({facet.plane, sign});
  }
  insert_t_junctions(cx, s.loops);
  return s;
}

Defects find_defects(const CellComplex& cx, const Surface& s) {
  Defects d;
  // (undirected edge (min, max), loop) and (vertex, loop), sorted: each key's loops in increasing order, as
  // ordered maps of vectors would hold them, without a node per key.
  std::vector<std::pair<DirectedEdge, int>> edge_uses;
  std::vector<std::pair<std::uint32_t, int>> vertex_uses;
  for (std::size_t i = 0; i < s.loops.size(); ++i) {
    const Loop& l = s.loops[i];
    for (std::size_t k = 0; k < l.size(); ++k) {
      const std::uint32_t a = l[k], b = l[(k + 1) % l.size()];
      edge_uses.push_back({{std::min(a, b), std::max(a, b)}, static_cast<int>(i)});
      vertex_uses.push_back({a, static_cast<int>(i)});
    }
  }
  std::sort(edge_uses.begin(), edge_uses.end());
  std::sort(vertex_uses.begin(), vertex_uses.end());
  auto cells_of = [&](const std::vector<int>& loops, std::size_t min_count) {
    std::map<int, std::size_t> count;
    for (int i : loops)
      for (int c : cx.facets[s.facet[i]].cells)
        if (c >= 0) ++count[c];
    std::vector<int> out;
    for (const auto& [c, n] : count)
      if (n >= min_count) out.push_back(c);
    return out;
  };
  // Calls visit(key, loops) for each run of equal keys.
  std::vector<int> loops;
  auto for_each_key = [&loops](const auto& uses, auto&& visit) {
    for (std::size_t r = 0; r < uses.size();) {
      std::size_t e = r;
      loops.clear();
      while (e < uses.size() && uses[e].first == uses[r].first) loops.push_back(uses[e++].second);
      visit(uses[r].first, loops);
      r = e;
    }
  };
  for_each_key(edge_uses, [&](const DirectedEdge&, const std::vector<int>& at_edge) {
    if (at_edge.size() <= 2) return;
    ++d.edges;
    // Cells forming a run of their own around the edge bound it with two of its surface facets.
    d.list.push_back({cells_of(at_edge, 2), cells_of(at_edge, 1)});
  });
  std::vector<std::pair<std::uint32_t, std::uint32_t>> around;
  for_each_key(vertex_uses, [&](std::uint32_t v, const std::vector<int>& at_vertex) {
    around.clear();
    for (int i : at_vertex) {
      const Loop& l = s.loops[i];
      const std::size_t n = l.size();
      const std::size_t k = static_cast<std::size_t>(std::find(l.begin(), l.end(), v) - l.begin());
      around.push_back({l[(k + n - 1) % n], l[(k + 1) % n]});
    }
    if (fans_at(around) <= 1) return;
    ++d.vertices;
    d.list.push_back({{}, cells_of(at_vertex, 1)});
  });
  return d;
}


std::size_t fans_at(const std::vector<std::pair<std::uint32_t, std::uint32_t>>& around) {
  std::vector<int> parent(around.size());
  for (std::size_t i = 0; i < parent.size(); ++i) parent[i] = static_cast<int>(i);
  auto find = [&](int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  std::vector<std::pair<std::uint32_t, int>> first_at;  // (other end of an edge at v, first loop using it)
  for (std::size_t i = 0; i < around.size(); ++i)
    for (std::uint32_t w : {around[i].first, around[i].second}) {
      const auto it = std::find_if(first_at.begin(), first_at.end(), [&](const auto& e) { return e.first == w; });
      if (it == first_at.end()) first_at.push_back({w, static_cast<int>(i)});
      else parent[find(static_cast<int>(i))] = find(it->second);
    }
  std::size_t classes = 0;
  for (std::size_t i = 0; i < parent.size(); ++i) classes += find(static_cast<int>(i)) == static_cast<int>(i);
  return classes;
}

DefectCounter::DefectCounter(const CellComplex& cx, const std::vector<bool>& inside)
    : cx_(cx), inside_(inside) {
  loops_.reserve(cx.facets.size());
  for (const Facet& f : cx.facets) loops_.push_back(f.vertices);
  insert_t_junctions(cx, loops_);  // every facet's corners: a superset of any surface's
  corner_.resize(loops_.size());
  at_.resize(cx.vertices.size());
  corners_on_surface_.assign(cx.vertices.size(), 0);
  for (std::size_t f = 0; f < loops_.size(); ++f) {
    const Loop& corners = cx.facets[f].vertices;
    std::size_t next_corner = 0;  // the corners appear in the extended loop in their order
    for (std::size_t k = 0; k < loops_[f].size(); ++k) {
      const bool is_corner = next_corner < corners.size() && loops_[f][k] == corners[next_corner];
      next_corner += is_corner;
      corner_[f].push_back(is_corner);
      at_[loops_[f][k]].push_back({static_cast<int>(f), static_cast<int>(k)});
      if (is_corner && on_surface(inside_, static_cast<int>(f))) ++corners_on_surface_[loops_[f][k]];
    }
  }
  std::vector<std::uint32_t> all(cx.vertices.size());
  for (std::size_t v = 0; v < all.size(); ++v) all[v] = static_cast<std::uint32_t>(v);
  count_ = defects_at(all, inside_);
}

bool DefectCounter::on_surface(const std::vector<bool>& inside, int facet) const {
  const Facet& f = cx_.facets[facet];
  return (f.cells[0] >= 0 && inside[f.cells[0]]) != (f.cells[1] >= 0 && inside[f.cells[1]]);
}

void DefectCounter::move_corners(const std::vector<bool>& from, const std::vector<bool>& to,
                                 const std::vector<int>& flipped) {
  std::vector<std::uint32_t> facets;
  for (int c : flipped) facets.insert(facets.end(), cx_.cells[c].facets.begin(), cx_.cells[c].facets.end());
  std::sort(facets.begin(), facets.end());
  facets.erase(std::unique(facets.begin(), facets.end()), facets.end());
  for (std::uint32_t f : facets) {
    const bool was = on_surface(from, static_cast<int>(f)), is = on_surface(to, static_cast<int>(f));
    if (was == is) continue;
    for (std::size_t k = 0; k < loops_[f].size(); ++k)
      if (corner_[f][k]) corners_on_surface_[loops_[f][k]] += is ? 1 : -1;
  }
}

std::vector<std::uint32_t> DefectCounter::around(const std::vector<int>& flipped) const {
  // The flipped facets' vertices (their loops, their corners' presence elsewhere), and every vertex of a
  // loop through one of them (its neighbours along that loop may change).
  std::vector<std::uint32_t> near;
  for (int c : flipped)
    for (std::uint32_t f : cx_.cells[c].facets) near.insert(near.end(), loops_[f].begin(), loops_[f].end());
  std::sort(near.begin(), near.end());
  near.erase(std::unique(near.begin(), near.end()), near.end());
  std::vector<std::uint32_t> out = near;
  for (std::uint32_t u : near)
    for (const auto& [g, pos] : at_[u]) out.insert(out.end(), loops_[g].begin(), loops_[g].end());
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

std::size_t DefectCounter::defects_at(const std::vector<std::uint32_t>& where, const std::vector<bool>& inside) const {
  std::size_t defects = 0;
  std::vector<std::tuple<std::uint32_t, std::uint32_t, int>> edges;  // (min end, max end, facet)
  std::vector<std::pair<std::uint32_t, std::uint32_t>> around;
  for (std::uint32_t v : where) {
    if (corners_on_surface_[v] == 0) continue;  // on no surface loop
    around.clear();
    for (const auto& [g, pos] : at_[v]) {
      if (!on_surface(inside, g)) continue;
      const Loop& l = loops_[g];
      const std::size_t n = l.size();
      auto present = [&](std::size_t k) { return corner_[g][k] || corners_on_surface_[l[k]] > 0; };
      std::size_t prev = static_cast<std::size_t>(pos), next = prev;
      do prev = (prev + n - 1) % n;
      while (!present(prev));
      do next = (next + 1) % n;
      while (!present(next));
      around.push_back({l[prev], l[next]});
      for (std::uint32_t w : {l[prev], l[next]}) edges.emplace_back(std::min(v, w), std::max(v, w), g);
    }
    if (fans_at(around) > 1) ++defects;
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && std::get<0>(edges[j]) == std::get<0>(edges[i]) &&
           std::get<1>(edges[j]) == std::get<1>(edges[i]))
      ++j;
    defects += j - i > 2;  // an edge of more than two surface facets
    i = j;
  }
  return defects;
}

std::size_t DefectCounter::count_with(const std::vector<bool>& inside, const std::vector<int>& flipped) {
  const std::vector<std::uint32_t> where = around(flipped);
  const std::size_t before = defects_at(where, inside_);
  move_corners(inside_, inside, flipped);
  const std::size_t after = defects_at(where, inside);
  move_corners(inside, inside_, flipped);
  return count_ - before + after;
}

void DefectCounter::commit(const std::vector<bool>& inside, const std::vector<int>& flipped) {
  count_ = count_with(inside, flipped);
  move_corners(inside_, inside, flipped);
  for (int c : flipped) inside_[c] = inside[c];
}

}  // namespace hsr
