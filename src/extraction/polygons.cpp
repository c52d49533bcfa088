// Stage 6, from the labels' surface to the output polygons (paper §3.6, the surface's last steps; DESIGN.md §1
// stage 6): coplanar facets merged per support plane and orientation into disks, a region with a hole covered
// greedily by disks (DECISIONS #8), each face's class, and the mesh of the polygons with the straight vertices
// no polygon needs dropped. The labelling itself (votes, energy, min-cut, repair) is in extraction.cpp.
#include "extraction/polygons.h"

#include "core/error.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <map>
#include <numeric>
#include <set>
#include <utility>

namespace hsr {
namespace {

/// If `boundary` (directed edges of a region, interior edges cancelled) is one simple closed loop, returns
/// it starting at its smallest edge; otherwise (a hole, a pinch vertex, several pieces) returns empty.
Loop single_simple_loop(const std::set<DirectedEdge>& boundary) {
  if (boundary.size() < 3) return {};
  std::map<std::uint32_t, std::uint32_t> next;
  for (const auto& [u, v] : boundary)
    if (!next.emplace(u, v).second) return {};  // two boundary edges leave u: pinch or touching hole
  Loop loop;
  std::uint32_t v = boundary.begin()->first;
  do {
    loop.push_back(v);
    const auto it = next.find(v);
    if (it == next.end() || loop.size() > boundary.size()) return {};
    v = it->second;
  } while (v != loop.front());
  return loop.size() == boundary.size() ? loop : Loop{};
}

void toggle_edges(std::set<DirectedEdge>& boundary, const Loop& loop) {
  const std::size_t n = loop.size();
  for (std::size_t i = 0; i < n; ++i) {
    const DirectedEdge e{loop[i], loop[(i + 1) % n]};
    const auto rev = boundary.find({e.second, e.first});
    if (rev != boundary.end()) boundary.erase(rev);
    else boundary.insert(e);
  }
}

/// A planar region that is a topological disk (union of convex facets), grown one facet at a time.
struct DiskRegion {
  std::set<DirectedEdge> boundary;             ///< directed boundary edges (interior on the left/inside)
  std::map<std::uint32_t, int> boundary_degree;  ///< boundary edges leaving each boundary vertex (1 for a disk)

  explicit DiskRegion(const Loop& first) {
    for (std::size_t i = 0; i < first.size(); ++i) add_edge({first[i], first[(i + 1) % first.size()]});
  }
  void add_edge(const DirectedEdge& e) {
    boundary.insert(e);
    ++boundary_degree[e.first];
  }
  void remove_edge(const DirectedEdge& e) {
    boundary.erase(e);
    if (--boundary_degree[e.first] == 0) boundary_degree.erase(e.first);
  }
  /// Adds the facet if the union stays a disk: the facet shares one contiguous, non-empty chain of edges
  /// with the boundary (not all of its edges), and touches the boundary nowhere else (none of its vertices
  /// off that chain is a boundary vertex). Both are needed and enough for two disks glued along an arc.
  bool try_add(const Loop& g) {
    const std::size_t n = g.size();
    std::vector<char> shared(n);  // edge i = g[i] -> g[i+1] runs against a boundary edge
    std::size_t count = 0, runs = 0;
    for (std::size_t i = 0; i < n; ++i) count += shared[i] = boundary.count({g[(i + 1) % n], g[i]}) > 0;
    if (count == 0 || count == n) return false;
    for (std::size_t i = 0; i < n; ++i) runs += shared[i] && !shared[(i + n - 1) % n];
    if (runs != 1) return false;
    for (std::size_t i = 0; i < n; ++i)
      if (!shared[i] && !shared[(i + n - 1) % n] && boundary_degree.count(g[i])) return false;
    for (std::size_t i = 0; i < n; ++i) {
      const DirectedEdge e{g[i], g[(i + 1) % n]};
      if (shared[i]) remove_edge({e.second, e.first});
      else add_edge(e);
    }
    return true;
  }
};

}  // namespace

/// Merges the loops of one (support plane, orientation) group. Loops sharing an edge (in opposite
/// directions) form components; a component whose union is a disk becomes one polygon. A component with a
/// hole (or a pinch vertex) is never turned into a keyhole polygon: it is covered greedily by disks instead
/// (grow a region facet by facet, breadth first from its lowest-index facet, accepting a neighbour only when
/// the union stays bounded by one simple loop; repeat from the next unused facet).
std::vector<Loop> merge_group(const std::vector<Loop>& loops, std::size_t* holed_components) {
  std::map<DirectedEdge, int> owner;
  for (std::size_t i = 0; i < loops.size(); ++i) {
    const Loop& l = loops[i];
    for (std::size_t k = 0; k < l.size(); ++k) owner.emplace(DirectedEdge{l[k], l[(k + 1) % l.size()]}, static_cast<int>(i));
  }
  std::vector<std::vector<int>> neighbours(loops.size());
  for (const auto& [e, i] : owner) {
    const auto it = owner.find({e.second, e.first});
    if (it != owner.end() && it->second != i) neighbours[i].push_back(it->second);
  }
  for (auto& nb : neighbours) {
    std::sort(nb.begin(), nb.end());
    nb.erase(std::unique(nb.begin(), nb.end()), nb.end());
  }

  std::vector<Loop> result;
  std::vector<int> component(loops.size(), -1);
  for (std::size_t seed = 0; seed < loops.size(); ++seed) {
    if (component[seed] >= 0) continue;
    std::vector<int> members{static_cast<int>(seed)};
    component[seed] = static_cast<int>(seed);
    for (std::size_t k = 0; k < members.size(); ++k)
      for (int nb : neighbours[members[k]])
        if (component[nb] < 0) {
          component[nb] = static_cast<int>(seed);
          members.push_back(nb);
        }
    std::sort(members.begin(), members.end());
    if (members.size() == 1) {
      result.push_back(loops[members[0]]);
      continue;
    }
    std::set<DirectedEdge> boundary;
    for (int i : members) toggle_edges(boundary, loops[i]);
    Loop merged = single_simple_loop(boundary);
    if (!merged.empty()) {
      result.push_back(std::move(merged));
      continue;
    }
    ++*holed_components;
    std::set<int> unused(members.begin(), members.end());
    while (!unused.empty()) {
      const int start = *unused.begin();
      unused.erase(unused.begin());
      DiskRegion region(loops[start]);
      std::deque<int> queue(neighbours[start].begin(), neighbours[start].end());
      while (!queue.empty()) {
        const int candidate = queue.front();
        queue.pop_front();
        if (!unused.count(candidate) || !region.try_add(loops[candidate])) continue;
        unused.erase(candidate);
        for (int nb : neighbours[candidate])
          if (unused.count(nb)) queue.push_back(nb);  // also retries neighbours rejected earlier
      }
      Loop piece = single_simple_loop(region.boundary);
      HSR_ASSERT(!piece.empty(), "greedy disk cover produced a non-simple region");
      result.push_back(std::move(piece));
    }
  }
  return result;
}

/// What an output face is, from its support plane and orientation (sign +1: the face's outward normal is
/// the plane's normal): the box's bottom is the ground, its other sides close the solid where the data
/// ends; a data plane (or a box side that is one) by its outward normal: up roof, vertical wall, down ground.
FaceClass face_class_of(const CellComplex& cx, int plane, int sign) {
  const SupportPlane& p = cx.planes[static_cast<std::size_t>(plane)];
  if (p.kind == SupportPlane::Kind::BoxSide && p.input_planes.empty())
    return p.box_side == 4 ? FaceClass::Ground : FaceClass::Closure;
  const double nz = sign * p.approx.normal.normalized().z();
  if (std::abs(nz) < kVerticalFaceNz) return FaceClass::Wall;
  return nz > 0 ? FaceClass::Roof : FaceClass::Ground;
}

/// The output mesh of the polygons (complex vertex loops): vertices shared, numbered in order of first use,
/// a vertex dropped only where no polygon needs it (it is a straight, non-corner vertex of every polygon
/// using it; after T-junction insertion every polygon geometrically passing through a surface vertex lists
/// it, so the mesh stays watertight). `plane_of[k]` is polygon k's support plane. `mesh_index` gets each
/// complex vertex's mesh vertex (-1: not used).
PolygonMesh assemble_mesh(const CellComplex& cx, const std::vector<Loop>& polygons, const std::vector<int>& plane_of,
                          std::vector<std::int64_t>& mesh_index) {
  std::vector<char> needed(cx.vertices.size(), 0);
  for (std::size_t k = 0; k < polygons.size(); ++k) {
    const Loop& l = polygons[k];
    const ExactPlane& plane = cx.planes[static_cast<std::size_t>(plane_of[k])].exact;
    const std::size_t n = l.size();
    for (std::size_t i = 0; i < n; ++i)
      if (!needed[l[i]] &&
          !is_straight(cx.vertices[l[(i + n - 1) % n]], cx.vertices[l[i]], cx.vertices[l[(i + 1) % n]], plane))
        needed[l[i]] = 1;
  }
  PolygonMesh mesh;
  mesh_index.assign(cx.vertices.size(), -1);
  for (const Loop& l : polygons) {
    std::vector<std::uint32_t> face;
    for (std::uint32_t v : l) {
      if (!needed[v]) continue;
      if (mesh_index[v] < 0) {
        mesh_index[v] = static_cast<std::int64_t>(mesh.vertices.size());
        mesh.vertices.push_back(cx.vertices_approx[v]);
      }
      face.push_back(static_cast<std::uint32_t>(mesh_index[v]));
    }
    HSR_ASSERT(face.size() >= 3, "extraction produced a face with fewer than 3 corners");
    mesh.faces.push_back(std::move(face));
  }
  return mesh;
}

bool closed_two_sided(const std::vector<std::vector<std::uint32_t>>& faces) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> used;
  for (const auto& f : faces) {
    std::set<std::uint32_t> corners(f.begin(), f.end());
    if (corners.size() != f.size()) return false;
    for (std::size_t i = 0; i < f.size(); ++i)
      if (++used[{f[i], f[(i + 1) % f.size()]}] > 1) return false;
  }
  for (const auto& [edge, n] : used)
    if (!used.count({edge.second, edge.first})) return false;
  return true;
}

namespace {

bool sub_precision(const Vec3& a, const Vec3& b) {
  const double scale = std::max({1.0, a.cwiseAbs().maxCoeff(), b.cwiseAbs().maxCoeff()});
  return (a - b).cwiseAbs().maxCoeff() <= kSubPrecisionUlps * std::numeric_limits<double>::epsilon() * scale;
}

}  // namespace

std::size_t collapse_sub_precision_edges(PolygonMesh& mesh) {
  std::vector<std::uint32_t> rep(mesh.vertices.size());
  std::iota(rep.begin(), rep.end(), 0u);
  const auto find = [&](std::uint32_t v) {
    while (rep[v] != v) v = rep[v] = rep[rep[v]];
    return v;
  };
  std::size_t collapsed = 0;
  for (const auto& f : mesh.faces)
    for (std::size_t i = 0; i < f.size(); ++i) {
      const std::uint32_t a = find(f[i]), b = find(f[(i + 1) % f.size()]);
      if (a == b || !sub_precision(mesh.vertices[a], mesh.vertices[b])) continue;
      rep[std::max(a, b)] = std::min(a, b);
      ++collapsed;
    }
  if (collapsed == 0) return 0;
  std::vector<std::vector<std::uint32_t>> faces;
  std::vector<FaceClass> classes;
  for (std::size_t k = 0; k < mesh.faces.size(); ++k) {
    std::vector<std::uint32_t> f;
    for (std::uint32_t v : mesh.faces[k]) {
      const std::uint32_t r = find(v);
      if (f.empty() || f.back() != r) f.push_back(r);
    }
    while (f.size() > 1 && f.front() == f.back()) f.pop_back();
    if (f.size() < 3) continue;
    faces.push_back(std::move(f));
    if (!mesh.face_class.empty()) classes.push_back(mesh.face_class[k]);
  }
  if (!closed_two_sided(faces) || !closed_two_sided(mesh.faces)) return 0;
  std::vector<std::int64_t> index(mesh.vertices.size(), -1);  // old vertex -> new, in order of first use
  std::vector<Vec3> vertices;
  for (auto& f : faces)
    for (std::uint32_t& v : f) {
      if (index[v] < 0) {
        index[v] = static_cast<std::int64_t>(vertices.size());
        vertices.push_back(mesh.vertices[v]);
      }
      v = static_cast<std::uint32_t>(index[v]);
    }
  mesh.vertices = std::move(vertices);
  mesh.faces = std::move(faces);
  if (!mesh.face_class.empty()) mesh.face_class = std::move(classes);
  return collapsed;
}

}  // namespace hsr
