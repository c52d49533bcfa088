// Test helpers for extraction: exact cell complexes made of axis-aligned integer boxes that tile their
// bounding box (conforming grids or non-conforming kd-trees), points sampled on a chosen boundary, and
// mesh checks (closedness, simplicity, volume) computed independently of the code under test.
#pragma once

#include "partition/cell_complex.h"

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <map>
#include <random>
#include <set>
#include <utility>
#include <vector>

namespace hsr::test {

struct IBox {
  std::array<int, 3> lo, hi;
  long volume() const { return long(hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]); }
};

/// A complex built from boxes, with the rectangle of every facet (for point sampling) and the input plane id
/// of every axis plane (interior planes only; box sides have none).
struct BoxComplex {
  CellComplex cx;
  std::vector<IBox> boxes;                       // == cells
  std::vector<std::array<int, 3>> facet_lo, facet_hi;  // facet rectangle (flat along its axis)
  std::vector<int> facet_axis;
  std::map<std::pair<int, int>, int> input_id;  // (axis, coordinate) -> input plane id
  std::vector<double> facet_area;
};

inline int input_plane_id_base() { return 100; }  // input ids differ from support-plane indices on purpose

/// Builds the exact complex of `boxes`, which must tile their bounding box. Each facet is the overlap of two
/// touching box faces (or a box face on the domain boundary). With `insert_flat_vertices`, facet loops also
/// list every box corner lying inside their edges (edge-conforming, like the BSP partitioner); without,
/// facets are bare rectangles and neighbours meet in T-junctions.
inline BoxComplex build_box_complex(const std::vector<IBox>& boxes, bool insert_flat_vertices = false) {
  BoxComplex out;
  out.boxes = boxes;
  CellComplex& cx = out.cx;
  std::array<int, 3> dlo = boxes[0].lo, dhi = boxes[0].hi;
  for (const IBox& b : boxes)
    for (int k = 0; k < 3; ++k) {
      dlo[k] = std::min(dlo[k], b.lo[k]);
      dhi[k] = std::max(dhi[k], b.hi[k]);
    }
  std::map<std::array<int, 3>, std::uint32_t> vertex_id;
  std::set<std::array<int, 3>> corners;
  for (const IBox& b : boxes)
    for (int m = 0; m < 8; ++m) corners.insert({(m & 1) ? b.hi[0] : b.lo[0], (m & 2) ? b.hi[1] : b.lo[1], (m & 4) ? b.hi[2] : b.lo[2]});
  auto vid = [&](const std::array<int, 3>& p) {
    auto it = vertex_id.find(p);
    if (it != vertex_id.end()) return it->second;
    const auto id = static_cast<std::uint32_t>(cx.vertices.size());
    vertex_id.emplace(p, id);
    cx.vertices.push_back({Rational(p[0]), Rational(p[1]), Rational(p[2])});
    cx.vertices_approx.push_back(Vec3(p[0], p[1], p[2]));
    return id;
  };
  std::map<std::pair<int, int>, int> plane_of;
  auto plane = [&](int axis, int coord) {
    auto it = plane_of.find({axis, coord});
    if (it != plane_of.end()) return it->second;
    SupportPlane sp;
    const bool side = coord == dlo[axis] || coord == dhi[axis];
    sp.kind = side ? SupportPlane::Kind::BoxSide : SupportPlane::Kind::Input;
    sp.box_side = side ? 2 * axis + (coord == dhi[axis] ? 1 : 0) : -1;
    Rational n[3] = {0, 0, 0};
    n[axis] = 1;
    sp.exact = {n[0], n[1], n[2], Rational(-coord)};
    sp.approx.normal = Vec3::Unit(axis);
    sp.approx.offset = -coord;
    const int id = static_cast<int>(cx.planes.size());
    if (!side) {
      sp.input_planes = {input_plane_id_base() + id};
      out.input_id[{axis, coord}] = input_plane_id_base() + id;
    }
    cx.planes.push_back(sp);
    plane_of[{axis, coord}] = id;
    return id;
  };
  cx.cells.resize(boxes.size());
  auto add_facet = [&](int axis, int coord, std::array<int, 2> uv_lo, std::array<int, 2> uv_hi, int positive, int negative) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;  // e_u x e_v = e_axis: this loop is CCW about +axis
    auto point = [&](int a, int b) {
      std::array<int, 3> p{};
      p[axis] = coord;
      p[u] = a;
      p[v] = b;
      return p;
    };
    const std::array<std::array<int, 3>, 4> rect = {point(uv_lo[0], uv_lo[1]), point(uv_hi[0], uv_lo[1]),
                                                    point(uv_hi[0], uv_hi[1]), point(uv_lo[0], uv_hi[1])};
    Facet f;
    f.plane = plane(axis, coord);
    f.cells = {positive, negative};
    for (int i = 0; i < 4; ++i) {
      f.vertices.push_back(vid(rect[i]));
      if (!insert_flat_vertices) continue;
      const auto& a = rect[i];
      const auto& b = rect[(i + 1) % 4];
      std::vector<std::pair<int, std::array<int, 3>>> inner;
      for (const auto& c : corners) {
        bool on = true;
        int t = 0;
        for (int k = 0; k < 3; ++k) {
          if (a[k] == b[k]) on = on && c[k] == a[k];
          else {
            const int lo = std::min(a[k], b[k]), hi = std::max(a[k], b[k]);
            on = on && c[k] > lo && c[k] < hi;
            t = std::abs(c[k] - a[k]);
          }
        }
        if (on) inner.push_back({t, c});
      }
      std::sort(inner.begin(), inner.end());
      for (const auto& [t, c] : inner) f.vertices.push_back(vid(c));
    }
    const auto fid = static_cast<std::uint32_t>(cx.facets.size());
    cx.facets.push_back(f);
    if (positive >= 0) cx.cells[positive].facets.push_back(fid);
    if (negative >= 0) cx.cells[negative].facets.push_back(fid);
    std::array<int, 3> lo{}, hi{};
    lo[axis] = hi[axis] = coord;
    lo[u] = uv_lo[0];
    lo[v] = uv_lo[1];
    hi[u] = uv_hi[0];
    hi[v] = uv_hi[1];
    out.facet_lo.push_back(lo);
    out.facet_hi.push_back(hi);
    out.facet_axis.push_back(axis);
    out.facet_area.push_back(double(uv_hi[0] - uv_lo[0]) * (uv_hi[1] - uv_lo[1]));
  };
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    std::map<int, std::vector<std::size_t>> starting_at;  // boxes by their low coordinate along axis
    for (std::size_t j = 0; j < boxes.size(); ++j) starting_at[boxes[j].lo[axis]].push_back(j);
    for (std::size_t i = 0; i < boxes.size(); ++i) {
      const IBox& a = boxes[i];
      if (a.lo[axis] == dlo[axis]) add_facet(axis, a.lo[axis], {a.lo[u], a.lo[v]}, {a.hi[u], a.hi[v]}, int(i), -1);
      if (a.hi[axis] == dhi[axis]) add_facet(axis, a.hi[axis], {a.lo[u], a.lo[v]}, {a.hi[u], a.hi[v]}, -1, int(i));
      const auto starting = starting_at.find(a.hi[axis]);
      if (starting == starting_at.end()) continue;
      for (std::size_t j : starting->second) {
        const IBox& b = boxes[j];
        const std::array<int, 2> lo = {std::max(a.lo[u], b.lo[u]), std::max(a.lo[v], b.lo[v])};
        const std::array<int, 2> hi = {std::min(a.hi[u], b.hi[u]), std::min(a.hi[v], b.hi[v])};
        if (lo[0] < hi[0] && lo[1] < hi[1]) add_facet(axis, a.hi[axis], lo, hi, int(j), int(i));
      }
    }
  }
  for (std::size_t c = 0; c < boxes.size(); ++c) {
    cx.cells[c].volume = Rational(boxes[c].volume());
    cx.cells[c].volume_approx = static_cast<double>(boxes[c].volume());  // "always set" (cell_complex.h)
    for (int k = 0; k < 3; ++k) cx.cells[c].centroid[k] = 0.5 * (boxes[c].lo[k] + boxes[c].hi[k]);
  }
  cx.box_min = {Rational(dlo[0]), Rational(dlo[1]), Rational(dlo[2])};
  cx.box_max = {Rational(dhi[0]), Rational(dhi[1]), Rational(dhi[2])};
  cx.box.extend(Vec3(dlo[0], dlo[1], dlo[2]));
  cx.box.extend(Vec3(dhi[0], dhi[1], dhi[2]));
  return out;
}

/// The grid with the given cut coordinates per axis (cells ordered x fastest).
inline std::vector<IBox> grid_boxes(const std::vector<int>& xs, const std::vector<int>& ys, const std::vector<int>& zs) {
  std::vector<IBox> boxes;
  for (std::size_t k = 0; k + 1 < zs.size(); ++k)
    for (std::size_t j = 0; j + 1 < ys.size(); ++j)
      for (std::size_t i = 0; i + 1 < xs.size(); ++i) boxes.push_back({{xs[i], ys[j], zs[k]}, {xs[i + 1], ys[j + 1], zs[k + 1]}});
  return boxes;
}

inline std::vector<int> iota_coords(int n) {
  std::vector<int> c(n + 1);
  for (int i = 0; i <= n; ++i) c[i] = i;
  return c;
}

/// A set of unit voxels (the ground-truth solid).
using VoxelSet = std::set<std::array<int, 3>>;

/// Random kd-tree tiling of [0,n)^3 by integer boxes, each box homogeneous w.r.t. `solid`; split positions
/// are random, so neighbouring boxes generally do not share whole faces (T-junctions everywhere).
inline std::vector<IBox> kd_boxes(const std::array<int, 3>& n, const VoxelSet& solid, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<IBox> out;
  std::vector<IBox> stack{{{0, 0, 0}, n}};
  while (!stack.empty()) {
    IBox b = stack.back();
    stack.pop_back();
    long in = 0;
    for (int x = b.lo[0]; x < b.hi[0]; ++x)
      for (int y = b.lo[1]; y < b.hi[1]; ++y)
        for (int z = b.lo[2]; z < b.hi[2]; ++z) in += solid.count({x, y, z});
    const bool homogeneous = in == 0 || in == b.volume();
    if (b.volume() == 1 || (homogeneous && rng() % 3 == 0)) {
      out.push_back(b);
      continue;
    }
    int axis;
    do axis = static_cast<int>(rng() % 3);
    while (b.hi[axis] - b.lo[axis] < 2);
    const int cut = b.lo[axis] + 1 + static_cast<int>(rng() % (b.hi[axis] - b.lo[axis] - 1));
    IBox lo = b, hi = b;
    lo.hi[axis] = cut;
    hi.lo[axis] = cut;
    stack.push_back(lo);
    stack.push_back(hi);
  }
  return out;
}

inline bool box_in_solid(const IBox& b, const VoxelSet& solid) {
  return solid.count({b.lo[0], b.lo[1], b.lo[2]}) > 0;  // boxes are homogeneous
}

/// Samples m x m points on every facet between a "truth inside" cell and an outside cell, normals pointing
/// outward, each tagged with its plane's input id.
struct Samples {
  PointCloud cloud;
  std::vector<int> plane;
};
inline void sample_facet(const BoxComplex& bc, std::size_t f, int m, const Vec3& normal, Samples& s) {
  const int axis = bc.facet_axis[f], u = (axis + 1) % 3, v = (axis + 2) % 3;
  const auto& lo = bc.facet_lo[f];
  const auto& hi = bc.facet_hi[f];
  const auto it = bc.input_id.find({axis, lo[axis]});
  const int id = it == bc.input_id.end() ? -1 : it->second;
  const int mu = std::max(1, m * (hi[u] - lo[u])), mv = std::max(1, m * (hi[v] - lo[v]));
  for (int i = 0; i < mu; ++i)
    for (int j = 0; j < mv; ++j) {
      Vec3 p;
      p[axis] = lo[axis];
      p[u] = lo[u] + (hi[u] - lo[u]) * (i + 0.5) / mu;
      p[v] = lo[v] + (hi[v] - lo[v]) * (j + 0.5) / mv;
      s.cloud.points.push_back(p);
      s.cloud.normals.push_back(normal);
      s.plane.push_back(id);
    }
}
inline Samples sample_boundary(const BoxComplex& bc, const std::vector<bool>& truth, int m) {
  Samples s;
  for (std::size_t f = 0; f < bc.cx.facets.size(); ++f) {
    const auto& cells = bc.cx.facets[f].cells;
    const bool pos_in = cells[0] >= 0 && truth[cells[0]];
    const bool neg_in = cells[1] >= 0 && truth[cells[1]];
    if (pos_in == neg_in) continue;
    const Vec3 axis_dir = Vec3::Unit(bc.facet_axis[f]);
    sample_facet(bc, f, m, pos_in ? Vec3(-axis_dir) : axis_dir, s);
  }
  return s;
}

// ------------------------------------------------------------------------------------------------ mesh checks

/// Every directed edge used exactly once and its reverse exactly once: closed, manifold edges, oriented.
inline bool closed_and_oriented(const PolygonMesh& mesh) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  for (const auto& f : mesh.faces)
    for (std::size_t i = 0; i < f.size(); ++i) ++directed[{f[i], f[(i + 1) % f.size()]}];
  for (const auto& [e, n] : directed) {
    if (n != 1) return false;
    const auto it = directed.find({e.second, e.first});
    if (it == directed.end() || it->second != 1) return false;
  }
  return !directed.empty();
}

/// Around every vertex the faces form one fan (one cycle of faces linked by shared edges at the vertex).
inline bool vertices_are_manifold(const PolygonMesh& mesh) {
  std::map<std::uint32_t, std::vector<std::size_t>> faces_at;
  for (std::size_t f = 0; f < mesh.faces.size(); ++f)
    for (auto v : mesh.faces[f]) faces_at[v].push_back(f);
  for (const auto& [v, faces] : faces_at) {
    // faces are linked at v when they share an edge incident to v
    std::map<std::uint32_t, std::vector<std::size_t>> by_other_end;
    for (std::size_t i = 0; i < faces.size(); ++i) {
      const auto& f = mesh.faces[faces[i]];
      const std::size_t n = f.size();
      const std::size_t k = std::find(f.begin(), f.end(), v) - f.begin();
      by_other_end[f[(k + 1) % n]].push_back(i);
      by_other_end[f[(k + n - 1) % n]].push_back(i);
    }
    std::vector<std::size_t> parent(faces.size());
    for (std::size_t i = 0; i < parent.size(); ++i) parent[i] = i;
    std::function<std::size_t(std::size_t)> find = [&](std::size_t x) { return parent[x] == x ? x : parent[x] = find(parent[x]); };
    for (const auto& [w, list] : by_other_end)
      for (std::size_t i = 1; i < list.size(); ++i) parent[find(list[i])] = find(list[0]);
    std::size_t roots = 0;
    for (std::size_t i = 0; i < parent.size(); ++i) roots += find(i) == i;
    if (roots != 1) return false;
  }
  return true;
}

inline double enclosed_volume(const PolygonMesh& mesh) {
  double v = 0;
  for (const auto& f : mesh.faces)
    for (std::size_t i = 1; i + 1 < f.size(); ++i)
      v += mesh.vertices[f[0]].dot(mesh.vertices[f[i]].cross(mesh.vertices[f[i + 1]])) / 6.0;
  return v;
}

inline bool has_repeated_vertex(const std::vector<std::uint32_t>& face) {
  std::set<std::uint32_t> s(face.begin(), face.end());
  return s.size() != face.size();
}

/// Planar face is simple: no repeated vertex and no two non-adjacent edges touching (exact for integer
/// coordinates; projects along the dominant axis of the Newell normal).
inline bool face_is_simple(const PolygonMesh& mesh, const std::vector<std::uint32_t>& face) {
  if (face.size() < 3 || has_repeated_vertex(face)) return false;
  Vec3 normal = Vec3::Zero();
  for (std::size_t i = 0; i < face.size(); ++i) normal += mesh.vertices[face[i]].cross(mesh.vertices[face[(i + 1) % face.size()]]);
  int k;
  normal.cwiseAbs().maxCoeff(&k);
  auto p2 = [&](std::uint32_t v) { return Vec2(mesh.vertices[v][(k + 1) % 3], mesh.vertices[v][(k + 2) % 3]); };
  auto orient = [](const Vec2& a, const Vec2& b, const Vec2& c) {
    const double d = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
    return (d > 0) - (d < 0);
  };
  auto on_segment = [&](const Vec2& a, const Vec2& b, const Vec2& p) {
    return orient(a, b, p) == 0 && std::min(a.x(), b.x()) <= p.x() && p.x() <= std::max(a.x(), b.x()) &&
           std::min(a.y(), b.y()) <= p.y() && p.y() <= std::max(a.y(), b.y());
  };
  const std::size_t n = face.size();
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j) {
      if (j == i + 1 || (i == 0 && j == n - 1)) continue;  // adjacent edges share one vertex
      const Vec2 a = p2(face[i]), b = p2(face[(i + 1) % n]), c = p2(face[j]), d = p2(face[(j + 1) % n]);
      const int o1 = orient(a, b, c), o2 = orient(a, b, d), o3 = orient(c, d, a), o4 = orient(c, d, b);
      if (o1 * o2 < 0 && o3 * o4 < 0) return false;
      if (on_segment(a, b, c) || on_segment(a, b, d) || on_segment(c, d, a) || on_segment(c, d, b)) return false;
    }
  return true;
}

/// No mesh vertex lies strictly inside an edge of a face (exact for integer coordinates).
inline bool t_junction_free(const PolygonMesh& mesh) {
  for (const auto& f : mesh.faces)
    for (std::size_t i = 0; i < f.size(); ++i) {
      const Vec3& a = mesh.vertices[f[i]];
      const Vec3& b = mesh.vertices[f[(i + 1) % f.size()]];
      for (std::size_t w = 0; w < mesh.vertices.size(); ++w) {
        const Vec3& p = mesh.vertices[w];
        if ((b - a).cross(p - a).squaredNorm() != 0) continue;
        const double t = (p - a).dot(b - a);
        if (t > 0 && t < (b - a).squaredNorm()) return false;
      }
    }
  return true;
}

/// Number of faces the union of `solid` should have after merging: connected components (4-neighbour,
/// same plane, same orientation) of its boundary unit squares. Valid when no merged region has a hole.
inline std::size_t expected_face_count(const VoxelSet& solid) {
  // A boundary square: (axis, coordinate along axis, u, v, outward sign).
  std::set<std::array<int, 5>> squares;
  for (const auto& c : solid)
    for (int axis = 0; axis < 3; ++axis)
      for (int s : {-1, 1}) {
        auto nb = c;
        nb[axis] += s;
        if (solid.count(nb)) continue;
        const int u = (axis + 1) % 3, v = (axis + 2) % 3;
        squares.insert({axis, s > 0 ? c[axis] + 1 : c[axis], c[u], c[v], s});
      }
  std::set<std::array<int, 5>> seen;
  std::size_t components = 0;
  for (const auto& sq : squares) {
    if (seen.count(sq)) continue;
    ++components;
    std::vector<std::array<int, 5>> stack{sq};
    seen.insert(sq);
    while (!stack.empty()) {
      auto cur = stack.back();
      stack.pop_back();
      for (auto [du, dv] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
        auto nb = cur;
        nb[2] += du;
        nb[3] += dv;
        if (squares.count(nb) && !seen.count(nb)) {
          seen.insert(nb);
          stack.push_back(nb);
        }
      }
    }
  }
  return components;
}

}  // namespace hsr::test
