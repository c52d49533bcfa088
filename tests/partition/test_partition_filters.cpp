// Issue 25: the partition's arithmetic filters change no decision. Every partitioner, on fixed random inputs
// generated here, gives the same complex as (1) the partition code before the filters of issue 25 (commit
// 55846fa): a digest of the whole complex (exact vertices, their doubles, facets, cells, exact volumes,
// centroids) recorded from that code; and (2) the same code with every filter off (partition_internal::
// set_filters(false): each decision then comes from the exact rational evaluation). Each complex is also
// validated with coverage.
#include "partition/exact_geometry.h"
#include "partition/partition.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>

#include "partition_fixtures.h"

namespace hsr {
namespace {

// FNV-1a over a canonical serialisation of the complex.
class Digest {
 public:
  void bytes(const void* data, std::size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) h_ = (h_ ^ p[i]) * 1099511628211ull;
  }
  void integer(long long v) { bytes(&v, sizeof v); }
  void real(double d) {
    std::uint64_t bits;
    std::memcpy(&bits, &d, sizeof bits);
    integer(static_cast<long long>(bits));
  }
  void rational(const Rational& q) {
    const std::string s = q.get_str(16);
    integer(static_cast<long long>(s.size()));
    bytes(s.data(), s.size());
  }
  std::uint64_t value() const { return h_; }

 private:
  std::uint64_t h_ = 1469598103934665603ull;
};

std::uint64_t digest(const CellComplex& cx) {
  Digest d;
  d.integer(static_cast<long long>(cx.planes.size()));
  for (const SupportPlane& p : cx.planes) {
    for (const Rational* q : {&p.exact.a, &p.exact.b, &p.exact.c, &p.exact.d}) d.rational(*q);
    d.integer(static_cast<int>(p.kind));
    for (int id : p.input_planes) d.integer(id);
  }
  d.integer(static_cast<long long>(cx.vertices.size()));
  for (std::size_t v = 0; v < cx.vertices.size(); ++v) {
    for (const Rational* q : {&cx.vertices[v].x, &cx.vertices[v].y, &cx.vertices[v].z}) d.rational(*q);
    for (int k = 0; k < 3; ++k) d.real(cx.vertices_approx[v][k]);
  }
  d.integer(static_cast<long long>(cx.facets.size()));
  for (const Facet& f : cx.facets) {
    d.integer(f.plane);
    d.integer(f.cells[0]);
    d.integer(f.cells[1]);
    d.integer(f.level);
    d.integer(static_cast<long long>(f.vertices.size()));
    for (auto v : f.vertices) d.integer(v);
  }
  d.integer(static_cast<long long>(cx.cells.size()));
  for (const Cell& c : cx.cells) {
    d.integer(static_cast<long long>(c.facets.size()));
    for (auto f : c.facets) d.integer(f);
    d.rational(c.volume);
    d.real(c.volume_approx);
    for (int k = 0; k < 3; ++k) d.real(c.centroid[k]);
  }
  return d.value();
}

// bench_partition's random rectangles (centre uniform in the unit cube, half sizes uniform in [lo, hi],
// normal uniform on the sphere or, with probability axis_fraction, an axis), with a random level and speed.
// grid > 0 snaps centres and half sizes to multiples of 1/grid: coplanar, collinear and concurrent planes.
std::vector<ConvexPolygon> rectangles(std::uint64_t seed, int count, double axis_fraction, double lo, double hi,
                                      int grid = 0) {
  std::mt19937_64 rng(seed);
  auto snap = [&](double x) { return grid > 0 ? std::round(x * grid) / grid : x; };
  std::vector<ConvexPolygon> out;
  for (int i = 0; i < count; ++i) {
    Vec3 n;
    if (uniform(rng, 0, 1) < axis_fraction) {
      n = Vec3::Zero();
      n[static_cast<int>(rng() % 3)] = 1;
    } else {
      do n = Vec3(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1));
      while (n.norm() < 1e-2 || n.norm() > 1);
      n.normalize();
    }
    const Vec3 c(snap(uniform(rng, 0, 1)), snap(uniform(rng, 0, 1)), snap(uniform(rng, 0, 1)));
    const Vec3 u = n.unitOrthogonal(), v = n.cross(u);
    const double hu = std::max(snap(uniform(rng, lo, hi)), lo), hv = std::max(snap(uniform(rng, lo, hi)), lo);
    ConvexPolygon p;
    p.plane_id = i;
    p.level = 1 + static_cast<int>(rng() % 3);
    p.speed = uniform(rng, 0.5, 1.0);
    p.plane.normal = n;
    p.plane.offset = -n.dot(c);
    p.vertices = {c - hu * u - hv * v, c + hu * u - hv * v, c + hu * u + hv * v, c - hu * u + hv * v};
    out.push_back(p);
  }
  return out;
}

// bench_partition's stand-in adjacency: two polygons of one level whose bounding boxes overlap.
std::vector<std::pair<int, int>> bbox_adjacency(const std::vector<ConvexPolygon>& polys) {
  std::vector<BBox> boxes;
  for (const auto& p : polys) {
    BBox b;
    for (const Vec3& v : p.vertices) b.extend(v);
    boxes.push_back(b);
  }
  std::vector<std::pair<int, int>> out;
  for (std::size_t i = 0; i < polys.size(); ++i)
    for (std::size_t j = i + 1; j < polys.size(); ++j)
      if (polys[i].level == polys[j].level && !((boxes[i].min.array() > boxes[j].max.array()).any() ||
                                                 (boxes[j].min.array() > boxes[i].max.array()).any()))
        out.emplace_back(polys[i].plane_id, polys[j].plane_id);
  return out;
}

struct Case {
  std::string name;
  std::vector<ConvexPolygon> polygons;
  PartitionParams params;  // method and the other fields; threads = 1 and no exact volumes unless set here
};

PartitionParams with(Partitioner method, double margin = 0.0) {
  PartitionParams p;
  p.method = method;
  p.bbox_margin = margin;
  p.threads = 1;
  return p;
}

std::vector<Case> cases() {
  const auto dense = rectangles(2501, 45, 0.0, 0.05, 0.3);         // bench_partition's dense set
  const auto cad = rectangles(2502, 50, 0.7, 0.0625, 0.375, 16);  // axis-aligned, on a 1/16 grid
  const auto convex = random_polygons(2503, 30);                  // convex polygons of 3-8 vertices
  auto first = [](const std::vector<ConvexPolygon>& v, int n) {
    return std::vector<ConvexPolygon>(v.begin(), v.begin() + n);
  };
  std::vector<Case> out;
  for (Partitioner m : {Partitioner::Bsp, Partitioner::Kinetic, Partitioner::Hierarchical}) {
    out.push_back({"dense", m == Partitioner::Bsp ? first(dense, 25) : dense, with(m)});
    out.push_back({"cad", cad, with(m, 0.05)});
    out.push_back({"convex", convex, with(m)});
  }
  PartitionParams p = with(Partitioner::Kinetic);
  p.kinetic_k = 2;
  out.push_back({"dense k=2", dense, p});
  out.push_back({"dense", first(dense, 14), with(Partitioner::Exhaustive)});
  out.push_back({"cad", first(cad, 18), with(Partitioner::Exhaustive, 0.05)});
  out.push_back({"convex", first(convex, 12), with(Partitioner::Exhaustive)});
  // The hierarchical rules' switches (issue 17) and small sub-domains.
  p = with(Partitioner::Hierarchical);
  p.wait_at_bounds = p.trim = true;
  out.push_back({"cad wait+trim", cad, p});
  p = with(Partitioner::Hierarchical);
  p.meet_at_point = true;
  out.push_back({"convex meet_at_point", convex, p});
  p = with(Partitioner::Hierarchical);
  p.cross_to_bounds = false;
  p.max_polygons_per_domain = 6;
  out.push_back({"dense no crossing, 6 per domain", first(dense, 30), p});
  p = with(Partitioner::Kinetic);
  p.max_polygons_per_domain = 5;
  out.push_back({"convex 5 per domain", convex, p});
  return out;
}

CellComplex partition(const Case& c, int threads = 1) {
  PartitionParams params = c.params;
  params.threads = threads;
  BBox box;
  for (const ConvexPolygon& p : c.polygons)
    for (const Vec3& v : p.vertices) box.extend(v);
  return run_partition({c.polygons, box, bbox_adjacency(c.polygons)}, params);
}

std::string label(const Case& c) { return std::string(partitioner_name(c.params.method)) + " " + c.name; }

// Digests of the complexes of cases(), in order, from the partition before issue 25's filters (55846fa).
const std::uint64_t kRecorded[] = {
    10975249503730281337ull,  // bsp dense
    671741750345790610ull,    // bsp cad
    7454819386891501096ull,   // bsp convex
    16957308938439799524ull,  // kinetic dense
    12973319300999925585ull,  // kinetic cad
    10088642816026000938ull,  // kinetic convex
    2297581808788883561ull,   // hierarchical dense
    9890649742146657831ull,   // hierarchical cad
    8209364940437960880ull,   // hierarchical convex
    12916605609652517174ull,  // kinetic dense k=2
    17070783438516823188ull,  // exhaustive dense
    12961848485972336874ull,  // exhaustive cad
    3981130029094650495ull,   // exhaustive convex
    14787774322655776862ull,  // hierarchical cad wait+trim
    7727918740259893825ull,   // hierarchical convex meet_at_point
    18312572010975903291ull,  // hierarchical dense no crossing, 6 per domain
    11437867679382763103ull,  // kinetic convex 5 per domain
};

TEST(PartitionFilters, SameComplexesAsBeforeTheFilters) {
  const std::vector<Case> all = cases();
  ASSERT_EQ(all.size(), sizeof kRecorded / sizeof kRecorded[0]);
  for (std::size_t i = 0; i < all.size(); ++i) {
    const CellComplex cx = partition(all[i]);
    EXPECT_EQ(digest(cx), kRecorded[i]) << label(all[i]) << ": " << cx.cells.size() << " cells";
    const ValidationReport r = validate(cx, &all[i].polygons);
    EXPECT_TRUE(r.ok) << label(all[i]) << ": " << (r.problems.empty() ? "" : r.problems.front());
  }
}

// Domains grow and are found in parallel: the same bytes on two threads.
TEST(PartitionFilters, SameComplexesOnTwoThreads) {
  const std::vector<Case> all = cases();
  for (std::size_t i : {3u, 6u, 13u})  // kinetic dense, hierarchical dense, hierarchical cad wait+trim
    EXPECT_EQ(digest(partition(all[i], 2)), kRecorded[i]) << label(all[i]);
}

// Every filter off (partition_internal::set_filters): the same complexes from the exact evaluations alone.
TEST(PartitionFilters, SameComplexesWithTheFiltersOff) {
  const std::vector<Case> all = cases();
  partition_internal::set_filters(false);
  std::vector<std::uint64_t> exact;
  for (const Case& c : all) exact.push_back(digest(partition(c)));
  partition_internal::set_filters(true);
  for (std::size_t i = 0; i < all.size(); ++i) EXPECT_EQ(exact[i], kRecorded[i]) << label(all[i]);
}

}  // namespace
}  // namespace hsr
