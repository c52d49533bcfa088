// Kinetic and hierarchical partitioners: nested domains, sub-domain walls, parallel growth, and the
// construction of the cells from the grown regions (see partition.h and kinetic_growth.h).
#include "partition/kinetic.h"

#include "core/error.h"
#include "core/log.h"
#include "partition/kinetic_growth.h"

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <condition_variable>
#include <exception>
#include <map>
#include <mutex>
#include <numeric>
#include <optional>

namespace hsr::partition_internal {

namespace {

constexpr const char* kStage = "partition";

// Input polygons of one level on one support plane, merged into the convex hull of their union (coplanar
// polygons of one level grow as one, as in KSR).
struct KPolygon {
  int plane = -1;             // builder support plane
  int level = 1;
  std::vector<P2> shape;      // exact, frame of the plane, CCW, positive area
  Rational time_scale;        // R / s
  std::vector<Vec3> shape3d;  // approximate, for conservative double filters
  std::vector<D2> shape_d;    // the double images of `shape` (approx)
  BBox bbox;
  double area = 0;
  std::vector<int> adjacent;  // sorted KPolygon indices (same level)
};

std::vector<KPolygon> prepare(const PartitionInput& input, const PartitionParams& params, ComplexBuilder& builder) {
  const bool hierarchical = params.method == Partitioner::Hierarchical;
  std::map<std::pair<int, int>, std::vector<std::size_t>> groups;  // (level, plane) -> input polygons
  for (std::size_t i = 0; i < input.polygons.size(); ++i) {
    const ConvexPolygon& poly = input.polygons[i];
    const int plane = builder.add_plane(canonical_plane(poly.plane));
    auto& ids = builder.plane(plane).input_planes;
    if (std::find(ids.begin(), ids.end(), poly.plane_id) == ids.end()) ids.push_back(poly.plane_id);
    int level = 1;
    if (hierarchical) {
      if (poly.level < 1 || poly.level > 3)
        throw Error(Status::BadInput, kStage,
                    "polygon of plane " + std::to_string(poly.plane_id) + " has level " + std::to_string(poly.level) +
                        " (expected 1, 2 or 3)");
      if (!(poly.speed > 0) || !std::isfinite(poly.speed))
        throw Error(Status::BadInput, kStage,
                    "polygon of plane " + std::to_string(poly.plane_id) + " has a non-positive speed");
      level = poly.level;
    }
    groups[{level, plane}].push_back(i);
  }
  std::vector<KPolygon> out;
  std::map<int, std::vector<int>> by_plane_id;  // input plane id -> KPolygons
  for (const auto& [key, members] : groups) {
    KPolygon k;
    k.level = key.first;
    k.plane = key.second;
    const ExactPlane& exact = builder.plane(k.plane).exact;
    const PlaneFrame& frame = builder.frame(k.plane);
    std::vector<P2> pts;
    double speed = 0;
    for (std::size_t i : members) {
      std::vector<P2> p = project_polygon(input.polygons[i], exact, frame);
      pts.insert(pts.end(), p.begin(), p.end());
      speed = std::max(speed, hierarchical ? input.polygons[i].speed : 1.0);
    }
    k.shape = convex_hull(std::move(pts));
    if (k.shape.size() < 3) continue;  // zero area: nothing grows (its plane still exists)
    k.shape_d = approx(k.shape);
    k.area = 0.5 * twice_area(k.shape).get_d() * area_scale(exact, frame);
    const double radius = std::sqrt(k.area / M_PI);
    k.time_scale = Rational(radius / speed);
    for (const P2& q : k.shape) {
      k.shape3d.push_back(to_double(lift(builder.int_plane_of(k.plane), frame, q)));
      k.bbox.extend(k.shape3d.back());
    }
    const int index = static_cast<int>(out.size());
    for (std::size_t i : members) by_plane_id[input.polygons[i].plane_id].push_back(index);
    out.push_back(std::move(k));
  }
  for (const auto& [a, b] : input.adjacent_planes) {
    auto ia = by_plane_id.find(a), ib = by_plane_id.find(b);
    if (ia == by_plane_id.end() || ib == by_plane_id.end()) continue;
    for (int x : ia->second)
      for (int y : ib->second)
        if (x != y && out[x].level == out[y].level) {
          out[x].adjacent.push_back(y);
          out[y].adjacent.push_back(x);
        }
  }
  for (KPolygon& k : out) {
    std::sort(k.adjacent.begin(), k.adjacent.end());
    k.adjacent.erase(std::unique(k.adjacent.begin(), k.adjacent.end()), k.adjacent.end());
  }
  return out;
}

bool boxes_overlap(const BBox& a, const BBox& b, double slack) {
  if (!filters_on()) return true;
  return !(((a.min.array() - slack) > b.max.array()).any() || ((a.max.array() + slack) < b.min.array()).any());
}

// If polygon k meets the interior of `cell` with positive area, the cell's section by k's plane (else empty).
// Reads the builder only (thread-safe).
std::vector<P2> polygon_in_cell(const ComplexBuilder& builder, int cell, const KPolygon& k, double slack) {
  if (!boxes_overlap(builder.cell_bbox(cell), k.bbox, slack)) return {};
  if (!builder.may_cross(cell, k.plane) || !builder.may_meet_polygon(cell, k.shape3d)) return {};
  if (!builder.crosses_of(cell, k.plane)) return {};
  std::vector<P2> section = builder.section_of(cell, k.plane);
  if (!interiors_overlap(section, approx(section), k.shape, k.shape_d)) return {};
  return section;
}

struct Domain {
  int cell = -1;
  std::vector<int> members;             // KPolygon indices, increasing
  std::vector<std::vector<P2>> sections;  // the cell's section by each member's plane
  void add(int member, std::vector<P2> section) {
    if (section.empty()) return;
    members.push_back(member);
    sections.push_back(std::move(section));
  }
};

// A point strictly inside both convex CCW polygons (whose interiors overlap): the vertex average of their
// intersection computed in doubles, checked exactly; exact clipping when rounding gets in the way.
P2 common_interior_point(const std::vector<P2>& a, const std::vector<P2>& b) {
  std::vector<std::array<double, 2>> poly, next;
  for (const P2& q : a) poly.push_back({q.u.get_d(), q.v.get_d()});
  const std::size_t m = b.size();
  for (std::size_t e = 0; e < m && poly.size() >= 3; ++e) {
    const double pu = b[e].u.get_d(), pv = b[e].v.get_d();
    const double qu = b[(e + 1) % m].u.get_d(), qv = b[(e + 1) % m].v.get_d();
    auto side = [&](const std::array<double, 2>& x) { return (qu - pu) * (x[1] - pv) - (qv - pv) * (x[0] - pu); };
    next.clear();
    for (std::size_t i = 0; i < poly.size(); ++i) {
      const auto& x = poly[i];
      const auto& y = poly[(i + 1) % poly.size()];
      const double sx = side(x), sy = side(y);
      if (sx >= 0) next.push_back(x);
      if ((sx > 0 && sy < 0) || (sx < 0 && sy > 0)) {
        const double t = sx / (sx - sy);
        next.push_back({x[0] + t * (y[0] - x[0]), x[1] + t * (y[1] - x[1])});
      }
    }
    poly.swap(next);
  }
  if (poly.size() >= 3) {
    double su = 0, sv = 0;
    for (const auto& x : poly) { su += x[0]; sv += x[1]; }
    const P2 guess{Rational(su / static_cast<double>(poly.size())), Rational(sv / static_cast<double>(poly.size()))};
    auto strictly_inside = [&](const std::vector<P2>& c) {
      for (std::size_t i = 0; i < c.size(); ++i)
        if (orient_sign(c[i], c[(i + 1) % c.size()], guess) <= 0) return false;
      return true;
    };
    if (strictly_inside(a) && strictly_inside(b)) return guess;
  }
  const std::vector<P2> exact = clip_convex(a, b);
  HSR_ASSERT(exact.size() >= 3, "kinetic: polygons without a common interior");
  Rational su = 0, sv = 0;
  for (const P2& q : exact) { su += q.u; sv += q.v; }
  const Rational n(static_cast<long>(exact.size()));
  return {su / n, sv / n};
}

// A point strictly inside the convex CCW polygon (positive area): the double vertex average as an exact dyadic
// rational when it is strictly inside (exact test; small denominators make what follows cheap), else the exact
// vertex average. (Only used where any relative-interior point gives the same answer.)
P2 relative_interior_point(const std::vector<P2>& poly, const std::vector<D2>& d) {
  double su = 0, sv = 0;
  for (const D2& q : d) { su += q.u; sv += q.v; }
  const double n = static_cast<double>(d.size());
  const double gu = su / n, gv = sv / n;
  if (std::isfinite(gu) && std::isfinite(gv)) {
    const P2 guess{Rational(gu), Rational(gv)};
    const D2 dg{gu, gv};
    bool inside = true;
    for (std::size_t i = 0; i < poly.size() && inside; ++i) {
      const std::size_t j = (i + 1) % poly.size();
      inside = orient_sign(poly[i], poly[j], guess, d[i], d[j], dg) > 0;
    }
    if (inside) return guess;
  }
  Rational au = 0, av = 0;
  for (const P2& q : poly) { au += q.u; av += q.v; }
  const Rational count(static_cast<long>(poly.size()));
  return {au / count, av / count};
}

// The region of a polygon alone in its domain: the whole section (no other plane cuts it, and walls are never
// crossed), as grow_regions would find it.
GrownRegion lone_region(const GrowthPolygon& g) {
  GrownRegion r;
  r.faces.push_back(g.domain);
  r.faces_d.push_back(approx(g.domain));
  std::vector<Vec3> poly3d;
  for (const P2& q : g.domain) poly3d.push_back(to_double(lift(g.integer, g.frame, q)));
  r.faces3d.push_back(std::move(poly3d));
  return r;
}

// The point of a facet used to decide whether it lies in a region: a point of its relative interior (each facet
// lies entirely inside or outside its plane's region, so any such point answers for the whole facet).
P2 facet_point(const ComplexBuilder& builder, std::uint32_t f, const PlaneFrame& frame) {
  const auto& loop = builder.facet_vertices(f);
  std::vector<P2> pts;
  std::vector<D2> d;
  for (auto v : loop) {
    pts.push_back(to_2d(frame, builder.vertex(v)));
    d.push_back(to_2d(frame, builder.vertex_approx(v)));
  }
  return relative_interior_point(pts, d);
}

struct FaceIndex {
  std::vector<std::vector<P2>> faces;
  std::vector<std::vector<D2>> faces_d;      // their double images (approx), for the orientation filter
  std::vector<std::vector<Vec3>> faces3d;    // approximate, for conservative filters
  std::vector<BBox> boxes3d;
  std::vector<std::array<double, 4>> boxes;  // umin, vmin, umax, vmax
  std::array<double, 4> all{1e300, 1e300, -1e300, -1e300};
  BBox box3d;
  std::vector<std::optional<ExactPoint>> inner;  // per face, lazily: its vertex average (relative interior)
};

bool box2d_overlap(const std::array<double, 4>& a, const std::array<double, 4>& b, double slack) {
  if (!filters_on()) return true;
  return !(a[0] - slack > b[2] || b[0] - slack > a[2] || a[1] - slack > b[3] || b[1] - slack > a[3]);
}

// Splits the domain by the grown regions, then merges cells separated by facets outside every region. The
// regions' faces are moved out (consumed: copying their exact vertices was a tenth of this step).
void build_domain(ComplexBuilder& builder, const Domain& domain, const std::vector<KPolygon>& polys,
                  std::vector<GrownRegion>&& regions, int level, double slack) {
  std::vector<int> cells{domain.cell};
  std::map<int, int> member_of_plane;  // support plane -> index in domain.members
  std::vector<FaceIndex> index(domain.members.size());
  for (std::size_t m = 0; m < domain.members.size(); ++m) {
    const KPolygon& k = polys[domain.members[m]];
    member_of_plane[k.plane] = static_cast<int>(m);
    FaceIndex& fi = index[m];
    fi.faces = std::move(regions[m].faces);
    fi.faces3d = std::move(regions[m].faces3d);
    fi.faces_d = std::move(regions[m].faces_d);
    for (std::size_t f = 0; f < fi.faces.size(); ++f) {
      std::array<double, 4> b{1e300, 1e300, -1e300, -1e300};
      for (const D2& q : fi.faces_d[f]) b = {std::min(b[0], q.u), std::min(b[1], q.v), std::max(b[2], q.u), std::max(b[3], q.v)};
      fi.boxes.push_back(b);
      fi.all = {std::min(fi.all[0], b[0]), std::min(fi.all[1], b[1]), std::max(fi.all[2], b[2]),
                std::max(fi.all[3], b[3])};
      BBox b3;
      for (const Vec3& q : fi.faces3d[f]) b3.extend(q);
      fi.box3d.extend(b3.min);
      fi.box3d.extend(b3.max);
      fi.boxes3d.push_back(b3);
    }
  }
  // Larger regions first (as bsp: fewer useless splits).
  std::vector<std::size_t> order(domain.members.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return polys[domain.members[a]].area > polys[domain.members[b]].area; });
  for (std::size_t m : order) {
    const KPolygon& k = polys[domain.members[m]];
    FaceIndex& fi = index[m];
    if (fi.faces.empty()) continue;
    fi.inner.resize(fi.faces.size());
    auto inner_point = [&](std::size_t f) -> const ExactPoint& {
      if (!fi.inner[f]) fi.inner[f] = lift(builder.int_plane_of(k.plane), builder.frame(k.plane),
                                           relative_interior_point(fi.faces[f], fi.faces_d[f]));
      return *fi.inner[f];
    };
    const std::size_t n = cells.size();
    for (std::size_t ci = 0; ci < n; ++ci) {
      const int c = cells[ci];
      if (n == 1 && c == domain.cell) {
        // The domain cell is still whole: its section by this plane is known, and a region always meets it
        // (it holds the polygon's seed face).
        builder.split(c, k.plane, level);
        cells.push_back(builder.num_cells() - 1);
        continue;
      }
      if (!boxes_overlap(builder.cell_bbox(c), fi.box3d, slack) || !builder.may_cross(c, k.plane) ||
          !builder.crosses(c, k.plane))
        continue;
      // Conservative double filter before the exact tests: the faces that may meet the cell.
      std::vector<std::size_t> candidates;
      for (std::size_t f = 0; f < fi.faces.size(); ++f)
        if (boxes_overlap(builder.cell_bbox(c), fi.boxes3d[f], slack) && builder.may_meet_polygon(c, fi.faces3d[f]))
          candidates.push_back(f);
      if (candidates.empty()) continue;
      // Exact and cheap: a face's relative-interior point strictly inside the cell proves that their
      // interiors overlap. Otherwise the exact section decides.
      bool meets = false;
      for (std::size_t f : candidates)
        if (builder.contains_strictly(c, inner_point(f))) { meets = true; break; }
      if (!meets) {
        const std::vector<P2> section = builder.section(c, k.plane);
        const std::vector<D2> section_d = approx(section);
        std::array<double, 4> sb{1e300, 1e300, -1e300, -1e300};
        for (const D2& q : section_d) sb = {std::min(sb[0], q.u), std::min(sb[1], q.v), std::max(sb[2], q.u), std::max(sb[3], q.v)};
        if (!box2d_overlap(sb, fi.all, slack)) continue;
        for (std::size_t f : candidates)
          if (box2d_overlap(sb, fi.boxes[f], slack) && interiors_overlap(section, section_d, fi.faces[f], fi.faces_d[f])) {
            meets = true;
            break;
          }
      }
      if (!meets) continue;
      builder.split(c, k.plane, level);
      cells.push_back(builder.num_cells() - 1);
    }
  }
  if (cells.size() == 1) return;
  // Merge across facets that lie in no region (each facet is entirely inside or outside its plane's region:
  // a region's boundary lies on other regions, whose planes split every cell they meet).
  std::sort(cells.begin(), cells.end());
  std::vector<int> parent(cells.size());
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  auto position = [&](int cell) {
    auto it = std::lower_bound(cells.begin(), cells.end(), cell);
    return (it != cells.end() && *it == cell) ? static_cast<int>(it - cells.begin()) : -1;
  };
  for (std::size_t ci = 0; ci < cells.size(); ++ci) {
    const int c = cells[ci];
    for (auto f : builder.cell_facets(c)) {
      const auto& fc = builder.facet_cells(f);
      const int other = fc[0] == c ? fc[1] : fc[0];
      if (other < c) continue;  // each interior facet once (and never a facet to the outside: -1)
      const int po = position(other);
      if (po < 0) continue;
      auto mp = member_of_plane.find(builder.facet_plane(f));
      HSR_ASSERT(mp != member_of_plane.end(), "kinetic: an inner facet of a domain is on no member plane");
      const FaceIndex& fi = index[mp->second];
      const P2 point = facet_point(builder, f, builder.frame(builder.facet_plane(f)));
      const D2 dpoint = approx(point);
      const double pu = dpoint.u, pv = dpoint.v;
      const std::array<double, 4> pb{pu, pv, pu, pv};
      bool inside = false;
      for (std::size_t r = 0; r < fi.faces.size() && !inside; ++r)
        inside = box2d_overlap(pb, fi.boxes[r], slack) && point_in_convex(point, dpoint, fi.faces[r], fi.faces_d[r]);
      if (!inside) parent[find(static_cast<int>(ci))] = find(po);
    }
  }
  std::map<int, std::vector<int>> groups;
  for (std::size_t ci = 0; ci < cells.size(); ++ci) groups[find(static_cast<int>(ci))].push_back(cells[ci]);
  for (auto& [root, group] : groups)
    if (group.size() > 1) builder.merge_cells(group);
}

// Runs grow(d) for every domain d and build(d) for d = 0, 1, ... in this order, each once grow(d) has returned. The
// cells step (build) is serial and was the larger half of a large partition, so it no longer waits for the whole
// growth: this thread builds each domain as soon as it has grown and grows the next ungrown domain (a shared
// counter, in domain order) while the one it needs is not ready; the other threads only grow. build(d) sees the
// same inputs in the same order whatever the timing, so the complex does not depend on the thread count. Returns
// when the last domain had grown (log::now_seconds).
template <class Grow, class Build>
double grow_then_build(std::size_t n, Grow&& grow, Build&& build) {
  const int threads = std::min<int>(static_cast<int>(tbb::global_control::active_value(
                                        tbb::global_control::max_allowed_parallelism)),
                                    tbb::this_task_arena::max_concurrency());
  std::atomic<std::size_t> next{0};  // the next domain nobody grows yet
  std::atomic<bool> stop{false};     // an error: take no more work
  std::mutex mutex;
  std::condition_variable grown_cv;
  std::vector<char> grown(n, 0);  // guarded by mutex
  std::size_t grown_count = 0;    // guarded by mutex
  double growth_end = log::now_seconds();
  std::exception_ptr worker_error;  // guarded by mutex
  // Grows one more domain; false when none is left.
  auto grow_one = [&]() {
    const std::size_t d = next.fetch_add(1);
    if (d >= n || stop.load()) return false;
    grow(d);
    {
      std::lock_guard<std::mutex> lock(mutex);
      grown[d] = 1;
      if (++grown_count == n) growth_end = log::now_seconds();
    }
    grown_cv.notify_all();
    return true;
  };
  tbb::task_group workers;
  for (int w = 1; w < threads; ++w)
    workers.run([&] {
      try {
        while (grow_one()) {
        }
      } catch (...) {
        std::lock_guard<std::mutex> lock(mutex);
        if (!worker_error) worker_error = std::current_exception();
        stop = true;
        grown_cv.notify_all();
      }
    });
  try {
    for (std::size_t d = 0; d < n; ++d) {
      for (;;) {
        {
          std::unique_lock<std::mutex> lock(mutex);
          if (worker_error) break;
          if (grown[d]) break;
        }
        if (grow_one()) continue;
        // Every domain is taken: wait for the one needed (or for a worker's error).
        std::unique_lock<std::mutex> lock(mutex);
        grown_cv.wait(lock, [&] { return grown[d] != 0 || worker_error; });
        break;
      }
      {
        std::lock_guard<std::mutex> lock(mutex);
        if (worker_error) break;
      }
      build(d);
    }
  } catch (...) {
    stop = true;
    workers.wait();
    throw;
  }
  workers.wait();
  if (worker_error) std::rethrow_exception(worker_error);
  return growth_end;
}

}  // namespace

KineticStats run_kinetic(const PartitionInput& input, const PartitionParams& params, ComplexBuilder& builder) {
  const bool hierarchical = params.method == Partitioner::Hierarchical;
  if (params.kinetic_k < 1)
    throw Error(Status::BadInput, kStage, "kinetic_k must be >= 1 (got " + std::to_string(params.kinetic_k) + ")");
  if (params.max_polygons_per_domain < 1)
    throw Error(Status::BadInput, kStage, "max_polygons_per_domain must be >= 1");
  if (params.max_crossings < 0) throw Error(Status::BadInput, kStage, "max_crossings must be >= 0");
  const std::vector<KPolygon> polys = prepare(input, params, builder);
  const BBox& box = builder.cell_bbox(0);
  const double diag = (box.max - box.min).norm();
  const double slack = 1e-9 * diag;
  constexpr int kMaxSubdivisionDepth = 10;

  KineticStats stats;
  const int max_level = hierarchical ? 3 : 1;
  std::unique_ptr<tbb::global_control> threads_limit;
  if (params.threads > 0)
    threads_limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                          static_cast<std::size_t>(params.threads));

  for (int level = 1; level <= max_level; ++level) {
    std::vector<int> level_polys;
    for (std::size_t i = 0; i < polys.size(); ++i)
      if (polys[i].level == level) level_polys.push_back(static_cast<int>(i));
    if (level_polys.empty()) continue;
    double t = log::now_seconds();
    auto lap = [&](double& acc) {
      const double now = log::now_seconds();
      acc += now - t;
      t = now;
    };
    // 1. Domains: the live cells some polygon of this level meets, split while they hold too many.
    std::vector<Domain> pending;
    {
      const int cells_before = builder.num_cells();
      std::vector<Domain> of_cell(static_cast<std::size_t>(cells_before));  // in parallel, then in cell order
      tbb::parallel_for(0, cells_before, [&](int c) {
        if (!builder.alive(c)) return;
        Domain& d = of_cell[static_cast<std::size_t>(c)];
        d.cell = c;
        for (int i : level_polys) d.add(i, polygon_in_cell(builder, c, polys[i], slack));
      });
      for (Domain& d : of_cell)
        if (!d.members.empty()) pending.push_back(std::move(d));
    }
    std::vector<Domain> domains;
    std::vector<int> depth(pending.size(), 0);
    while (!pending.empty()) {
      Domain d = std::move(pending.back());
      pending.pop_back();
      const int dep = depth.back();
      depth.pop_back();
      if (static_cast<int>(d.members.size()) <= params.max_polygons_per_domain || dep >= kMaxSubdivisionDepth) {
        domains.push_back(std::move(d));
        continue;
      }
      // The wall: the support plane of one of the domain's polygons (it meets the cell, so its plane crosses
      // it), as a bsp step; that polygon is then done: its plane bounds every cell it could reach here. The
      // plane that splits the other polygons most evenly (fewest on its fuller side, a polygon it cuts
      // counting on both; ties: the larger polygon, then the first), so sub-domains shrink fast. A heuristic
      // in doubles: it only chooses among exact walls.
      int wall_member = d.members.front();
      {
        std::size_t best = ~std::size_t{0};
        for (int i : d.members) {
          const ExactPlane& pl = builder.plane(polys[i].plane).exact;
          const double a = pl.a.get_d(), b = pl.b.get_d(), c = pl.c.get_d(), dd = pl.d.get_d();
          std::size_t pos_n = 0, neg_n = 0;
          for (int j : d.members) {
            if (j == i) continue;
            bool pos = false, neg = false;
            for (const Vec3& q : polys[j].shape3d) {
              const double v = a * q.x() + b * q.y() + c * q.z() + dd;
              pos |= v > 0;
              neg |= v < 0;
            }
            pos_n += pos;
            neg_n += neg;
          }
          const std::size_t score = std::max(pos_n, neg_n);
          if (score < best || (score == best && polys[i].area > polys[wall_member].area)) {
            best = score;
            wall_member = i;
          }
        }
      }
      const int h = polys[wall_member].plane;
      builder.split(d.cell, h, level);
      ++stats.subdomain_splits;
      for (int half : {d.cell, builder.num_cells() - 1}) {
        Domain e;
        e.cell = half;
        for (int i : d.members)
          if (i != wall_member) e.add(i, polygon_in_cell(builder, half, polys[i], slack));
        if (e.members.empty()) continue;
        pending.push_back(std::move(e));
        depth.push_back(dep + 1);
      }
    }
    std::sort(domains.begin(), domains.end(), [](const Domain& a, const Domain& b) { return a.cell < b.cell; });
    stats.domains += static_cast<int>(domains.size());

    lap(stats.seconds_domains);
    // 2. Growth, in parallel over the domains (each reads the builder's planes only, which the cells step does not
    // change); one time function per polygon, shared by its domains.
    std::vector<std::shared_ptr<const ArrivalTime>> times(polys.size());
    tbb::parallel_for(std::size_t(0), level_polys.size(), [&](std::size_t n) {
      const KPolygon& k = polys[level_polys[n]];
      times[level_polys[n]] = std::make_shared<const ArrivalTime>(k.shape, k.time_scale);
    });
    std::vector<std::vector<GrownRegion>> regions(domains.size());
    auto grow_domain = [&](std::size_t d) {
      Domain& dom = domains[d];  // its sections are moved into the growth input (not used afterwards)
      std::vector<GrowthPolygon> input;
      input.reserve(dom.members.size());  // (GMP's rationals move without noexcept: a growing vector copies)
      GrowthRules rules;
      rules.hierarchical = hierarchical;
      rules.k = params.kinetic_k;
      rules.max_crossings = params.max_crossings;
      rules.cross_to_bounds = params.cross_to_bounds;
      rules.meet_at_point = params.meet_at_point;
      rules.wait_at_bounds = params.wait_at_bounds;
      rules.trim = hierarchical && params.trim;
      for (std::size_t mi = 0; mi < dom.members.size(); ++mi) {
        const int i = dom.members[mi];
        const KPolygon& k = polys[i];
        GrowthPolygon g;
        g.id = i;
        g.plane = builder.plane(k.plane).exact;
        g.integer = builder.int_plane_of(k.plane);
        g.frame = builder.frame(k.plane);
        g.shape = k.shape;
        g.time_scale = k.time_scale;
        g.domain = std::move(dom.sections[mi]);
        if (dom.members.size() > 1) g.seed = common_interior_point(k.shape, g.domain);  // (alone: lone_region)
        g.time = times[i];
        input.push_back(std::move(g));
        std::vector<int> adj;
        for (int j : k.adjacent) {
          auto it = std::lower_bound(dom.members.begin(), dom.members.end(), j);
          if (it != dom.members.end() && *it == j) adj.push_back(static_cast<int>(it - dom.members.begin()));
        }
        rules.adjacent.push_back(std::move(adj));
      }
      regions[d] = input.size() == 1 ? std::vector<GrownRegion>{lone_region(input[0])} : grow_regions(input, rules);
    };
    // 3. Cells, in domain order (deterministic), each domain as soon as it has grown (grow_then_build).
    auto build_cells = [&](std::size_t d) {
      for (const GrownRegion& r : regions[d]) {
        stats.faces += static_cast<long long>(r.faces.size());
        stats.stops += r.stops;
        stats.crossings += r.crossings;
      }
      build_domain(builder, domains[d], polys, std::move(regions[d]), level, slack);
    };
    const double growth_end = grow_then_build(domains.size(), grow_domain, build_cells);
    stats.seconds_growth += growth_end - t;  // (the cells step overlaps it: "cells" is the time after the growth)
    t = growth_end;
    lap(stats.seconds_cells);
  }
  return stats;
}

}  // namespace hsr::partition_internal
