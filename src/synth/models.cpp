// The procedural models of the synth stage, built by exact CSG (CGAL Nef polyhedra) from convex pieces
// (boxes and gable prisms), so every model is a closed 2-manifold by construction: no hand-made vertex
// lists to get wrong, T-junctions resolved by the arrangement, coplanar touching pieces merged.
// The exact result is then expressed with convex planar faces (CGAL triangulates each face, we merge the
// triangles back greedily into convex polygons), because downstream code fan-triangulates faces.
#include "synth/synth_internal.h"

#include "core/error.h"

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Nef_polyhedron_3.h>
#include <CGAL/Polyhedron_3.h>
#include <CGAL/boost/graph/convert_nef_polyhedron_to_polygon_mesh.h>
#include <CGAL/convex_hull_3.h>
#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <Eigen/Geometry>

#include <array>
#include <cmath>
#include <functional>
#include <map>
#include <random>

namespace hsr::synth_detail {
namespace {

using K = CGAL::Exact_predicates_exact_constructions_kernel;
using Nef = CGAL::Nef_polyhedron_3<K>;
using Poly = CGAL::Polyhedron_3<K>;
using Epick = CGAL::Exact_predicates_inexact_constructions_kernel;

Nef convex_hull_of(const std::vector<Vec3>& corners) {
  std::vector<K::Point_3> pts;
  for (const Vec3& c : corners) pts.emplace_back(c.x(), c.y(), c.z());
  Poly poly;
  CGAL::convex_hull_3(pts.begin(), pts.end(), poly);
  return Nef(poly);
}

Nef box(double x0, double x1, double y0, double y1, double z0, double z1) {
  std::vector<Vec3> c;
  for (double x : {x0, x1})
    for (double y : {y0, y1})
      for (double z : {z0, z1}) c.emplace_back(x, y, z);
  return convex_hull_of(c);
}

/// Gable-roofed block: walls from z0 up to `eave`, roof ridge at height `ridge` running along x, centred in y.
Nef gable_along_x(double x0, double x1, double y0, double y1, double z0, double eave, double ridge) {
  const double ym = 0.5 * (y0 + y1);
  std::vector<Vec3> c;
  for (double x : {x0, x1}) {
    c.emplace_back(x, y0, z0); c.emplace_back(x, y1, z0);
    c.emplace_back(x, y0, eave); c.emplace_back(x, y1, eave);
    c.emplace_back(x, ym, ridge);
  }
  return convex_hull_of(c);
}

/// Same, ridge running along y, centred in x.
Nef gable_along_y(double x0, double x1, double y0, double y1, double z0, double eave, double ridge) {
  const double xm = 0.5 * (x0 + x1);
  std::vector<Vec3> c;
  for (double y : {y0, y1}) {
    c.emplace_back(x0, y, z0); c.emplace_back(x1, y, z0);
    c.emplace_back(x0, y, eave); c.emplace_back(x1, y, eave);
    c.emplace_back(xm, y, ridge);
  }
  return convex_hull_of(c);
}

/// Cross-gable L house: two 6 m wide wings, eaves at 3 m, ridges at 6 m, meeting in two valleys.
Nef make_house() {
  Nef main_wing = gable_along_x(0, 10, 0, 6, 0, 3, 6);
  // The second wing starts under the main ridge (y = 3), so its gable end is hidden inside the main wing.
  Nef side_wing = gable_along_y(4, 10, 3, 14, 0, 3, 6);
  return main_wing + side_wing;
}

/// Gable house with one gabled dormer on the south slope and one chimney through the north slope.
Nef make_dormer_house() {
  Nef house = gable_along_x(0, 12, 0, 8, 0, 3, 7);        // south slope z = 3 + y, north z = 11 - y
  Nef dormer = gable_along_y(4, 7, 1.5, 3.8, 3, 5.5, 6.5); // its back end stays below the main roof
  Nef chimney = box(9, 9.8, 5, 5.8, 5, 8.5);               // bottom below the north slope, top above the ridge
  return house + dormer + chimney;
}

/// Stepped bracket (base plate, step, upright) extruded along y, with a rectangular slot through the base.
Nef make_bracket() {
  Nef profile = box(0, 8, 0, 4, 0, 1) + box(0, 5, 0, 4, 1, 2.5) + box(0, 1.5, 0, 4, 2.5, 5);
  return profile - box(5.8, 7.2, 1.2, 2.8, -1, 2);
}

/// The interior air of an 8 x 6 x 3 room holding a table (top + 4 legs) and a floor-to-ceiling pillar.
Nef make_room() {
  Nef table = box(2, 4.4, 1.5, 3, 0.72, 0.78);
  for (double x : {2.05, 4.27})
    for (double y : {1.55, 2.87}) table += box(x, x + 0.08, y, y + 0.08, 0, 0.72);
  Nef pillar = box(5.5, 6, 3.5, 4, 0, 3);
  return box(0, 8, 0, 6, 0, 3) - table - pillar;
}

/// Two buildings around a courtyard (about [6,18] x [6,18]): a flat-roofed L block and a gable block with
/// a lower flat-roofed wing.
Nef make_courtyard() {
  Nef west_block = box(0, 16, 0, 6, 0, 7) + box(0, 6, 6, 16, 0, 7);
  Nef east_block = gable_along_x(6, 24, 18, 24, 0, 6, 9) + box(18, 24, 6, 18, 0, 5);
  return west_block + east_block;
}

// ---------------------------------------------------------------------------------------------------------
// Aerial building models (metres, z up, standing on z = 0): several blocks with different eave heights,
// flat / gable / hip / shed roofs, touching and overlapping, dormers. Built axis-aligned from convex pieces
// (exact CSG), then turned about z and moved by the caller; the seed draws the dimensions.

/// The nearest value on the 0.1 m grid. Every coordinate of the aerial models is on it, sums included, so
/// heights that are equal as decimals are equal as doubles (near-equal ones would leave 1e-15 slivers in
/// the exact union).
double dm(double x) { return std::round(10.0 * x) / 10.0; }
/// Lengths are drawn on the 0.1 m grid: short exact decimals keep the CSG's rationals small.
double draw_dm(std::mt19937_64& rng, double lo, double hi) { return dm(draw(rng, lo, hi)); }

/// Height a roof of pitch drawn in [lo_deg, hi_deg] gains over `run` metres (on the 0.1 m grid, >= 0.5 m).
double rise_over(std::mt19937_64& rng, double run, double lo_deg, double hi_deg) {
  return std::max(0.5, dm(run * std::tan(draw(rng, lo_deg, hi_deg) * M_PI / 180.0)));
}

/// Hip-roofed block: walls up to `eave`, four roof faces of equal pitch meeting in a ridge along x.
Nef hip_along_x(double x0, double x1, double y0, double y1, double z0, double eave, double ridge) {
  const double ym = 0.5 * (y0 + y1), inset = std::min(0.5 * (y1 - y0), 0.45 * (x1 - x0));
  std::vector<Vec3> c;
  for (double x : {x0, x1})
    for (double y : {y0, y1}) {
      c.emplace_back(x, y, z0);
      c.emplace_back(x, y, eave);
    }
  c.emplace_back(x0 + inset, ym, ridge);
  c.emplace_back(x1 - inset, ym, ridge);
  return convex_hull_of(c);
}

/// Shed (mono-pitch) block: eave `low` along y = y0, `high` along y = y1.
Nef shed_along_x(double x0, double x1, double y0, double y1, double z0, double low, double high) {
  std::vector<Vec3> c;
  for (double x : {x0, x1}) {
    c.emplace_back(x, y0, z0); c.emplace_back(x, y1, z0);
    c.emplace_back(x, y0, low); c.emplace_back(x, y1, high);
  }
  return convex_hull_of(c);
}

/// Flat-roofed blocks: a main block and one or two others, lower or higher, overlapping or touching it.
Nef make_aerial_flat(std::mt19937_64& rng) {
  const double L = draw_dm(rng, 12, 24), W = draw_dm(rng, 8, 14), H = draw_dm(rng, 4, 12);
  Nef b = box(0, L, 0, W, 0, H);
  const double l2 = draw_dm(rng, 5, 0.6 * L), w2 = draw_dm(rng, 4, 9), h2 = draw_dm(rng, 3, H + 4);
  const double x2 = draw_dm(rng, 0, L - l2);
  b += box(x2, dm(x2 + l2), dm(W - draw_dm(rng, 0, 2)), dm(W + w2), 0, std::abs(h2 - H) < 1 ? dm(H + 1.5) : h2);  // overlapping
  if (rng() % 2) {  // a low annex touching the west side
    const double w3 = draw_dm(rng, 3, W - 1), y3 = draw_dm(rng, 0, W - w3);
    b += box(-draw_dm(rng, 3, 6), 0, y3, dm(y3 + w3), 0, draw_dm(rng, 2.5, std::max(2.6, H - 1.5)));
  }
  return b;
}

/// Gable main block with a perpendicular lower gable wing (T or L).
Nef make_aerial_gable(std::mt19937_64& rng) {
  const double L = draw_dm(rng, 12, 20), W = draw_dm(rng, 7, 11), eave = draw_dm(rng, 3, 7);
  const double ridge = dm(eave + rise_over(rng, 0.5 * W, 20, 50));
  Nef b = gable_along_x(0, L, 0, W, 0, eave, ridge);
  const double w2 = draw_dm(rng, 5, W - 1), x2 = draw_dm(rng, 0, L - w2), e2 = draw_dm(rng, 2.6, eave);
  const double r2 = dm(std::min(ridge - 0.8, e2 + rise_over(rng, 0.5 * w2, 20, 45)));
  b += gable_along_y(x2, dm(x2 + w2), dm(0.5 * W), dm(W + draw_dm(rng, 4, 9)), 0, e2, dm(std::max(r2, e2 + 1.0)));
  return b;
}

/// Hip-roofed main block with a flat-roofed garage beside it.
Nef make_aerial_hip(std::mt19937_64& rng) {
  const double L = draw_dm(rng, 12, 20), W = draw_dm(rng, 8, 12), eave = draw_dm(rng, 3, 7);
  Nef b = hip_along_x(0, L, 0, W, 0, eave, dm(eave + rise_over(rng, 0.5 * W, 20, 45)));
  const double gw = draw_dm(rng, 3.5, 6), gl = draw_dm(rng, 5, 8);
  b += box(L, dm(L + gw), draw_dm(rng, 0, W - gl > 0 ? W - gl : 0.1), W, 0, draw_dm(rng, 2.5, 3.2));
  return b;
}

/// Two shed-roofed blocks side by side at different heights (a step edge between them).
Nef make_aerial_shed(std::mt19937_64& rng) {
  const double L = draw_dm(rng, 10, 18), W = draw_dm(rng, 6, 10), low = draw_dm(rng, 3, 6);
  Nef b = shed_along_x(0, L, 0, W, 0, low, dm(low + draw_dm(rng, 1, 3)));
  const double L2 = draw_dm(rng, 6, L), low2 = dm(low + draw_dm(rng, 2, 4));
  b += shed_along_x(draw_dm(rng, 0, L - L2), L, W, dm(W + draw_dm(rng, 5, 9)), 0, dm(low2 + draw_dm(rng, 1, 2.5)), low2);
  return b;
}

/// Gable house with one or two gabled dormers on the south slope.
Nef make_aerial_dormer(std::mt19937_64& rng) {
  const double L = draw_dm(rng, 12, 18), W = draw_dm(rng, 8, 10), eave = draw_dm(rng, 3, 5);
  const double rise = rise_over(rng, 0.5 * W, 30, 50);  // south slope z = eave + y * (2 rise / W)
  Nef b = gable_along_x(0, L, 0, W, 0, eave, dm(eave + rise));
  const int dormers = 1 + static_cast<int>(rng() % 2);
  const double slope = 2.0 * rise / W;
  for (int d = 0; d < dormers; ++d) {
    const double dw = draw_dm(rng, 2.2, 3.2), x0 = (d + 0.5) * L / dormers - 0.5 * dw;
    const double y0 = draw_dm(rng, 1.0, 1.6);
    const double depth = std::min(draw_dm(rng, 2.0, 2.6), 0.5 * W - 0.2 - y0);  // stays on the south slope
    const double front = eave + y0 * slope;  // roof height at the dormer's front wall
    // Its walls and ridge stay under the main roof at its back end (0.2 m below), so it ends in the slope.
    const double room = depth * slope - 0.2;
    double wall = draw_dm(rng, 1.0, 1.4), rise_d = 0.4 * dw;
    if (wall + rise_d > room) {
      const double k = room / (wall + rise_d);
      wall *= k;
      rise_d *= k;
    }
    b += gable_along_y(x0, x0 + dw, y0, y0 + depth, front - 0.5, front + wall, front + wall + rise_d);
  }
  return b;
}

/// L-shaped block: a flat-roofed wing, a gable wing and a hip-roofed corner block of their own heights.
Nef make_aerial_mixed(std::mt19937_64& rng) {
  const double W = draw_dm(rng, 7, 10), L1 = draw_dm(rng, 12, 18), L2 = draw_dm(rng, 10, 16);
  const double e1 = draw_dm(rng, 5, 9), e2 = draw_dm(rng, 3, 5);
  Nef b = box(0, L1, 0, W, 0, e1);
  b += gable_along_y(dm(L1 - W), L1, W, dm(W + L2), 0, e2, dm(e2 + rise_over(rng, 0.5 * W, 20, 45)));
  const double e3 = draw_dm(rng, 3, 6);
  b += hip_along_x(dm(L1 - 1), dm(L1 + draw_dm(rng, 6, 9)), -1, dm(W + 1), 0, e3, dm(e3 + rise_over(rng, 0.5 * W + 1, 20, 45)));
  return b;
}

/// A small house with a steep gable or hip roof (45-60 degrees, the south German houses of Vaihingen) and
/// now and then a lower flat-roofed shed against one gable end.
Nef make_aerial_steep(std::mt19937_64& rng) {
  const double L = draw_dm(rng, 9, 15), W = draw_dm(rng, 7, 10), eave = draw_dm(rng, 3, 6);
  const double ridge = dm(eave + rise_over(rng, 0.5 * W, 45, 60));
  Nef b = rng() % 2 ? gable_along_x(0, L, 0, W, 0, eave, ridge) : hip_along_x(0, L, 0, W, 0, eave, ridge);
  if (rng() % 2) b += box(L, dm(L + draw_dm(rng, 3, 5)), 0, draw_dm(rng, 4, W), 0, draw_dm(rng, 2.5, eave - 0.3));
  return b;
}

/// Turns the model about the z axis by `angle` and moves it by `shift` (double rounding only: every face
/// stays planar to ~1e-15 relative, far below the tolerance that groups faces into planes).
void turn_and_move(PolygonMesh& mesh, double angle, const Vec3& shift) {
  const Eigen::Matrix3d r = Eigen::AngleAxisd(angle, Vec3::UnitZ()).toRotationMatrix();
  for (Vec3& v : mesh.vertices) v = r * v + shift;
}

Vec3 face_normal(const std::vector<Vec3>& pts, const std::vector<std::uint32_t>& loop) {
  Vec3 n = Vec3::Zero();  // Newell's method
  for (std::size_t i = 0; i < loop.size(); ++i) n += pts[loop[i]].cross(pts[loop[(i + 1) % loop.size()]]);
  return n.normalized();
}

/// Greedily merges adjacent coplanar triangles into convex polygons, then starts each loop at a strictly
/// convex corner (so a fan from vertex 0 never starts with a zero-area triangle).
PolygonMesh merge_into_convex_faces(std::vector<Vec3> pts, std::vector<std::vector<std::uint32_t>> faces) {
  const double scale = bounding_box(pts).diagonal();
  const double eps = 1e-12 * scale * scale;
  std::vector<Vec3> normals;
  for (const auto& f : faces) normals.push_back(face_normal(pts, f));
  std::vector<bool> alive(faces.size(), true);
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> edge_face;
  auto index_edges = [&](int f) {
    const auto& loop = faces[f];
    for (std::size_t i = 0; i < loop.size(); ++i) edge_face[{loop[i], loop[(i + 1) % loop.size()]}] = f;
  };
  for (int f = 0; f < static_cast<int>(faces.size()); ++f) index_edges(f);

  auto convex = [&](const std::vector<std::uint32_t>& loop, const Vec3& n) {
    for (std::size_t i = 0; i < loop.size(); ++i) {
      const Vec3& a = pts[loop[(i + loop.size() - 1) % loop.size()]];
      const Vec3& b = pts[loop[i]];
      const Vec3& c = pts[loop[(i + 1) % loop.size()]];
      if ((b - a).cross(c - b).dot(n) < -eps) return false;
    }
    return true;
  };
  // Loop of `f` rotated to start at `start` (an index into the loop).
  auto rotated = [](const std::vector<std::uint32_t>& loop, std::size_t start) {
    std::vector<std::uint32_t> r(loop.begin() + start, loop.end());
    r.insert(r.end(), loop.begin(), loop.begin() + start);
    return r;
  };

  bool changed = true;
  while (changed) {
    changed = false;
    for (int f = 0; f < static_cast<int>(faces.size()); ++f) {
      if (!alive[f]) continue;
      for (std::size_t i = 0; i < faces[f].size(); ++i) {
        const std::uint32_t u = faces[f][i], v = faces[f][(i + 1) % faces[f].size()];
        auto it = edge_face.find({v, u});
        if (it == edge_face.end()) continue;
        const int g = it->second;
        if (g == f || !alive[g] || normals[f].dot(normals[g]) < 1.0 - 1e-12) continue;
        // f = v ... u (after rotation), g = u ... v; merged = f's loop + g's interior vertices.
        std::vector<std::uint32_t> pf = rotated(faces[f], (i + 1) % faces[f].size());
        const auto& lg = faces[g];
        std::size_t gu = std::find(lg.begin(), lg.end(), u) - lg.begin();
        std::vector<std::uint32_t> pg = rotated(lg, gu);
        if (pg.size() < 2 || pg.back() != v) continue;
        std::vector<std::uint32_t> merged = pf;
        merged.insert(merged.end(), pg.begin() + 1, pg.end() - 1);
        std::vector<std::uint32_t> sorted = merged;
        std::sort(sorted.begin(), sorted.end());
        if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) continue;
        if (!convex(merged, normals[f])) continue;
        for (std::size_t k = 0; k < lg.size(); ++k) edge_face.erase({lg[k], lg[(k + 1) % lg.size()]});
        edge_face.erase({u, v});
        faces[f] = merged;
        alive[g] = false;
        index_edges(f);
        changed = true;
        i = static_cast<std::size_t>(-1);  // rescan the grown face
      }
    }
  }

  PolygonMesh mesh;
  mesh.vertices = std::move(pts);
  for (std::size_t f = 0; f < faces.size(); ++f) {
    if (!alive[f]) continue;
    const auto& loop = faces[f];
    std::size_t start = 0;
    double best = -1;
    for (std::size_t i = 0; i < loop.size(); ++i) {
      const Vec3& a = mesh.vertices[loop[(i + loop.size() - 1) % loop.size()]];
      const Vec3& b = mesh.vertices[loop[i]];
      const Vec3& c = mesh.vertices[loop[(i + 1) % loop.size()]];
      const double turn = (b - a).normalized().cross((c - b).normalized()).dot(normals[f]);
      if (turn > best + 1e-9) { best = turn; start = i; }
    }
    mesh.faces.push_back(rotated(loop, start));
  }
  return mesh;
}

/// Canonical convex faces of one planar region (a face of the exact solid, possibly non-convex or with
/// holes), given by its directed boundary edges. A convex single loop is kept as is; anything else is
/// triangulated by a constrained Delaunay triangulation built in a canonical insertion order (so the result
/// does not depend on CGAL's internal, address-dependent ordering) and merged back into convex pieces later.
void region_faces(const std::vector<Vec3>& pts, const std::vector<K::Point_3>& exact, const Vec3& normal,
                  std::vector<std::pair<std::uint32_t, std::uint32_t>> boundary,
                  std::vector<std::vector<std::uint32_t>>& out) {
  std::sort(boundary.begin(), boundary.end());
  // Single convex loop?
  std::map<std::uint32_t, std::uint32_t> next;
  bool simple = true;
  for (const auto& [u, v] : boundary) simple = next.emplace(u, v).second && simple;
  if (simple) {
    std::vector<std::uint32_t> loop{boundary.front().first};
    while (loop.size() <= boundary.size()) {
      const std::uint32_t v = next.at(loop.back());
      if (v == loop.front()) break;
      loop.push_back(v);
    }
    bool convex = loop.size() == boundary.size();
    for (std::size_t i = 0; convex && i < loop.size(); ++i) {
      const Vec3& a = pts[loop[(i + loop.size() - 1) % loop.size()]];
      const Vec3& b = pts[loop[i]];
      const Vec3& c = pts[loop[(i + 1) % loop.size()]];
      convex = (b - a).cross(c - b).dot(normal) >= -1e-12 * (b - a).norm() * (c - b).norm();
    }
    if (convex) {
      out.push_back(loop);
      return;
    }
  }
  // 2D coordinates: drop the dominant axis of the normal, keep a right-handed frame.
  int axis = 0;
  normal.cwiseAbs().maxCoeff(&axis);
  const int i0 = (axis + 1) % 3, i1 = (axis + 2) % 3;
  const bool flipped = normal[axis] < 0;
  // Exact: the CSG's vertices are rationals whose doubles are no longer collinear where they were, and a
  // double triangulation then keeps a sliver on the wrong side of the boundary (a non-manifold truth).
  using Vb = CGAL::Triangulation_vertex_base_with_info_2<std::uint32_t, K>;
  using Fb = CGAL::Constrained_triangulation_face_base_2<K>;
  using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
  using Cdt = CGAL::Constrained_Delaunay_triangulation_2<K, Tds, CGAL::Exact_predicates_tag>;
  auto coord = [&](std::uint32_t v, int i) { return i == 0 ? exact[v].x() : i == 1 ? exact[v].y() : exact[v].z(); };
  auto p2 = [&](std::uint32_t v) { return K::Point_2(coord(v, i0), coord(v, i1)); };
  Cdt cdt;
  std::map<std::uint32_t, Cdt::Vertex_handle> handle;
  for (const auto& [u, v] : boundary)
    for (std::uint32_t w : {u, v})
      if (!handle.count(w)) {
        handle[w] = cdt.insert(p2(w));
        handle[w]->info() = w;
      }
  for (const auto& [u, v] : boundary) cdt.insert_constraint(handle[u], handle[v]);
  // Inside by the even-odd rule on the boundary (holes included): the parity of the constrained edges
  // crossed from the infinite face, found by one flood over the triangulation (linear in its size).
  std::map<Cdt::Face_handle, int> parity;
  std::vector<Cdt::Face_handle> stack{cdt.infinite_face()};
  parity[cdt.infinite_face()] = 0;
  while (!stack.empty()) {
    const Cdt::Face_handle f = stack.back();
    stack.pop_back();
    for (int i = 0; i < 3; ++i) {
      const Cdt::Face_handle g = f->neighbor(i);
      if (parity.count(g)) continue;
      parity[g] = parity[f] ^ (cdt.is_constrained({f, i}) ? 1 : 0);
      stack.push_back(g);
    }
  }
  for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
    if (parity.at(f) == 0) continue;
    std::vector<std::uint32_t> tri{f->vertex(0)->info(), f->vertex(1)->info(), f->vertex(2)->info()};
    if (flipped) std::swap(tri[1], tri[2]);  // CDT faces are counter-clockwise in the (i0, i1) frame
    out.push_back(tri);
  }
}

/// The convex faces of planar regions over canonically ordered vertices (`exact`: each vertex's exact
/// value), regions taken in a canonical order: by their sorted boundary edges.
PolygonMesh convex_faces_of_regions(std::vector<Vec3> pts, const std::vector<K::Point_3>& exact,
                                    std::vector<PlanarRegion> regions) {
  for (PlanarRegion& r : regions) std::sort(r.boundary.begin(), r.boundary.end());
  std::sort(regions.begin(), regions.end(), [](const auto& a, const auto& b) { return a.boundary < b.boundary; });
  std::vector<std::vector<std::uint32_t>> faces;
  for (const PlanarRegion& r : regions) region_faces(pts, exact, r.normal, r.boundary, faces);
  return merge_into_convex_faces(std::move(pts), std::move(faces));
}

PolygonMesh to_mesh(Nef nef) {
  nef = nef.regularization();  // differences leave lower-dimensional residue where pieces touch
  HSR_ASSERT(nef.is_simple(), "synth model is not a 2-manifold");
  std::vector<K::Point_3> exact_points;
  std::vector<std::vector<std::size_t>> polygons;
  CGAL::convert_nef_polyhedron_to_polygon_soup(nef, exact_points, polygons, /*triangulate_all_faces=*/false);
  // Canonical vertex order (lexicographic), so nothing below depends on CGAL's address-dependent order.
  std::vector<std::array<double, 3>> keys;
  for (const auto& p : exact_points)
    keys.push_back({CGAL::to_double(p.x()), CGAL::to_double(p.y()), CGAL::to_double(p.z())});
  std::vector<std::array<double, 3>> sorted_keys = keys;
  std::sort(sorted_keys.begin(), sorted_keys.end());
  sorted_keys.erase(std::unique(sorted_keys.begin(), sorted_keys.end()), sorted_keys.end());
  std::vector<Vec3> pts;
  for (const auto& k : sorted_keys) pts.emplace_back(k[0], k[1], k[2]);
  std::vector<std::vector<std::uint32_t>> items;
  for (const auto& poly : polygons) {
    std::vector<std::uint32_t> f;
    for (std::size_t v : poly)
      f.push_back(static_cast<std::uint32_t>(std::lower_bound(sorted_keys.begin(), sorted_keys.end(), keys[v]) -
                                             sorted_keys.begin()));
    items.push_back(std::move(f));
  }
  // Planar regions: items connected across an edge with the same normal (= one face of the exact solid).
  std::vector<Vec3> normals;
  for (const auto& f : items) normals.push_back(face_normal(pts, f));
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::size_t> edge_item;
  for (std::size_t i = 0; i < items.size(); ++i)
    for (std::size_t k = 0; k < items[i].size(); ++k) edge_item[{items[i][k], items[i][(k + 1) % items[i].size()]}] = i;
  std::vector<std::size_t> region(items.size());
  for (std::size_t i = 0; i < items.size(); ++i) region[i] = i;
  std::function<std::size_t(std::size_t)> find = [&](std::size_t i) { return region[i] == i ? i : region[i] = find(region[i]); };
  for (const auto& [e, i] : edge_item) {
    auto it = edge_item.find({e.second, e.first});
    if (it != edge_item.end() && normals[i].dot(normals[it->second]) > 1.0 - 1e-12) region[find(i)] = find(it->second);
  }
  std::map<std::size_t, PlanarRegion> boundary_of;
  for (const auto& [e, i] : edge_item) {
    auto it = edge_item.find({e.second, e.first});
    if (it == edge_item.end() || find(it->second) != find(i)) boundary_of[find(i)].boundary.push_back(e);
  }
  std::vector<PlanarRegion> regions;
  for (auto& [r, region] : boundary_of) {
    region.normal = normals[r];
    regions.push_back(std::move(region));
  }
  std::vector<K::Point_3> exact_of(pts.size());  // one exact point per (deduplicated) double vertex
  for (std::size_t i = 0; i < exact_points.size(); ++i)
    exact_of[static_cast<std::size_t>(std::lower_bound(sorted_keys.begin(), sorted_keys.end(), keys[i]) - sorted_keys.begin())] =
        exact_points[i];
  return convex_faces_of_regions(std::move(pts), exact_of, std::move(regions));
}

}  // namespace

PolygonMesh mesh_of_regions(const std::vector<Vec3>& vertices, std::vector<PlanarRegion> regions) {
  // Canonical vertex order (lexicographic), as to_mesh's.
  std::vector<std::uint32_t> order(vertices.size());
  for (std::uint32_t i = 0; i < order.size(); ++i) order[i] = i;
  auto key = [&](std::uint32_t i) { return std::array<double, 3>{vertices[i].x(), vertices[i].y(), vertices[i].z()}; };
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return key(a) < key(b); });
  std::vector<std::uint32_t> rank(vertices.size());
  std::vector<Vec3> pts;
  std::vector<K::Point_3> exact;
  for (std::uint32_t i = 0; i < order.size(); ++i) {
    HSR_ASSERT(i == 0 || key(order[i - 1]) < key(order[i]), "mesh_of_regions: repeated vertex");
    rank[order[i]] = i;
    pts.push_back(vertices[order[i]]);
    exact.emplace_back(pts.back().x(), pts.back().y(), pts.back().z());
  }
  for (PlanarRegion& r : regions)
    for (auto& [u, v] : r.boundary) {
      u = rank[u];
      v = rank[v];
    }
  return convex_faces_of_regions(std::move(pts), exact, std::move(regions));
}

std::optional<Model> build_model(const std::string& name, const SynthParams& params) {
  if (std::optional<Model> indoor = build_indoor_model(name, params)) return indoor;
  const std::uint64_t seed = params.seed;
  Model m;
  static const std::map<std::string, Nef (*)(std::mt19937_64&)> aerial = {
      {"aerial_flat", make_aerial_flat},     {"aerial_gable", make_aerial_gable}, {"aerial_hip", make_aerial_hip},
      {"aerial_shed", make_aerial_shed},     {"aerial_dormer", make_aerial_dormer},
      {"aerial_mixed", make_aerial_mixed},   {"aerial_steep", make_aerial_steep}};
  if (const auto it = aerial.find(name); it != aerial.end()) {
    // The model's own generator, seeded from the scan seed and the name (so models differ for one seed).
    std::uint64_t name_hash = 1469598103934665603ull;  // FNV-1a: the same on every platform
    for (unsigned char ch : name) name_hash = (name_hash ^ ch) * 1099511628211ull;
    std::mt19937_64 rng(seed * 0x9E3779B97F4A7C15ull ^ name_hash);
    m.mesh = to_mesh(it->second(rng));
    turn_and_move(m.mesh, draw(rng, 0.0, M_PI), Vec3(draw_dm(rng, -50, 50), draw_dm(rng, -50, 50), 0));
    m.aerial = true;
    return m;
  }
  const double h = 1.7;  // terrestrial scanner height above the ground (m)
  if (name == "box") {
    m.mesh = to_mesh(box(0, 4, 0, 3, 0, 2));
    m.scanners = {{-3, -2.5, h}, {7.5, -2, h}, {6.5, 5.5, h}, {-2.5, 5, h}, {2.3, 1.2, 10}};
  } else if (name == "house") {
    m.mesh = to_mesh(make_house());
    m.scanners = {{-6, -5, h}, {16, -4, h}, {16, 18, h}, {-4, 12, h}, {4.5, 6.5, 22}};
  } else if (name == "dormer_house") {
    m.mesh = to_mesh(make_dormer_house());
    m.scanners = {{-6, -6, h}, {18, -5, h}, {17, 14, h}, {-5, 13, h}, {6, 3, 20}};
  } else if (name == "bracket") {
    // A CAD part on a table: scanners all above the table plane (z = 0), units arbitrary.
    m.mesh = to_mesh(make_bracket());
    m.scanners = {{-6, -7, 4}, {12, -6, 6}, {13, 9, 3}, {-5, 10, 7}, {4, 2, 14}};
  } else if (name == "room") {
    m.mesh = to_mesh(make_room());
    m.scanners = {{1.2, 4.6, 1.6}, {6.8, 1.2, 1.4}};
    m.indoor = true;
  } else if (name == "courtyard") {
    m.mesh = to_mesh(make_courtyard());
    // One scanner in the courtyard (it sees the inner walls at close range), six outside, one aerial.
    m.scanners = {{11, 12.5, h}, {-7, 9, h}, {9, -7, h}, {31, 13, h}, {15, 31, h}, {29, -5, h}, {-5, 29, h},
                  {12, 12, 35}};
  } else {
    return std::nullopt;
  }
  return m;
}

}  // namespace hsr::synth_detail
