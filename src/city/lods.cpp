// LoD 1.2, LoD 1.3 and the attributes of one `hsr city` feature (lods.h).
//
// Attributes (names as 3DBAG's, docs.3dbag.nl/en/schema/attributes, where one exists; units: the tile's):
//   b3_h_maaiveld          ground height: the LoD 2.2 bottom (the child's --ground-z floored to the partition box's
//                          step, hsr_ground_z and hsr_ground_source say how it was found)
//   b3_h_dak_min/_50p/_70p/_max  roof heights over the plan (the LoD 2.2 roof heightmap's 2nd, 50th, 70th, 99th
//                          percentiles: roofer's min and max are its roof points' 2nd and 99th)
//   b3_dak_type            horizontal | multiple horizontal | slanted | no planes
//   b3_rmse_lod12/13/22    RMS distance of the building's points to each solid
//   b3_volume_lod12/13/22  volume of each solid
//   b3_puntdichtheid       points over the footprint (a group: the plan) per unit² (3DBAG suffixes its AHN version)
//   b3_nodata_fractie      share of the footprint's (a group: the plan's) cells without a point (3DBAG: _ahn3, _ahn4)
//   b3_reconstructie_onvolledig  doubtful: hsr_points_unexplained_share above its warning share
//   hsr_validity_lod12/13/22     "valid" or eval's failed checks (3DBAG's b3_val3dity_* hold val3dity codes)
//   hsr_lod13_parts, hsr_lod13_note  LoD 1.3's roof parts; why it is the LoD 1.2 block where it is
#include "city/lods.h"

#include "core/error.h"
#include "core/face_class.h"
#include "core/kd_tree.h"
#include "eval/eval.h"

#include <algorithm>
#include <tuple>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <numeric>
#include <set>
#include <sstream>

namespace hsr {

namespace {

constexpr double kPi = 3.14159265358979323846;
using PlanQ = std::array<std::int64_t, 2>;
using PlanRing = std::vector<std::uint32_t>;

/// Newell vector of a face: its normal times twice its area.
Vec3 newell(const PolygonMesh& m, std::size_t f) {
  Vec3 n = Vec3::Zero();
  const auto& ring = m.faces[f];
  for (std::size_t i = 0; i < ring.size(); ++i) {
    const Vec3& a = m.vertices[ring[i]];
    const Vec3& b = m.vertices[ring[(i + 1) % ring.size()]];
    n += Vec3((a.y() - b.y()) * (a.z() + b.z()), (a.z() - b.z()) * (a.x() + b.x()), (a.x() - b.x()) * (a.y() + b.y()));
  }
  return n;
}

double slope_deg(const Vec3& n) { return std::acos(std::clamp(n.z() / n.norm(), -1.0, 1.0)) * 180.0 / kPi; }

/// True when plan points p and r are within `snap` steps of each other (in x and in y).
bool plan_near(const PlanQ& p, const PlanQ& r, std::int64_t snap) {
  return std::llabs(p[0] - r[0]) <= snap && std::llabs(p[1] - r[1]) <= snap;
}

/// The plan as integer points on the writer's grid (so that "the same point" and "on this edge" are exact).
struct Plan {
  double grid = 0.001;
  std::vector<PlanQ> q;
  std::map<PlanQ, std::uint32_t> index;

  std::int64_t snap = 2;       ///< LodParams::plan_snap_steps
  std::int64_t edge_snap = 50;  ///< LodParams::edge_snap in steps
  std::uint32_t id(const Vec3& v) {
    const PlanQ k{std::llround(v.x() / grid), std::llround(v.y() / grid)};
    if (const auto it = index.find(k); it != index.end()) return it->second;
    for (std::uint32_t i = 0; i < q.size(); ++i)  // an earlier point this close is this one
      if (plan_near(q[i], k, snap)) return index[k] = i;
    index[k] = static_cast<std::uint32_t>(q.size());
    q.push_back(k);
    return static_cast<std::uint32_t>(q.size() - 1);
  }
  double x(std::uint32_t i) const { return static_cast<double>(q[i][0]) * grid; }
  double y(std::uint32_t i) const { return static_cast<double>(q[i][1]) * grid; }
};

/// Twice the signed plan area of a ring (exact).
__int128 twice_area(const Plan& plan, const PlanRing& ring) {
  __int128 a = 0;
  for (std::size_t i = 0; i < ring.size(); ++i) {
    const PlanQ& p = plan.q[ring[i]];
    const PlanQ& r = plan.q[ring[(i + 1) % ring.size()]];
    a += static_cast<__int128>(p[0]) * r[1] - static_cast<__int128>(r[0]) * p[1];
  }
  return a;
}

/// True when plan point p lies within `snap` steps of segment a-b, between its ends (exact integers).
bool plan_strictly_inside(const PlanQ& a, const PlanQ& b, const PlanQ& p, std::int64_t snap) {
  const __int128 dx = b[0] - a[0], dy = b[1] - a[1], ex = p[0] - a[0], ey = p[1] - a[1];
  const __int128 cross = dx * ey - dy * ex, len2 = dx * dx + dy * dy;
  if (cross * cross > static_cast<__int128>(snap) * snap * len2) return false;
  const __int128 t = dx * ex + dy * ey;
  return t > 0 && t < len2;
}


/// Puts every plan point that lies on an edge of a ring (within `snap` steps of it) into that edge, in
/// order: faces that meet along a line then share its vertices (no T-junction in the solid). Only points of
/// other rings: a ring's own vertex near its own edge is a spike of it, and would fold the ring.
void subdivide(const Plan& plan, std::vector<PlanRing>& rings, std::int64_t snap) {
  std::vector<std::uint32_t> points;
  for (const PlanRing& r : rings) points.insert(points.end(), r.begin(), r.end());
  std::sort(points.begin(), points.end());
  points.erase(std::unique(points.begin(), points.end()), points.end());
  for (PlanRing& ring : rings) {
    const std::set<std::uint32_t> own(ring.begin(), ring.end());
    PlanRing out;
    for (std::size_t i = 0; i < ring.size(); ++i) {
      const std::uint32_t a = ring[i], b = ring[(i + 1) % ring.size()];
      out.push_back(a);
      std::vector<std::pair<__int128, std::uint32_t>> on;
      for (std::uint32_t p : points)
        if (!own.count(p) && !plan_near(plan.q[p], plan.q[a], snap) && !plan_near(plan.q[p], plan.q[b], snap) &&
            plan_strictly_inside(plan.q[a], plan.q[b], plan.q[p], snap)) {
          const __int128 t = static_cast<__int128>(plan.q[b][0] - plan.q[a][0]) * (plan.q[p][0] - plan.q[a][0]) +
                             static_cast<__int128>(plan.q[b][1] - plan.q[a][1]) * (plan.q[p][1] - plan.q[a][1]);
          on.emplace_back(t, p);
        }
      std::sort(on.begin(), on.end());
      for (const auto& tp : on) out.push_back(tp.second);
    }
    ring = std::move(out);
  }
}

/// Crossing-number test of plan point (x, y) against a ring.
bool inside_ring(const Plan& plan, const PlanRing& ring, double x, double y) {
  bool in = false;
  for (std::size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++) {
    const double xi = plan.x(ring[i]), yi = plan.y(ring[i]), xj = plan.x(ring[j]), yj = plan.y(ring[j]);
    if ((yi > y) != (yj > y) && x < (xj - xi) * (y - yi) / (yj - yi) + xi) in = !in;
  }
  return in;
}

/// A roof face as the heightmap sees it: its plan ring and its plane.
struct RoofFace {
  std::size_t face = 0;
  PlanRing ring;   ///< counter-clockwise from above
  Vec3 normal, point;
  double minx = 0, miny = 0, maxx = 0, maxy = 0;
  double z_at(double x, double y) const {
    return point.z() - (normal.x() * (x - point.x()) + normal.y() * (y - point.y())) / normal.z();
  }
};

/// What the LoD 2.2 solid gives: the plan (its ground faces), the ground height, the roof faces.
struct Footing {
  Plan plan;
  std::vector<PlanRing> ground;  ///< counter-clockwise from above
  double z_ground = 0;
  std::vector<RoofFace> roofs;   ///< faces of class Roof that face up
  std::string problem;           ///< non-empty: no LoD 1 can be made, and why
};

/// Drops repeated consecutive points (the last-first pair included) and spikes (a, b, a -> a): what merging
/// near points leaves of a sliver.
void drop_repeats(PlanRing& ring) {
  for (bool changed = true; changed && ring.size() >= 3;) {
    changed = false;
    ring.erase(std::unique(ring.begin(), ring.end()), ring.end());
    while (ring.size() > 1 && ring.back() == ring.front()) ring.pop_back();
    for (std::size_t i = 0; i < ring.size() && ring.size() >= 3; ++i) {
      const std::size_t prev = (i + ring.size() - 1) % ring.size(), next = (i + 1) % ring.size();
      if (ring[prev] == ring[next]) {
        ring.erase(ring.begin() + static_cast<std::ptrdiff_t>(std::max(i, next)));
        ring.erase(ring.begin() + static_cast<std::ptrdiff_t>(std::min(i, next)));
        changed = true;
        break;
      }
    }
  }
}

/// The footing with plan points `snap` steps apart or less merged, and points as close to an edge put on it.
Footing read_footing(const PolygonMesh& m, double grid, std::int64_t snap) {
  Footing ft;
  ft.plan.grid = grid;
  ft.plan.snap = snap;
  ft.plan.edge_snap = snap;
  const std::vector<FaceClass> classes = face_classes_or_by_normal(m);
  double zsum = 0;
  std::size_t zn = 0;
  double zmin = INFINITY, zmax = -INFINITY;
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    if (classes[f] != FaceClass::Ground) continue;
    PlanRing ring;
    for (auto it = m.faces[f].rbegin(); it != m.faces[f].rend(); ++it) {  // reversed: counter-clockwise from above
      ring.push_back(ft.plan.id(m.vertices[*it]));
      zsum += m.vertices[*it].z();
      zmin = std::min(zmin, m.vertices[*it].z());
      zmax = std::max(zmax, m.vertices[*it].z());
      ++zn;
    }
    drop_repeats(ring);
    if (ring.size() >= 3) ft.ground.push_back(std::move(ring));
  }
  if (ft.ground.empty()) {
    ft.problem = "the LoD 2.2 solid has no GroundSurface";
    return ft;
  }
  if (zmax - zmin > grid / 2) ft.problem = "the LoD 2.2 GroundSurfaces are not at one height";
  ft.z_ground = std::round(zsum / static_cast<double>(zn) / grid) * grid;
  for (const PlanRing& r : ft.ground)
    if (twice_area(ft.plan, r) <= 0) ft.problem = "a LoD 2.2 GroundSurface does not face down";
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    if (classes[f] != FaceClass::Roof) continue;
    RoofFace r;
    r.face = f;
    r.normal = newell(m, f);
    if (!(r.normal.z() > 0)) continue;  // a vertical or overhanging face labelled roof: nothing over the plan
    r.point = m.vertices[m.faces[f][0]];
    r.minx = r.miny = INFINITY;
    r.maxx = r.maxy = -INFINITY;
    for (std::uint32_t v : m.faces[f]) {
      r.ring.push_back(ft.plan.id(m.vertices[v]));
      r.minx = std::min(r.minx, m.vertices[v].x());
      r.maxx = std::max(r.maxx, m.vertices[v].x());
      r.miny = std::min(r.miny, m.vertices[v].y());
      r.maxy = std::max(r.maxy, m.vertices[v].y());
    }
    drop_repeats(r.ring);
    if (r.ring.size() >= 3) ft.roofs.push_back(std::move(r));
  }
  return ft;
}

bool inside_plan(const Footing& ft, double x, double y) {
  for (const PlanRing& r : ft.ground)
    if (inside_ring(ft.plan, r, x, y)) return true;
  return false;
}

/// The roof heightmap: per plan cell inside the plan, the topmost roof face over its centre and its height.
/// Why cells, not points: the heights describe hsr's model (LoD 1.2 and 1.3 are made from them), and each unit of
/// plan area counts once whatever the point density. roofer takes its percentiles of its roof-plane points
/// instead; on the 55 AHN3 buildings the 50th and 70th agree with it within 0.02 / 0.01 m median (DECISIONS #146).
struct Heightmap {
  std::vector<double> z;
  std::vector<std::size_t> roof;  ///< index into Footing::roofs
};

/// The plan's bounding box: min x, min y, max x, max y.
std::array<double, 4> plan_bounds(const Footing& ft) {
  double minx = INFINITY, miny = INFINITY, maxx = -INFINITY, maxy = -INFINITY;
  for (const PlanRing& r : ft.ground)
    for (std::uint32_t v : r) {
      minx = std::min(minx, ft.plan.x(v));
      maxx = std::max(maxx, ft.plan.x(v));
      miny = std::min(miny, ft.plan.y(v));
      maxy = std::max(maxy, ft.plan.y(v));
    }
  return {minx, miny, maxx, maxy};
}

/// How many `cell`-sized squares cover [lo, hi] (at least 1).
long cells_across(double lo, double hi, double cell) { return std::max(1L, std::lround(std::ceil((hi - lo) / cell))); }

/// The grid of `cell`-sized squares over the plan's bounding box: its south-west corner and its size in cells
/// (at least 1 x 1).
std::tuple<double, double, long, long> plan_grid(const Footing& ft, double cell) {
  const auto [minx, miny, maxx, maxy] = plan_bounds(ft);
  return {minx, miny, cells_across(minx, maxx, cell), cells_across(miny, maxy, cell)};
}

Heightmap roof_heightmap(const Footing& ft, double cell) {
  Heightmap hm;
  const auto [minx, miny, nx, ny] = plan_grid(ft, cell);
  for (long j = 0; j < ny; ++j)
    for (long i = 0; i < nx; ++i) {
      const double x = minx + (static_cast<double>(i) + 0.5) * cell, y = miny + (static_cast<double>(j) + 0.5) * cell;
      if (!inside_plan(ft, x, y)) continue;
      double best = -INFINITY;
      std::size_t best_roof = 0;
      for (std::size_t k = 0; k < ft.roofs.size(); ++k) {
        const RoofFace& r = ft.roofs[k];
        if (x < r.minx || x > r.maxx || y < r.miny || y > r.maxy || !inside_ring(ft.plan, r.ring, x, y)) continue;
        const double z = r.z_at(x, y);
        if (z > best) best = z, best_roof = k;
      }
      if (std::isfinite(best)) {
        hm.z.push_back(best);
        hm.roof.push_back(best_roof);
      }
    }
  return hm;
}

/// The p-th percentile (0-100) of `v` (nearest rank on the sorted values); NaN for none.
double percentile(std::vector<double> v, double p) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const double rank = p / 100.0 * static_cast<double>(v.size() - 1);
  return v[static_cast<std::size_t>(std::llround(rank))];
}

/// b3_h_dak_min, _50p, _70p, _max: percentiles of the roof heightmap, in the world's heights (z0: the mesh's
/// origin). Why min and max are the roof_min_percentile-th and roof_max_percentile-th (2nd, 99th), not the
/// extremes: these are 3DBAG's names, and roofer, its engine, writes those percentiles of its roof points as
/// "min" and "max", so that a sliver of a lower roof at the footprint's edge or a chimney of a few cells does
/// not make them; with the extremes hsr's min was up to 10.2 m below roofer's on the AHN3 buildings (#146).
nlohmann::json number_or_null(double v);

void add_roof_heights(const Heightmap& hm, double z0, const LodParams& p, nlohmann::json& a) {
  a["b3_h_dak_min"] = number_or_null(z0 + percentile(hm.z, p.roof_min_percentile));
  a["b3_h_dak_50p"] = number_or_null(z0 + percentile(hm.z, 50));
  a["b3_h_dak_70p"] = number_or_null(z0 + percentile(hm.z, 70));
  a["b3_h_dak_max"] = number_or_null(z0 + percentile(hm.z, p.roof_max_percentile));
}

/// b3_dak_type from the LoD 2.2 roof faces: slanted when one slopes by horizontal_slope or more, else
/// horizontal or multiple horizontal by the number of distinct levels (same_level apart), as roofer counts
/// its roof planes.
std::string roof_type(const PolygonMesh& m, const LodParams& p) {
  const std::vector<FaceClass> classes = face_classes_or_by_normal(m);
  std::vector<double> levels;
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    if (classes[f] != FaceClass::Roof) continue;
    if (slope_deg(newell(m, f)) >= p.horizontal_slope) return "slanted";
    double z = 0;
    for (std::uint32_t v : m.faces[f]) z += m.vertices[v].z();
    levels.push_back(z / static_cast<double>(m.faces[f].size()));
  }
  if (levels.empty()) return "no planes";
  std::sort(levels.begin(), levels.end());
  std::size_t distinct = 1;
  const double tolerance = p.same_level / p.metres_per_unit;
  for (std::size_t i = 1; i < levels.size(); ++i) distinct += levels[i] - levels[i - 1] >= tolerance;
  return distinct == 1 ? "horizontal" : "multiple horizontal";
}

/// A part of the plan at one level.
struct Region {
  std::vector<PlanRing> rings;  ///< counter-clockwise from above
  double level = 0;
};

/// The solid of `regions` standing on the plan's ground rings: the ground faces at z_ground, each region's
/// rings at its level, a vertical wall along every plan edge where the level on its left is above the level
/// on its right (the outside is at z_ground), every vertical side split at the levels other faces have at that
/// plan point (so that each edge of the solid is used once each way). Rings must be subdivided (subdivide).
PolygonMesh stepped_solid(const Plan& plan, const std::vector<PlanRing>& ground, const std::vector<Region>& regions,
                          double z_ground, const Vec3& origin) {
  PolygonMesh m;
  m.origin = origin;
  std::map<std::pair<std::uint32_t, double>, std::uint32_t> vid;
  const auto vertex = [&](std::uint32_t p, double z) {
    const auto [it, added] = vid.emplace(std::make_pair(p, z), static_cast<std::uint32_t>(m.vertices.size()));
    if (added) m.vertices.emplace_back(plan.x(p), plan.y(p), z);
    return it->second;
  };
  std::map<std::uint32_t, std::set<double>> levels;  // per plan point, the heights of the horizontal faces there
  for (const PlanRing& r : ground)
    for (std::uint32_t p : r) levels[p].insert(z_ground);
  std::map<std::pair<std::uint32_t, std::uint32_t>, double> left;  // directed plan edge -> level on its left
  for (const Region& g : regions)
    for (const PlanRing& r : g.rings)
      for (std::size_t i = 0; i < r.size(); ++i) {
        levels[r[i]].insert(g.level);
        left[{r[i], r[(i + 1) % r.size()]}] = g.level;
      }
  for (const PlanRing& r : ground) {
    std::vector<std::uint32_t> face;
    for (auto it = r.rbegin(); it != r.rend(); ++it) face.push_back(vertex(*it, z_ground));
    m.faces.push_back(face);
    m.face_class.push_back(FaceClass::Ground);
  }
  for (const Region& g : regions)
    for (const PlanRing& r : g.rings) {
      std::vector<std::uint32_t> face;
      for (std::uint32_t p : r) face.push_back(vertex(p, g.level));
      m.faces.push_back(face);
      m.face_class.push_back(FaceClass::Roof);
    }
  for (const auto& [edge, high] : left) {
    const auto other = left.find({edge.second, edge.first});
    const double low = other == left.end() ? z_ground : other->second;
    if (!(high > low)) continue;
    const std::uint32_t a = edge.first, b = edge.second;
    std::vector<std::uint32_t> face{vertex(a, low), vertex(b, low)};
    for (double z : levels[b])
      if (z > low && z < high) face.push_back(vertex(b, z));
    face.push_back(vertex(b, high));
    face.push_back(vertex(a, high));
    const std::set<double>& at_a = levels[a];
    for (auto it = at_a.rbegin(); it != at_a.rend(); ++it)
      if (*it > low && *it < high) face.push_back(vertex(a, *it));
    m.faces.push_back(face);
    m.face_class.push_back(FaceClass::Wall);
  }
  return m;
}

/// A level rounded to the writer's grid and at least one step above the ground: faces of one level stay on
/// one plane, and no wall is of zero height.
double snap_level(double z, double z_ground, double grid) { return std::max(std::round(z / grid) * grid, z_ground + grid); }

/// LoD 1.3's parts: connected roof surfaces (roof faces sharing an edge of the LoD 2.2 solid), then
/// neighbours in plan whose levels differ by less than lod13_min_step joined (their level recomputed).
/// Returns each roof face's part (index into Footing::roofs order) and the part levels.
std::vector<std::size_t> roof_parts(const PolygonMesh& m, const Footing& ft, const Heightmap& hm, const LodParams& p,
                                    std::vector<double>& part_level) {
  const std::size_t n = ft.roofs.size();
  std::vector<std::size_t> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  const auto find = [&](std::size_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  const auto join_by = [&](auto key_of) {  // joins faces that share an edge by key_of(a, b)
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::size_t> owner;
    for (std::size_t k = 0; k < n; ++k) {
      const auto keys = key_of(k);
      for (const auto& e : keys) owner.emplace(e, k);
    }
    return owner;
  };
  // Roof faces sharing a 3D edge of the solid are one surface.
  const auto edges3d = [&](std::size_t k) {
    std::vector<std::pair<std::uint32_t, std::uint32_t>> out;
    const auto& ring = m.faces[ft.roofs[k].face];
    for (std::size_t i = 0; i < ring.size(); ++i) out.emplace_back(ring[i], ring[(i + 1) % ring.size()]);
    return out;
  };
  const auto owner3d = join_by(edges3d);
  for (std::size_t k = 0; k < n; ++k)
    for (const auto& [a, b] : edges3d(k))
      if (const auto it = owner3d.find({b, a}); it != owner3d.end()) parent[find(k)] = find(it->second);
  const auto levels_of = [&]() {
    std::map<std::size_t, std::vector<double>> heights;
    for (std::size_t c = 0; c < hm.z.size(); ++c) heights[find(hm.roof[c])].push_back(hm.z[c]);
    std::map<std::size_t, double> level;
    for (std::size_t k = 0; k < n; ++k) {
      const std::size_t root = find(k);
      if (level.count(root)) continue;
      level[root] = heights.count(root) ? percentile(heights[root], p.roof_percentile) : ft.roofs[k].point.z();
    }
    return level;
  };
  // Neighbours in plan (a plan edge used both ways) closer than the step: one part.
  const auto edges2d = [&](std::size_t k) {
    std::vector<std::pair<std::uint32_t, std::uint32_t>> out;
    const PlanRing& ring = ft.roofs[k].ring;
    for (std::size_t i = 0; i < ring.size(); ++i) out.emplace_back(ring[i], ring[(i + 1) % ring.size()]);
    return out;
  };
  const auto owner2d = join_by(edges2d);
  const std::map<std::size_t, double> level = levels_of();
  const double step = p.lod13_min_step / p.metres_per_unit;
  for (std::size_t k = 0; k < n; ++k)
    for (const auto& [a, b] : edges2d(k))
      if (const auto it = owner2d.find({b, a}); it != owner2d.end()) {
        const std::size_t ra = find(k), rb = find(it->second);
        if (ra != rb && level.count(ra) && level.count(rb) && std::abs(level.at(ra) - level.at(rb)) < step) parent[ra] = rb;
      }
  const std::map<std::size_t, double> joined = levels_of();
  std::map<std::size_t, std::size_t> number;
  std::vector<std::size_t> part(n);
  part_level.clear();
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t root = find(k);
    const auto [it, added] = number.emplace(root, part_level.size());
    if (added) part_level.push_back(joined.at(root));
    part[k] = it->second;
  }
  return part;
}

/// The solid's verdict by eval's exact check, and its volume.
struct Checked {
  std::string validity;
  double volume = 0;
  bool valid() const { return validity == "valid"; }
};

Checked check(const PolygonMesh& m) {
  const Validity v = check_validity(m);
  return {v.valid() ? std::string("valid") : v.summary(), v.volume};
}

/// RMS distance of the points to the solid; `order`: the points' kd-tree leaf order (one for all LoDs).
double rmse(const std::vector<Vec3>& points, const PolygonMesh& m, const std::vector<int>& order) {
  if (points.empty()) return NAN;
  double sum = 0;
  for (double d : point_mesh_distances(points, m, order)) sum += d * d;
  return std::sqrt(sum / static_cast<double>(points.size()));
}

/// Points over a region per unit² and the share of the region's cells (sized to hold nodata_cell_points at that
/// density, over the region's bounding box `bounds` = min x, min y, max x, max y; a cell is the region's when its
/// centre is, `in_region(x, y)`) without a point. Why cells sized by the density: at any density a cell without a
/// point is then a hole in the data (occlusion, a glass roof, water), not sampling's chance. `area`: the region's,
/// unit²; {NaN, NaN} when it is not positive.
template <class InRegion>
std::pair<double, double> density_and_gaps_in(const std::vector<Vec3>& points, double area, const std::array<double, 4>& bounds,
                                              const LodParams& p, InRegion&& in_region) {
  if (!(area > 0)) return {NAN, NAN};
  std::vector<const Vec3*> inside;
  for (const Vec3& v : points)
    if (in_region(v.x(), v.y())) inside.push_back(&v);
  const double density = static_cast<double>(inside.size()) / area;
  if (inside.empty()) return {0.0, 1.0};
  const double cell = std::sqrt(p.nodata_cell_points / density);
  const auto [minx, miny, maxx, maxy] = bounds;
  const long nx = cells_across(minx, maxx, cell), ny = cells_across(miny, maxy, cell);
  std::vector<char> hit(static_cast<std::size_t>(nx * ny), 0);
  for (const Vec3* v : inside) {
    const long i = std::clamp(static_cast<long>((v->x() - minx) / cell), 0L, nx - 1);
    const long j = std::clamp(static_cast<long>((v->y() - miny) / cell), 0L, ny - 1);
    hit[static_cast<std::size_t>(j * nx + i)] = 1;
  }
  std::size_t cells = 0, empty = 0;
  for (long j = 0; j < ny; ++j)
    for (long i = 0; i < nx; ++i)
      if (in_region(minx + (static_cast<double>(i) + 0.5) * cell, miny + (static_cast<double>(j) + 0.5) * cell)) {
        ++cells;
        empty += !hit[static_cast<std::size_t>(j * nx + i)];
      }
  return {density, cells ? static_cast<double>(empty) / static_cast<double>(cells) : NAN};
}

/// b3_puntdichtheid and b3_nodata_fractie over the LoD 2.2 plan (density_and_gaps_in).
std::pair<double, double> density_and_gaps(const Footing& ft, const std::vector<Vec3>& points, const LodParams& p) {
  __int128 twice = 0;
  for (const PlanRing& r : ft.ground) twice += twice_area(ft.plan, r);
  const double area = static_cast<double>(twice) * ft.plan.grid * ft.plan.grid / 2;
  return density_and_gaps_in(points, area, plan_bounds(ft), p, [&](double x, double y) { return inside_plan(ft, x, y); });
}

/// b3_puntdichtheid and b3_nodata_fractie over the building's footprint (x, y in the points' frame), the same rule
/// as density_and_gaps over the plan. Why the footprint when there is one: 3DBAG's figures are the cadastral
/// polygon's (roofer rasterises its footprint), and the LoD 2.2 plan may fall short of it; on AHN3_08831 the plan
/// was 23 m² short of the footprint and its density 5.9 % under the footprint's (DECISIONS #146).
std::pair<double, double> footprint_density_and_gaps(const Footprint& fp, const std::vector<Vec3>& points, const LodParams& p) {
  double area = 0, minx = INFINITY, miny = INFINITY, maxx = -INFINITY, maxy = -INFINITY;
  for (const FootprintPolygon& poly : fp) {
    area += std::abs(twice_ring_area(poly.outer)) / 2;
    for (const auto& h : poly.holes) area -= std::abs(twice_ring_area(h)) / 2;
    for (const Vec2& q : poly.outer) {
      minx = std::min(minx, q.x());
      maxx = std::max(maxx, q.x());
      miny = std::min(miny, q.y());
      maxy = std::max(maxy, q.y());
    }
  }
  return density_and_gaps_in(points, area, {minx, miny, maxx, maxy}, p,
                             [&](double x, double y) { return inside_footprint(x, y, fp); });
}

nlohmann::json number_or_null(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

/// LoD 1.3 regions from the parts, or a note why there are none (the roof's projections do not tile the plan).
std::vector<Region> lod13_regions(const PolygonMesh& m, Footing& ft, const Heightmap& hm, const LodParams& p,
                                  std::string& note) {
  __int128 ground = 0, roofs = 0;
  double perimeter = 0;  // in steps
  for (const PlanRing& r : ft.ground) ground += twice_area(ft.plan, r);
  for (const RoofFace& r : ft.roofs) {
    roofs += twice_area(ft.plan, r.ring);
    for (std::size_t i = 0; i < r.ring.size(); ++i) {
      const PlanQ& a = ft.plan.q[r.ring[i]];
      const PlanQ& b = ft.plan.q[r.ring[(i + 1) % r.ring.size()]];
      perimeter += std::hypot(static_cast<double>(b[0] - a[0]), static_cast<double>(b[1] - a[1]));
    }
  }
  // Within the edge snap along every roof edge: slivers, not a gap or an overlap.
  if (std::abs(static_cast<double>(ground - roofs)) > 2 * static_cast<double>(ft.plan.edge_snap) * perimeter) {
    note = "the LoD 2.2 roof faces do not cover the plan exactly once";
    return {};
  }
  std::vector<double> level;
  const std::vector<std::size_t> part = roof_parts(m, ft, hm, p, level);
  std::vector<Region> regions(level.size());
  for (std::size_t k = 0; k < ft.roofs.size(); ++k) regions[part[k]].rings.push_back(ft.roofs[k].ring);
  for (std::size_t i = 0; i < regions.size(); ++i) regions[i].level = snap_level(level[i], ft.z_ground, ft.plan.grid);
  return regions;
}

}  // namespace

void parse_lod_list(const std::string& list, LodParams& params) {
  params.lod12 = params.lod13 = params.lod22 = false;
  std::stringstream in(list);
  std::string item;
  bool any = false;
  while (std::getline(in, item, ',')) {
    bool* flag = item == "1.2" ? &params.lod12 : item == "1.3" ? &params.lod13 : item == "2.2" ? &params.lod22 : nullptr;
    if (!flag) throw Error(Status::BadInput, "city", "--lod: '" + item + "' is not one of 1.2, 1.3, 2.2 (e.g. --lod 1.2,2.2)");
    if (*flag) throw Error(Status::BadInput, "city", "--lod: " + item + " is given twice");
    *flag = any = true;
  }
  if (!any || (!list.empty() && list.back() == ','))
    throw Error(Status::BadInput, "city", "--lod: '" + list + "' names no LoD (e.g. --lod 1.2,1.3,2.2)");
}

std::string lod_list(const LodParams& p) {
  std::string s;
  for (const auto& [flag, name] : {std::pair{p.lod12, "1.2"}, std::pair{p.lod13, "1.3"}, std::pair{p.lod22, "2.2"}})
    if (flag) s += (s.empty() ? "" : ",") + std::string(name);
  return s;
}

nlohmann::json roof_surface_attributes(const PolygonMesh& mesh, std::size_t face) {
  if (face >= mesh.faces.size()) return nullptr;
  const FaceClass c = face < mesh.face_class.size() ? mesh.face_class[face] : FaceClass::Unknown;
  if (c != FaceClass::Roof) return nullptr;
  const Vec3 n = newell(mesh, face);
  if (!(n.norm() > 0)) return nullptr;
  double azimuth = std::atan2(n.x(), n.y()) * 180.0 / kPi;  // from +y (north), clockwise
  if (azimuth < 0) azimuth += 360.0;
  return {{"b3_hellingshoek", slope_deg(n)},
          {"b3_azimut", n.x() == 0 && n.y() == 0 ? nlohmann::json(nullptr) : nlohmann::json(azimuth)},
          {"b3_opp", n.norm() / 2}};
}

BuildingLods building_lods(const PolygonMesh& lod22, const std::vector<Vec3>& points, const nlohmann::json& run_attributes,
                           const LodParams& p, const Footprint& footprint) {
  BuildingLods out;
  nlohmann::json& a = out.attributes;
  Footing ft = read_footing(lod22, p.grid, p.plan_snap_steps);
  const Heightmap hm = ft.problem.empty() ? roof_heightmap(ft, p.height_cell / p.metres_per_unit) : Heightmap{};
  a["b3_dak_type"] = roof_type(lod22, p);
  // Heights are the world's (3DBAG's are above the vertical datum): the mesh's vertices are local to its origin.
  const double z0 = lod22.origin.z();
  if (ft.problem.empty()) a["b3_h_maaiveld"] = z0 + ft.z_ground;
  add_roof_heights(hm, z0, p, a);
  if (ft.problem.empty() || !footprint.empty()) {
    const auto [density, gaps] = footprint.empty() ? density_and_gaps(ft, points, p) : footprint_density_and_gaps(footprint, points, p);
    a["b3_puntdichtheid"] = number_or_null(density);
    a["b3_nodata_fractie"] = number_or_null(gaps);
  }
  if (run_attributes.contains("hsr_points_unexplained_share") && run_attributes["hsr_points_unexplained_share"].is_number())
    a["b3_reconstructie_onvolledig"] = run_attributes["hsr_points_unexplained_share"].get<double>() > p.doubtful_unexplained_share;
  const Checked c22 = check(lod22);
  a["hsr_validity_lod22"] = c22.validity;
  a["b3_volume_lod22"] = c22.volume;
  const std::vector<int> order = points.empty() ? std::vector<int>{} : KdTree(points).leaf_order();
  a["b3_rmse_lod22"] = number_or_null(rmse(points, lod22, order));
  if (!p.lod12 && !p.lod13) return out;
  if (!ft.problem.empty() || hm.z.empty()) {
    a["hsr_lod1_note"] = ft.problem.empty() ? std::string("no roof face over the plan") : ft.problem;
    return out;
  }
  // LoD 1.2: the ground faces alone (several of them share their points exactly).
  std::vector<PlanRing> plan_rings = ft.ground;
  subdivide(ft.plan, plan_rings, ft.plan.snap);
  const Region block{plan_rings, snap_level(percentile(hm.z, p.roof_percentile), ft.z_ground, ft.plan.grid)};
  const PolygonMesh lod12 = stepped_solid(ft.plan, plan_rings, {block}, ft.z_ground, lod22.origin);
  const Checked c12 = check(lod12);
  const auto add = [&](const std::string& lod, const PolygonMesh& solid, const Checked& c) {
    const std::string key = lod == "1.2" ? "lod12" : "lod13";
    a["hsr_validity_" + key] = c.validity;
    if (!c.valid()) return;
    a["b3_volume_" + key] = c.volume;
    a["b3_rmse_" + key] = number_or_null(rmse(points, solid, order));
    out.solids.push_back({lod, solid});
  };
  if (p.lod12) add("1.2", lod12, c12);
  if (!p.lod13) return out;
  // LoD 1.3: plan points within the edge snap are one, ground and roof rings share their plan points. The
  // heightmap's roof indices are those of `ft` (the same faces, in the same order, unless merging dropped
  // a sliver: then the parts are read off the exact footing's).
  std::string note;
  std::vector<Region> regions;
  Footing snapped = read_footing(lod22, p.grid, std::max<std::int64_t>(p.plan_snap_steps, std::llround(p.edge_snap / p.metres_per_unit / p.grid)));
  if (snapped.roofs.size() != ft.roofs.size() || !snapped.problem.empty()) {
    note = "merging plan points closer than the edge snap dropped a roof face";
  } else {
    std::vector<PlanRing> rings = snapped.ground;
    for (const RoofFace& r : snapped.roofs) rings.push_back(r.ring);
    subdivide(snapped.plan, rings, snapped.plan.edge_snap);
    for (std::size_t i = 0; i < snapped.ground.size(); ++i) snapped.ground[i] = rings[i];
    for (std::size_t k = 0; k < snapped.roofs.size(); ++k) snapped.roofs[k].ring = rings[snapped.ground.size() + k];
    regions = lod13_regions(lod22, snapped, hm, p, note);
  }
  std::set<double> levels;
  for (const Region& r : regions) levels.insert(r.level);
  if (levels.size() == 1) regions = {block};  // one level: the block itself (its level is the same percentile)
  PolygonMesh lod13;
  Checked c13;
  if (regions.size() == 1) {
    lod13 = lod12;
    c13 = c12;
  } else if (!regions.empty()) {
    lod13 = stepped_solid(snapped.plan, snapped.ground, regions, snapped.z_ground, lod22.origin);
    c13 = check(lod13);
    if (!c13.valid()) note = "the stepped solid is " + c13.validity;
  }
  if (!note.empty()) {  // the block stands in, and the feature says why
    regions = {block};
    lod13 = lod12;
    c13 = c12;
    a["hsr_lod13_note"] = note;
  }
  std::set<double> distinct;
  for (const Region& r : regions) distinct.insert(r.level);
  a["hsr_lod13_parts"] = distinct.size();
  add("1.3", lod13, c13);
  return out;
}

}  // namespace hsr
