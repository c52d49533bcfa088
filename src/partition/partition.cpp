#include "partition/partition.h"

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/log.h"
#include "partition/complex_builder.h"
#include "partition/growth_rules.h"
#include "partition/kinetic.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <map>
#include <numeric>

namespace hsr {

using namespace partition_internal;

namespace {

constexpr const char* kStage = "partition";

// One input polygon, registered on its support plane.
struct Prepared {
  int plane = -1;
  std::vector<P2> poly2d;  // exact 2D convex hull in the support plane's frame; empty if degenerate
  double area = 0;         // approximate 3D area (ordering only)
  int level = 1;
  int plane_id = -1;       // the input polygon's plane id (adjacency is given in these)
};

std::vector<Prepared> register_polygons(const PartitionInput& input, ComplexBuilder& builder) {
  std::vector<Prepared> out;
  out.reserve(input.polygons.size());
  for (const ConvexPolygon& poly : input.polygons) {
    Prepared p;
    p.plane = builder.add_plane(canonical_plane(poly.plane));
    auto& ids = builder.plane(p.plane).input_planes;
    if (std::find(ids.begin(), ids.end(), poly.plane_id) == ids.end()) ids.push_back(poly.plane_id);
    const ExactPlane exact = builder.plane(p.plane).exact;
    p.poly2d = project_polygon(poly, exact, builder.frame(p.plane));
    if (!p.poly2d.empty())
      p.area = 0.5 * twice_area(p.poly2d).get_d() * area_scale(exact, builder.frame(p.plane));
    p.level = poly.level;
    p.plane_id = poly.plane_id;
    out.push_back(std::move(p));
  }
  return out;
}

void run_exhaustive(const std::vector<Prepared>& polys, ComplexBuilder& builder) {
  // Every plane carrying an input polygon, in plane id order (deterministic), at the lowest level on it.
  std::vector<int> level(builder.num_planes(), -1);
  for (const Prepared& p : polys)
    if (level[p.plane] < 0 || p.level < level[p.plane]) level[p.plane] = p.level;
  log::Progress progress(kStage, "exhaustive partition (planes)", static_cast<std::size_t>(builder.num_planes()));
  for (int h = 0; h < builder.num_planes(); ++h) {
    progress.update(static_cast<std::size_t>(h));
    if (level[h] < 0 || builder.plane(h).kind != SupportPlane::Kind::Input) continue;
    const int n = builder.num_cells();  // children of this pass lie on one side of h
    for (int c = 0; c < n; ++c)
      if (builder.may_cross(c, h) && builder.crosses(c, h)) builder.split(c, h, level[h]);
  }
  progress.finish();
}

// The polygon extended to its bounds (the bounds rule of growth_rules.h, applied once): the support plane's
// section of the box, clipped by the bounds' halfplanes, joined with the polygon itself. Unchanged without
// bounds.
std::vector<P2> extend_to_bounds(const Prepared& p, const std::vector<const Prepared*>& adjacent,
                                 ComplexBuilder& builder, const ExactPoint& lo, const ExactPoint& hi) {
  if (p.poly2d.empty()) return p.poly2d;
  const ExactPlane& plane = builder.plane(p.plane).exact;
  const PlaneFrame& frame = builder.frame(p.plane);
  // The box's projection on the two kept axes, clipped to the box itself (the dropped axis).
  const Rational* l[3] = {&lo.x, &lo.y, &lo.z};
  const Rational* h[3] = {&hi.x, &hi.y, &hi.z};
  int ku = (frame.drop + 1) % 3, kv = (frame.drop + 2) % 3;
  if (frame.swap) std::swap(ku, kv);
  std::vector<P2> section{{*l[ku], *l[kv]}, {*h[ku], *l[kv]}, {*h[ku], *h[kv]}, {*l[ku], *h[kv]}};
  if (twice_area(section) < 0) std::reverse(section.begin(), section.end());
  section = clip_to_box(section, plane, frame, lo, hi);
  if (section.size() < 3) return p.poly2d;
  std::vector<Line> lines;
  for (const Prepared* q : adjacent) {
    Line line;
    if (q->plane != p.plane &&
        line_between(builder.int_plane_of(p.plane), frame, builder.int_plane_of(q->plane), section, line))
      lines.push_back(std::move(line));
  }
  const std::vector<Bound> bounds = find_bounds(ArrivalTime(p.poly2d, 1), lines, std::vector<char>(lines.size(), 1));
  if (bounds.empty()) return p.poly2d;
  std::vector<P2> region = clip_to_bounds(std::move(section), bounds, lines);
  region.insert(region.end(), p.poly2d.begin(), p.poly2d.end());
  return convex_hull(std::move(region));
}

/// Splits every live cell whose interior the polygon crosses with positive area by the polygon's plane.
void split_cells_by(const Prepared& p, ComplexBuilder& builder, double slack) {
  if (p.poly2d.empty() || builder.plane(p.plane).kind != SupportPlane::Kind::Input) return;
  BBox pb;
  std::vector<Vec3> poly3d;
  for (const P2& q : p.poly2d) {
    poly3d.push_back(to_double(lift(builder.int_plane_of(p.plane), builder.frame(p.plane), q)));
    pb.extend(poly3d.back());
  }
  std::vector<int> to_split;
  const int n = builder.num_cells();
  for (int c = 0; c < n; ++c) {
    if (!builder.alive(c)) continue;  // merged away by a kinetic partitioner (PartitionInput::cuts)
    const BBox& cb = builder.cell_bbox(c);
    if (filters_on() &&
        (((cb.min.array() - slack) > pb.max.array()).any() || ((cb.max.array() + slack) < pb.min.array()).any()))
      continue;
    if (!builder.may_cross(c, p.plane) || !builder.may_meet_polygon(c, poly3d) || !builder.crosses(c, p.plane))
      continue;
    if (interiors_overlap(builder.section(c, p.plane), p.poly2d)) to_split.push_back(c);
  }
  for (int c : to_split) builder.split(c, p.plane, p.level);
}

void run_bsp(const std::vector<Prepared>& polys, ComplexBuilder& builder, double slack) {
  std::vector<std::size_t> order(polys.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return polys[a].area > polys[b].area; });
  log::Progress progress(kStage, "bsp partition (polygons)", polys.size());
  std::size_t done = 0;
  for (std::size_t i : order) {
    progress.update(done++);
    split_cells_by(polys[i], builder, slack);
  }
  progress.finish();
}

/// PartitionInput::cuts, in their order, after the partitioner.
void insert_cuts(const PartitionInput& input, ComplexBuilder& builder, double slack) {
  if (input.cuts.empty()) return;
  PartitionInput cuts_only;
  cuts_only.polygons = input.cuts;
  for (const Prepared& p : register_polygons(cuts_only, builder)) split_cells_by(p, builder, slack);
}

}  // namespace

void partition_box(const BBox& b, double margin, ExactPoint& lo, ExactPoint& hi) {
  if (!b.valid() || !b.min.allFinite() || !b.max.allFinite())
    throw Error(Status::BadInput, kStage, "the points' bounding box is empty or not finite");
  if (!(margin >= 0) || !std::isfinite(margin))
    throw Error(Status::BadInput, kStage, "bbox_margin must be >= 0 (got " + std::to_string(margin) + ")");
  const double diag = b.diagonal();
  if (!(diag > 0)) throw Error(Status::BadInput, kStage, "the points' bounding box has zero diagonal");
  const double m = margin * diag;
  const double step = std::ldexp(1.0, std::ilogb(diag) - 10);
  double l[3], h[3];
  for (int k = 0; k < 3; ++k) {
    l[k] = std::floor((b.min[k] - m) / step) * step;
    h[k] = std::ceil((b.max[k] + m) / step) * step;
    if (!(l[k] < h[k]))
      throw Error(Status::DegenerateInput, kStage,
                  std::string("the partition box has zero extent along ") + "xyz"[k] + " (use bbox_margin > 0)");
  }
  lo = {Rational(l[0]), Rational(l[1]), Rational(l[2])};
  hi = {Rational(h[0]), Rational(h[1]), Rational(h[2])};
}

CellComplex run_partition(const PartitionInput& input, const PartitionParams& params) {
  ExactPoint lo, hi;
  partition_box(input.points_bbox, params.bbox_margin, lo, hi);
  ComplexBuilder builder(lo, hi);
  const double t0 = log::now_seconds();
  if (params.method == Partitioner::Kinetic || params.method == Partitioner::Hierarchical) {
    const KineticStats st = run_kinetic(input, params, builder);
    log::verbose(std::string("partition: ") + partitioner_name(params.method) + ": " + std::to_string(st.domains) +
                 " domains (" + std::to_string(st.subdomain_splits) + " sub-domain splits), " + std::to_string(st.faces) +
                 " region faces, " + std::to_string(st.stops) + " stops, " + std::to_string(st.crossings) +
                 " crossings; seconds: domains " + std::to_string(st.seconds_domains) + ", growth " +
                 std::to_string(st.seconds_growth) + ", cells " + std::to_string(st.seconds_cells));
  } else {
    std::vector<Prepared> polys = register_polygons(input, builder);
    if (params.method == Partitioner::Exhaustive) {
      run_exhaustive(polys, builder);
    } else {
      if (params.bsp_extend) {
        std::map<int, std::vector<int>> on_plane_id;  // input plane id -> polygons
        for (std::size_t i = 0; i < polys.size(); ++i) on_plane_id[polys[i].plane_id].push_back(static_cast<int>(i));
        std::vector<std::vector<const Prepared*>> adjacent(polys.size());
        for (const auto& [a, b] : input.adjacent_planes) {
          if (a == b || !on_plane_id.count(a) || !on_plane_id.count(b)) continue;
          for (int i : on_plane_id[a])
            for (int j : on_plane_id[b]) {
              adjacent[i].push_back(&polys[j]);
              adjacent[j].push_back(&polys[i]);
            }
        }
        std::vector<std::vector<P2>> extended(polys.size());
        for (std::size_t i = 0; i < polys.size(); ++i) extended[i] = extend_to_bounds(polys[i], adjacent[i], builder, lo, hi);
        for (std::size_t i = 0; i < polys.size(); ++i) polys[i].poly2d = std::move(extended[i]);
      }
      run_bsp(polys, builder, 1e-9 * (to_double(hi) - to_double(lo)).norm());
    }
  }
  insert_cuts(input, builder, 1e-9 * (to_double(hi) - to_double(lo)).norm());
  const double t_finish = log::now_seconds();
  CellComplex out = std::move(builder).finish(params.exact_volumes);
  log::verbose(std::string("partition: complex assembled") + (params.exact_volumes ? " (exact volumes)" : "") +
               " in " + std::to_string(log::now_seconds() - t_finish) + " s");
  log::verbose(std::string("partition: ") + partitioner_name(params.method) + ", " +
               std::to_string(input.polygons.size()) + " polygons on " +
               std::to_string(out.planes.size() - 6) + " planes -> " + std::to_string(out.cells.size()) +
               " cells, " + std::to_string(out.facets.size()) + " facets, " + std::to_string(out.vertices.size()) +
               " vertices in " + std::to_string(log::now_seconds() - t0) + " s");
  return out;
}

const char* partitioner_name(Partitioner p) {
  switch (p) {
    case Partitioner::Exhaustive: return "exhaustive";
    case Partitioner::Bsp: return "bsp";
    case Partitioner::Kinetic: return "kinetic";
    case Partitioner::Hierarchical: return "hierarchical";
  }
  return "?";
}

Partitioner parse_partitioner(const std::string& name) {
  for (Partitioner p : {Partitioner::Exhaustive, Partitioner::Bsp, Partitioner::Kinetic, Partitioner::Hierarchical})
    if (name == partitioner_name(p)) return p;
  throw Error(Status::BadInput, kStage,
              "unknown partitioner '" + name + "' (expected exhaustive, bsp, kinetic or hierarchical)");
}

void write_partition_dump(const CellComplex& cx, const std::string& path) {
  std::size_t max_degree = 0;
  for (const Facet& f : cx.facets) max_degree = std::max(max_degree, f.vertices.size());
  AtomicFile file(path, kStage);
  std::ostream& out = file.stream();
  out << "ply\nformat ascii 1.0\ncomment hsr partition dump: every facet, coloured by its support plane\n";
  out << "element vertex " << cx.vertices_approx.size() << "\nproperty double x\nproperty double y\nproperty double z\n";
  out << "element face " << cx.facets.size() << "\nproperty list " << (max_degree > 255 ? "int" : "uchar")
      << " int vertex_indices\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
  out << std::setprecision(17);
  for (const Vec3& v : cx.vertices_approx) out << v.x() << ' ' << v.y() << ' ' << v.z() << '\n';
  for (const Facet& f : cx.facets) {
    out << f.vertices.size();
    for (auto v : f.vertices) out << ' ' << v;
    int rgb[3] = {200, 200, 200};
    if (cx.planes[f.plane].kind != SupportPlane::Kind::BoxSide) {
      // Hue by golden-ratio steps: neighbouring plane ids get well separated colours.
      const double hue = std::fmod(f.plane * 0.6180339887498949, 1.0) * 6.0;
      const double s = 0.65, v = 0.95, c = v * s;
      const double x = c * (1.0 - std::abs(std::fmod(hue, 2.0) - 1.0));
      double r = 0, g = 0, b = 0;
      switch (static_cast<int>(hue)) {
        case 0: r = c; g = x; break;
        case 1: r = x; g = c; break;
        case 2: g = c; b = x; break;
        case 3: g = x; b = c; break;
        case 4: r = x; b = c; break;
        default: r = c; b = x; break;
      }
      const double mm = v - c;
      rgb[0] = static_cast<int>(std::lround(255 * (r + mm)));
      rgb[1] = static_cast<int>(std::lround(255 * (g + mm)));
      rgb[2] = static_cast<int>(std::lround(255 * (b + mm)));
    }
    out << ' ' << rgb[0] << ' ' << rgb[1] << ' ' << rgb[2] << '\n';
  }
  file.commit();
}

}  // namespace hsr
