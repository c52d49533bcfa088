// Stage 6: surface extraction (paper §3.6), the labelling and run_extraction's chain. See extraction.h for the
// energy; this file holds
//   1. point-to-facet assignment (the votes of the point term),
//   2. the energy model and its exact minimisation by one s-t min cut (building orders: DECISIONS #24),
//   then the labels' repair (DECISIONS #9) and clean-up (label_cleanup.h, #26) and run_extraction, which turns
//   the surface into polygons (polygons.cpp: coplanar merging, #8; vertex clean-up) and proves them simple (#29).
#include "extraction/extraction.h"

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/face_class.h"
#include "core/log.h"
#include "core/min_cut.h"
#include "extraction/label_cleanup.h"
#include "extraction/polygons.h"
#include "extraction/surface.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <deque>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <utility>

namespace hsr {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr const char* kStage = "extraction";

double facet_area(const CellComplex& cx, const Facet& f) {
  Vec3 newell = Vec3::Zero();
  const std::size_t n = f.vertices.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3& p = cx.vertices_approx[f.vertices[i]];
    const Vec3& q = cx.vertices_approx[f.vertices[(i + 1) % n]];
    newell += p.cross(q);
  }
  return 0.5 * newell.norm();
}

// ---------------------------------------------------------------------------------------------------------
// Inputs.

/// The points' normals: the input's own, or cloud's.
const std::vector<Vec3>& normals_of(const ExtractionInput& in) { return in.normals ? *in.normals : in.cloud->normals; }

void check_input(const ExtractionInput& in) {
  if (!in.complex) throw Error(Status::BadInput, kStage, "no cell complex given");
  if (!in.cloud) throw Error(Status::BadInput, kStage, "no point cloud given");
  if (!in.point_plane) throw Error(Status::BadInput, kStage, "no point-to-plane assignment given");
  const CellComplex& cx = *in.complex;
  if (cx.cells.empty()) throw Error(Status::BadInput, kStage, "the cell complex has no cells");
  if (cx.vertices_approx.size() != cx.vertices.size())
    throw Error(Status::BadInput, kStage, "cell complex: vertices_approx and vertices differ in size");
  if (!in.cloud->empty() && normals_of(in).size() != in.cloud->size())
    throw Error(Status::BadInput, kStage, "point cloud has no normals (" + std::to_string(in.cloud->size()) + " points)");
  if (in.point_plane->size() != in.cloud->size())
    throw Error(Status::BadInput, kStage,
                "point-to-plane assignment has " + std::to_string(in.point_plane->size()) + " entries for " +
                    std::to_string(in.cloud->size()) + " points");
  if (!(in.spacing > 0.0) || !std::isfinite(in.spacing))
    throw Error(Status::BadInput, kStage, "point spacing r must be positive and finite, got " + std::to_string(in.spacing));
}

// ---------------------------------------------------------------------------------------------------------
// 1. Point votes.

struct FacetVotes {
  std::size_t agree = 0;     ///< inliers with n·N > 0: want cells[0] outside, cells[1] inside
  std::size_t oppose = 0;    ///< inliers with n·N < 0: want cells[0] inside, cells[1] outside
  std::size_t assigned = 0;  ///< |I_f|: all inliers assigned to the facet (including n·N == 0)
};

/// Assigns each inlier to the first facet (by index) of its support plane whose polygon contains the point's
/// projection; points whose plane carries no facet, or which fall outside every facet, do not vote.
std::vector<FacetVotes> assign_points(const ExtractionInput& in, std::size_t* voting_points) {
  const CellComplex& cx = *in.complex;
  const PointCloud& cloud = *in.cloud;
  const std::vector<Vec3>& normals = normals_of(in);
  std::vector<FacetVotes> votes(cx.facets.size());
  *voting_points = 0;

  // input plane id -> support plane (the first one listing it). A box side lists the input planes that
  // coincide with it (a tight partition box), and their inliers vote on its facets like any others.
  std::map<int, int> support_of_input;
  for (std::size_t s = 0; s < cx.planes.size(); ++s)
    for (int id : cx.planes[s].input_planes) support_of_input.emplace(id, static_cast<int>(s));

  std::vector<std::vector<int>> facets_of_plane(cx.planes.size());
  for (std::size_t f = 0; f < cx.facets.size(); ++f) {
    const int s = cx.facets[f].plane;
    HSR_ASSERT(s >= 0 && static_cast<std::size_t>(s) < cx.planes.size(), "facet with an invalid support plane");
    facets_of_plane[s].push_back(static_cast<int>(f));
  }

  std::vector<std::vector<std::size_t>> points_of_plane(cx.planes.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const int id = (*in.point_plane)[i];
    if (id < 0) continue;
    const auto it = support_of_input.find(id);
    if (it != support_of_input.end()) points_of_plane[it->second].push_back(i);
  }

  // Containment tolerance: far below any feature of the complex, far above double rounding of the vertices.
  const double eps = 1e-9 * std::max(cx.box.diagonal(), 1e-30);

  for (std::size_t s = 0; s < cx.planes.size(); ++s) {
    const auto& facet_ids = facets_of_plane[s];
    if (points_of_plane[s].empty() || facet_ids.empty()) continue;
    // Orthonormal frame (u, v) with u × v = N: facet loops (CCW about N) are CCW in it.
    const Vec3 normal = cx.planes[s].approx.normal.normalized();
    const Vec3 u = (std::abs(normal.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(normal).normalized();
    const Vec3 v = normal.cross(u);
    std::vector<std::vector<Vec2>> polys(facet_ids.size());
    Vec2 lo = Vec2::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    std::vector<std::pair<Vec2, Vec2>> boxes(facet_ids.size());
    for (std::size_t k = 0; k < facet_ids.size(); ++k) {
      Vec2 blo = Vec2::Constant(std::numeric_limits<double>::infinity()), bhi = -blo;
      for (std::uint32_t vid : cx.facets[facet_ids[k]].vertices) {
        const Vec3& p = cx.vertices_approx[vid];
        const Vec2 q(p.dot(u), p.dot(v));
        polys[k].push_back(q);
        blo = blo.cwiseMin(q);
        bhi = bhi.cwiseMax(q);
      }
      boxes[k] = {blo, bhi};
      lo = lo.cwiseMin(blo);
      hi = hi.cwiseMax(bhi);
    }
    // Uniform grid of about one facet per bin; each bin lists the facets whose box meets it, ascending.
    const int grid = std::max(1, static_cast<int>(std::ceil(std::sqrt(static_cast<double>(facet_ids.size())))));
    const Vec2 extent = (hi - lo).cwiseMax(Vec2::Constant(1e-300));
    auto bin_of = [&](double value, int axis) {
      const int b = static_cast<int>(std::floor((value - lo[axis]) / extent[axis] * grid));
      return std::clamp(b, 0, grid - 1);
    };
    std::vector<std::vector<int>> bins(static_cast<std::size_t>(grid) * grid);
    for (std::size_t k = 0; k < facet_ids.size(); ++k) {
      const int x0 = bin_of(boxes[k].first.x() - eps, 0), x1 = bin_of(boxes[k].second.x() + eps, 0);
      const int y0 = bin_of(boxes[k].first.y() - eps, 1), y1 = bin_of(boxes[k].second.y() + eps, 1);
      for (int bx = x0; bx <= x1; ++bx)
        for (int by = y0; by <= y1; ++by) bins[static_cast<std::size_t>(bx) * grid + by].push_back(static_cast<int>(k));
    }
    auto contains = [&](const std::vector<Vec2>& poly, const Vec2& q) {
      const std::size_t n = poly.size();
      for (std::size_t i = 0; i < n; ++i) {
        const Vec2 e = poly[(i + 1) % n] - poly[i];
        const Vec2 w = q - poly[i];
        const double cross = e.x() * w.y() - e.y() * w.x();
        if (cross < -eps * e.norm()) return false;
      }
      return true;
    };
    for (std::size_t i : points_of_plane[s]) {
      const Vec3& p = cloud.points[i];
      const Vec2 q(p.dot(u), p.dot(v));
      if (q.x() < lo.x() - eps || q.y() < lo.y() - eps || q.x() > hi.x() + eps || q.y() > hi.y() + eps) continue;
      for (int k : bins[static_cast<std::size_t>(bin_of(q.x(), 0)) * grid + bin_of(q.y(), 1)]) {
        if (!contains(polys[k], q)) continue;
        FacetVotes& fv = votes[facet_ids[k]];
        const double d = normals[i].dot(normal);
        if (d > 0) ++fv.agree;
        else if (d < 0) ++fv.oppose;
        ++fv.assigned;
        ++*voting_points;
        break;
      }
    }
  }
  return votes;
}

// ---------------------------------------------------------------------------------------------------------
// 2. Energy model: U(x) = constant + Σ_c (x_c ? cost_in : cost_out) + Σ_pairs w [x_a != x_b]
//                        + Σ_orders hard [x_upper and not x_lower]   (building mode).

struct EnergyModel {
  std::vector<double> cost_in, cost_out;
  double constant = 0.0;
  struct Pair {
    int a, b;
    double weight;
  };
  std::vector<Pair> pairs;  ///< between two cells; pairs with the fixed outside node are folded into cost_in
  /// Building mode: across a non-vertical facet, the upper cell may be inside only if the lower one is.
  struct Order {
    int upper, lower;
  };
  std::vector<Order> orders;
  /// Per cell: the cells its orders put below / above it (indices into cells, in the order of `orders`).
  std::vector<std::vector<int>> below, above;
  double hard = 0.0;  ///< the cost of breaking an order: more than every other term together

  double evaluate(const std::vector<bool>& inside) const {
    double e = constant;
    for (std::size_t c = 0; c < cost_in.size(); ++c) e += inside[c] ? cost_in[c] : cost_out[c];
    for (const Pair& p : pairs)
      if (inside[p.a] != inside[p.b]) e += p.weight;
    for (const Order& o : orders)
      if (inside[o.upper] && !inside[o.lower]) e += hard;
    return e;
  }

  /// Per cell: (neighbour cell, pairwise weight).
  std::vector<std::vector<std::pair<int, double>>> neighbours() const {
    std::vector<std::vector<std::pair<int, double>>> out(cost_in.size());
    for (const Pair& p : pairs) {
      out[p.a].push_back({p.b, p.weight});
      out[p.b].push_back({p.a, p.weight});
    }
    return out;
  }

  /// Energy change when cell c changes label (pairs only; callers with orders flip closed sets instead).
  double flip_delta(const std::vector<bool>& inside, const std::vector<std::vector<std::pair<int, double>>>& nb, int c) const {
    double delta = inside[c] ? cost_out[c] - cost_in[c] : cost_in[c] - cost_out[c];
    for (const auto& [d, w] : nb[c]) delta += inside[c] == inside[d] ? w : -w;
    return delta;
  }

  /// The cells that must change with c to keep every order: turning c inside turns the cells below it
  /// inside, turning it outside turns the cells above it outside (transitively). {c} without orders.
  /// `read` (if given) gets the cells whose labels the answer depends on: c and every cell looked at.
  std::vector<int> flip_set(const std::vector<bool>& inside, int c, std::vector<int>* read = nullptr) const {
    std::vector<int> set{c};
    if (read) read->push_back(c);
    if (orders.empty()) return set;
    const bool to_inside = !inside[c];
    const auto& next = to_inside ? below : above;
    // Sets are short (a column of cells): a linear membership test beats a per-call array over all cells.
    for (std::size_t k = 0; k < set.size(); ++k)
      for (int to : next[set[k]]) {
        if (read) read->push_back(to);
        if (inside[to] != to_inside && std::find(set.begin(), set.end(), to) == set.end()) set.push_back(to);
      }
    return set;
  }
};

/// Building mode: the facets of the partition box's bottom are the ground (box side 4 = -z).
bool on_ground(const CellComplex& cx, const Facet& f) {
  const SupportPlane& p = cx.planes[static_cast<std::size_t>(f.plane)];
  return p.kind == SupportPlane::Kind::BoxSide && p.box_side == 4;
}

/// |n_z| of a support plane's unit normal at most this: vertical (a wall or a box side; the building
/// structure's walls are exactly vertical, its roofs at least 5 degrees off).
constexpr double kVerticalPlaneNz = 0.05;
bool is_vertical(const SupportPlane& p) { return std::abs(p.approx.normal.z()) <= kVerticalPlaneNz; }
/// A wall: a vertical data plane (detected or recovered). The box's sides are vertical but no wall: closing
/// the solid there is a guess, not data, and costs the full area term.
bool is_wall(const SupportPlane& p) { return !p.input_planes.empty() && is_vertical(p); }

/// Building mode: the orders across non-vertical interior facets, and the hard cost of breaking one.
void add_building_orders(const CellComplex& cx, EnergyModel& m) {
  for (const Facet& f : cx.facets) {
    const SupportPlane& p = cx.planes[static_cast<std::size_t>(f.plane)];
    if (f.cells[0] < 0 || f.cells[1] < 0 || is_vertical(p)) continue;
    // cells[0] is on the positive side of the plane, i.e. above it when the normal points up.
    const bool positive_is_up = p.approx.normal.z() > 0;
    m.orders.push_back({positive_is_up ? f.cells[0] : f.cells[1], positive_is_up ? f.cells[1] : f.cells[0]});
  }
  m.below.assign(m.cost_in.size(), {});
  m.above.assign(m.cost_in.size(), {});
  for (const auto& o : m.orders) {
    m.below[o.upper].push_back(o.lower);
    m.above[o.lower].push_back(o.upper);
  }
  double total = 1.0;
  for (std::size_t c = 0; c < m.cost_in.size(); ++c) total += m.cost_in[c] + m.cost_out[c];
  for (const auto& pr : m.pairs) total += pr.weight;
  m.hard = 2.0 * total;
}

/// Per support plane of the complex: every input plane lying on it is vouched for by a recovery rule
/// (ExtractionInput::vouched). A detected plane on it keeps the full area term.
std::vector<char> vouched_support_planes(const ExtractionInput& in) {
  const CellComplex& cx = *in.complex;
  std::vector<char> out(cx.planes.size(), 0);
  if (!in.vouched) return out;
  for (std::size_t s = 0; s < cx.planes.size(); ++s) {
    const auto& ids = cx.planes[s].input_planes;
    out[s] = !ids.empty() && std::all_of(ids.begin(), ids.end(), [&](int id) {
      return id >= 0 && static_cast<std::size_t>(id) < in.vouched->size() && (*in.vouched)[static_cast<std::size_t>(id)] != 0;
    });
  }
  return out;
}

/// Per facet: it lies inside a slab a rule vouches solid (ExtractionInput::solid_slabs; DECISIONS #230): its plane
/// is not upright, its centroid lies inside a slab and so does every vertex of both its cells (a spacing r beyond an
/// upright bound allowed: a plane within r stands for a box's side, #73's covers). Why: the slab is a top's thickness
/// down to the underside its rim measured; another level plane through it (a second top at the same height, its fit
/// millimetres off) split each column into cells, and those under it, holding no point, paid their bottom's and
/// sides' area solid and the crossing facet's air, as large: the min-cut left the top a sliver over air. Upright
/// facets are not asked (each column on its own: what of a box's rectangle its top does not cover stays air).
std::vector<char> slab_facets(const ExtractionInput& in) {
  const CellComplex& cx = *in.complex;
  std::vector<char> inside(cx.facets.size(), 0);
  if (!in.solid_slabs || in.solid_slabs->empty()) return inside;
  const double eps = 1e-9 * std::max(cx.box.diagonal(), 1e-30);
  // `q` lies within the slab, `upright` beyond an upright bound and `level` beyond the others at the most.
  const auto within = [&](const std::vector<Plane>& slab, const Vec3& q, double upright, double level) {
    return std::all_of(slab.begin(), slab.end(), [&](const Plane& h) {
      return h.signed_distance(q) < (std::abs(h.normal.z()) <= kVerticalPlaneNz ? upright : level);
    });
  };
  // A cell reaches at most a spacing r beyond an upright bound (a plane within r stands for a box's side: the
  // top's own side recovered at its edge), and not beyond the others (its top's plane, its bottom).
  const auto cell_in_slab = [&](int c, const std::vector<Plane>& slab) {
    for (std::uint32_t f : cx.cells[static_cast<std::size_t>(c)].facets)
      for (std::uint32_t v : cx.facets[f].vertices)
        if (!within(slab, cx.vertices_approx[v], in.spacing, eps)) return false;
    return true;
  };
  for (std::size_t f = 0; f < cx.facets.size(); ++f) {
    const Facet& facet = cx.facets[f];
    if (facet.cells[0] < 0 || facet.cells[1] < 0 || is_vertical(cx.planes[static_cast<std::size_t>(facet.plane)])) continue;
    Vec3 centre = Vec3::Zero();
    for (std::uint32_t v : facet.vertices) centre += cx.vertices_approx[v];
    centre /= static_cast<double>(facet.vertices.size());
    for (const std::vector<Plane>& slab : *in.solid_slabs)
      if (within(slab, centre, -eps, -eps) && cell_in_slab(facet.cells[0], slab) && cell_in_slab(facet.cells[1], slab)) {
        inside[f] = 1;
        break;
      }
  }
  return inside;
}

EnergyModel build_energy(const ExtractionInput& in, const ExtractionParams& params, const std::vector<FacetVotes>& votes) {
  const CellComplex& cx = *in.complex;
  EnergyModel m;
  m.cost_in.assign(cx.cells.size(), 0.0);
  m.cost_out.assign(cx.cells.size(), 0.0);

  std::vector<double> areas(cx.facets.size());
  double total_area = 0.0;
  for (std::size_t f = 0; f < cx.facets.size(); ++f) total_area += (areas[f] = facet_area(cx, cx.facets[f]));
  if (!(total_area > 0.0)) throw Error(Status::DegenerateInput, kStage, "the cell complex has zero total facet area");

  const std::vector<char> vouched = vouched_support_planes(in);
  const std::vector<char> in_slab = slab_facets(in);
  const double point_area = kPi * in.spacing * in.spacing;  // area a point stands for (paper: π r²)
  const double point_weight = point_area / total_area;
  for (std::size_t f = 0; f < cx.facets.size(); ++f) {
    const Facet& facet = cx.facets[f];
    const int positive = facet.cells[0], negative = facet.cells[1];
    const double agree = point_weight * static_cast<double>(votes[f].agree);
    const double oppose = point_weight * static_cast<double>(votes[f].oppose);
    // Unary point votes (paper eq. 3 read per end cell): "agree" points want the positive cell outside and
    // the negative cell inside; "oppose" points the reverse. The outside node is fixed outside.
    if (positive >= 0) {
      m.cost_in[positive] += agree;
      m.cost_out[positive] += oppose;
    } else {
      m.constant += oppose;
    }
    if (negative >= 0) {
      m.cost_out[negative] += agree;
      m.cost_in[negative] += oppose;
    } else {
      m.constant += agree;
    }
    // Area term (paper eq. 4), clamped at zero so the pairwise term stays submodular. Building mode: the
    // ground costs nothing (the solid stands on it), walls only wall_area_weight of it (often unscanned;
    // recovered through the roof outlines), the box's sides in full.
    double weight =
        params.lambda * std::max(0.0, areas[f] - point_area * static_cast<double>(votes[f].assigned)) / total_area;
    if (params.building && on_ground(cx, facet)) weight = 0.0;
    if (params.building && is_wall(cx.planes[static_cast<std::size_t>(facet.plane)])) weight *= params.wall_area_weight;
    if (vouched[static_cast<std::size_t>(facet.plane)]) weight *= params.vouched_area_weight;
    if (in_slab[f]) weight *= params.slab_facet_weight;
    if (weight <= 0.0) continue;
    if (positive >= 0 && negative >= 0) {
      if (positive != negative) m.pairs.push_back({positive, negative, weight});
    } else if (positive >= 0) {
      m.cost_in[positive] += weight;
    } else if (negative >= 0) {
      m.cost_in[negative] += weight;
    }
  }
  if (params.building) add_building_orders(cx, m);
  return m;
}

/// Exact minimiser of the energy by one s-t min cut (core/min_cut.h); label 1 = inside. Ties go to
/// "outside" (the minimal inside set).
std::vector<bool> minimise(const EnergyModel& m) {
  MinCutProblem problem;
  problem.cost0 = m.cost_out;
  problem.cost1 = m.cost_in;
  for (const auto& p : m.pairs) problem.edges.push_back({p.a, p.b, p.weight, p.weight});
  for (const auto& o : m.orders) problem.edges.push_back({o.upper, o.lower, m.hard, 0.0});
  return min_cut_labels(problem);
}

}  // namespace

double extraction_energy(const ExtractionInput& input, const ExtractionParams& params, const std::vector<bool>& inside) {
  check_input(input);
  if (inside.size() != input.complex->cells.size())
    throw Error(Status::BadInput, kStage, "labelling has " + std::to_string(inside.size()) + " entries for " +
                                              std::to_string(input.complex->cells.size()) + " cells");
  std::size_t voting = 0;
  const auto votes = assign_points(input, &voting);
  return build_energy(input, params, votes).evaluate(inside);
}

/// Building mode, when the optimum labels nothing inside (no roof part outweighs its faces): the cell that
/// wins by being inside (largest cost_out - cost_in: its points vote for it) is made inside, with what lies
/// under it, and the rest is solved again; when none wins (a small roof over a tall box's closure faces),
/// the cell most points vote inside (largest cost_out: only votes put cost on "outside"). Returns the
/// number of cells forced (0: no point wanted any cell inside).
std::size_t force_best_cell_inside(EnergyModel& model, std::vector<bool>& inside) {
  int best = -1;
  double best_gain = 0.0, most_votes = 0.0;
  for (std::size_t c = 0; c < model.cost_in.size(); ++c) {
    const double gain = model.cost_out[c] - model.cost_in[c];
    if (gain > best_gain) {
      best = static_cast<int>(c);
      best_gain = gain;
    }
  }
  for (std::size_t c = 0; best < 0 && c < model.cost_in.size(); ++c)
    most_votes = std::max(most_votes, model.cost_out[c]);
  for (std::size_t c = 0; best < 0 && c < model.cost_in.size(); ++c)
    if (most_votes > 0.0 && model.cost_out[c] == most_votes) best = static_cast<int>(c);
  if (best < 0) return 0;
  model.cost_out[static_cast<std::size_t>(best)] += model.hard;
  inside = minimise(model);
  return 1;
}

/// Labels may make inside cells touch along an edge or at a vertex only (a non-manifold surface). Repairs in
/// rounds; each round rebuilds the surface, finds the defects and flips one cell per defect (with the cells
/// that must follow it to keep the building orders, EnergyModel::flip_set):
///   phase 1: the candidate whose flip raises U least, either way; flipped cells are locked;
///   phase 2 (if phase 1 gets stuck): only outside cells may turn inside. Growing the inside set
///            monotonically must end (at worst with every cell inside: the box), so the repair always
///            terminates with a 2-manifold.
/// Returns the final surface and its defects (none unless the repair is off or gave up).
std::pair<Surface, Defects> repair_non_manifold(const CellComplex& cx, const EnergyModel& model,
                                                const ExtractionParams& params, ExtractionResult& result) {
  Surface surface;
  Defects defects;
  std::vector<char> locked(cx.cells.size(), 0);
  const auto neighbours = model.neighbours();
  bool grow_only = false;
  for (std::size_t round = 0;; ++round) {
    surface = surface_of(cx, result.inside);
    defects = find_defects(cx, surface);
    if (defects.list.empty() || !params.repair_non_manifold || round > cx.cells.size() + 100) break;
    bool flipped = false;
    std::vector<char> flipped_now(cx.cells.size(), 0);
    for (const auto& defect : defects.list) {
      // A neighbouring defect's flip this round may already have repaired this one: re-check next round.
      if (std::any_of(defect.all.begin(), defect.all.end(), [&](int c) { return flipped_now[c] != 0; })) continue;
      std::vector<int> best;
      double best_delta = std::numeric_limits<double>::infinity();
      for (const auto* list : {&defect.preferred, &defect.all}) {
        for (int c : *list) {
          if (grow_only && result.inside[c]) continue;
          const std::vector<int> set = model.flip_set(result.inside, c);
          if (!grow_only && std::any_of(set.begin(), set.end(), [&](int d) { return locked[d] != 0; })) continue;
          double delta = 0.0;
          if (set.size() == 1) {
            delta = model.flip_delta(result.inside, neighbours, c);
          } else {
            std::vector<bool> after = result.inside;
            for (int d : set) after[d] = !after[d];
            delta = model.evaluate(after) - model.evaluate(result.inside);
          }
          if (delta < best_delta) {
            best = set;
            best_delta = delta;
          }
        }
        if (!best.empty()) break;
      }
      if (best.empty()) continue;
      for (int d : best) {
        result.inside[d] = !result.inside[d];
        locked[d] = 1;
        flipped_now[d] = 1;
        ++result.repaired_cells;
      }
      flipped = true;
    }
    if (!flipped) {
      if (grow_only) break;
      grow_only = true;
    }
  }
  return {std::move(surface), std::move(defects)};
}

/// The label clean-up (label_cleanup.h) on the repaired labels; the surface and its defects are rebuilt
/// when it flips anything.
void clean_up(const CellComplex& cx, const EnergyModel& model, const std::vector<FacetVotes>& votes, double spacing,
              const ExtractionParams& params, ExtractionResult& result, Surface& surface, Defects& defects) {
  if (params.face_price > 0 && params.cleanup_max_cells > 0 && cx.cells.size() > params.cleanup_max_cells) {
    result.cleanup_skipped = true;
    log::warn("extraction: label clean-up skipped: " + std::to_string(cx.cells.size()) + " cells, more than " +
              std::to_string(params.cleanup_max_cells) + " (its cost grows faster than the cells; the default " +
              "hierarchical partition gives fewer)");
    return;
  }
  LabelCleanupParams cp;
  cp.face_price = params.face_price;
  cp.small_share = params.small_face_share;
  cp.small_weight = params.small_face_weight;
  cp.point_tolerance = params.point_tolerance_spacings * spacing;
  cp.support_points = params.support_points;
  cp.support_distance = params.support_distance_spacings * spacing;
  std::vector<std::size_t> facet_points(votes.size());
  for (std::size_t f = 0; f < votes.size(); ++f) facet_points[f] = votes[f].assigned;
  FlipSet flip_set;  // empty without building orders: every cell flips alone
  if (!model.orders.empty())
    flip_set = [&](const std::vector<bool>& inside, int c, std::vector<int>* read) { return model.flip_set(inside, c, read); };
  const LabelCleanupResult r = clean_up_labels(cx, result.inside, cp, flip_set, facet_points);
  result.cleanup_moves = r.moves;
  result.cleanup_cells = r.cells_flipped;
  result.cleanup_displacement = r.displacement;
  if (r.moves == 0) return;
  surface = surface_of(cx, result.inside);
  defects = find_defects(cx, surface);
  log::verbose("[extraction] clean-up: " + std::to_string(r.moves) + " flips of " + std::to_string(r.cells_flipped) +
               " cells, faces " + std::to_string(r.faces_before) + " -> " + std::to_string(r.faces_after) + " (small " +
               std::to_string(r.small_before) + " -> " + std::to_string(r.small_after) + ")" +
               ", displacement " + std::to_string(r.displacement) + " of the diagonal (" + std::to_string(r.rejected) +
               " flips refused: not manifold; " + std::to_string(r.supported) + " not made: supported points)");
}

namespace {
/// Per level: face price (fraction of the diagonal per removed face) and λ. Measured on the shared scans,
/// bench/results/faces.md.
struct DetailLevel {
  Detail level;
  const char* name;
  double face_price, lambda;
};
constexpr DetailLevel kDetailLevels[] = {
    {Detail::Full, "full", 0.0, 0.5},
    {Detail::High, "high", 1e-5, 0.5},
    {Detail::Medium, "medium", 3e-5, 0.5},
    {Detail::Low, "low", 1e-4, 0.5},
};
}  // namespace

Detail parse_detail(const std::string& name) {
  for (const DetailLevel& l : kDetailLevels)
    if (name == l.name) return l.level;
  throw Error(Status::BadInput, kStage, "unknown detail level '" + name + "' (full, high, medium, low)");
}

const char* detail_name(Detail d) {
  for (const DetailLevel& l : kDetailLevels)
    if (l.level == d) return l.name;
  return "?";
}

void apply_detail(Detail d, ExtractionParams& params) {
  for (const DetailLevel& l : kDetailLevels)
    if (l.level == d) {
      params.face_price = l.face_price;
      params.lambda = l.lambda;
    }
}

ExtractionResult run_extraction(const ExtractionInput& input, const ExtractionParams& params) {
  check_input(input);
  if (!(params.wall_area_weight >= 0) || !std::isfinite(params.wall_area_weight) || !(params.lambda >= 0) ||
      !(params.vouched_area_weight >= 0) || !std::isfinite(params.vouched_area_weight) ||
      !(params.slab_facet_weight >= 0) || !std::isfinite(params.slab_facet_weight) ||
      !(params.face_price >= 0) || !std::isfinite(params.face_price))
    throw Error(Status::BadInput, kStage,
                "parameters: lambda >= 0, wall_area_weight >= 0, vouched_area_weight >= 0, slab_facet_weight >= 0 and "
                "face_price >= 0 required");
  const CellComplex& cx = *input.complex;
  ExtractionResult result;
  double phase_start = log::now_seconds();
  auto phase_done = [&](const char* what) {  // --verbose: where the stage's time goes
    const double now = log::now_seconds();
    char buf[96];
    std::snprintf(buf, sizeof buf, "[extraction] %s %.3f s", what, now - phase_start);
    log::verbose(buf);
    phase_start = now;
  };

  const auto votes = assign_points(input, &result.voting_points);
  EnergyModel model = build_energy(input, params, votes);
  result.inside = minimise(model);
  std::size_t inside_count = static_cast<std::size_t>(std::count(result.inside.begin(), result.inside.end(), true));
  if (inside_count == 0 && params.building) {
    result.forced_cells = force_best_cell_inside(model, result.inside);
    inside_count = static_cast<std::size_t>(std::count(result.inside.begin(), result.inside.end(), true));
    if (result.forced_cells)
      log::warn("extraction: no roof part outweighed its faces; the best supported cell and what lies under it "
                "were kept (" + std::to_string(inside_count) + " cells)");
  }
  result.energy = model.evaluate(result.inside);
  phase_done("votes, energy and min-cut");
  log::verbose("[extraction] " + std::to_string(result.voting_points) + " of " + std::to_string(input.cloud->size()) +
               " points vote; " + std::to_string(inside_count) + " of " + std::to_string(cx.cells.size()) +
               " cells inside; energy " + std::to_string(result.energy));
  if (inside_count == 0)
    throw Error(Status::DegenerateInput, kStage,
                "no cell labelled inside (" + std::to_string(result.voting_points) + " voting points, " +
                    std::to_string(cx.cells.size()) + " cells): nothing to enclose");
  if (inside_count == cx.cells.size())
    log::warn("extraction: every cell is labelled inside; the output is the bounding box");

  auto [surface, defects] = repair_non_manifold(cx, model, params, result);
  phase_done("surface and non-manifold repair");
  if (params.face_price > 0.0) {
    clean_up(cx, model, votes, input.spacing, params, result, surface, defects);
    phase_done("label clean-up");
  }
  result.non_manifold_vertices = defects.vertices;
  if (result.repaired_cells > 0 || result.cleanup_moves > 0) {
    result.energy = model.evaluate(result.inside);
    log::verbose("[extraction] flipped " + std::to_string(result.repaired_cells) +
                 " cells to make the surface manifold; energy now " + std::to_string(result.energy));
  }
  inside_count = static_cast<std::size_t>(std::count(result.inside.begin(), result.inside.end(), true));
  if (inside_count == 0)
    throw Error(Status::DegenerateInput, kStage, "no cell left inside after the non-manifold repair");

  std::vector<Loop>& loops = surface.loops;
  const auto& group_of = surface.group;
  result.surface_facets = loops.size();

  std::vector<Loop> polygons;
  std::vector<FaceClass> classes;
  std::vector<int> plane_of;  // each polygon's support plane
  std::size_t holed = 0;
  if (params.merge_coplanar) {
    std::map<std::pair<int, int>, std::vector<Loop>> groups;
    for (std::size_t i = 0; i < loops.size(); ++i) groups[group_of[i]].push_back(std::move(loops[i]));
    for (auto& [key, members] : groups)
      for (Loop& l : merge_group(members, &holed)) {
        polygons.push_back(std::move(l));
        classes.push_back(face_class_of(cx, key.first, key.second));
        plane_of.push_back(key.first);
      }
  } else {
    polygons = std::move(loops);
    for (const auto& [plane, sign] : group_of) {
      classes.push_back(face_class_of(cx, plane, sign));
      plane_of.push_back(plane);
    }
  }
  phase_done("coplanar merge");
  std::vector<std::int64_t> mesh_index;
  result.mesh = assemble_mesh(cx, polygons, plane_of, mesh_index);
  result.mesh.face_class = std::move(classes);
  result.mesh.origin = input.cloud->origin;
  result.output_faces = result.mesh.faces.size();
  phase_done("mesh");
  std::vector<char> not_simple_once_rounded;
  const std::size_t at_risk = prove_simple_polygons(cx, result.mesh, mesh_index, &not_simple_once_rounded);  // throws if one is not
  phase_done("simple polygons proof");
  result.sub_precision_necks = zip_sub_precision_necks(cx, result.mesh, mesh_index, not_simple_once_rounded);  // #161
  if (at_risk > 0 && result.sub_precision_necks == 0)
    log::warn("extraction: " + std::to_string(at_risk) +
              " output polygon(s) come closer to themselves or to another than the coordinates' precision: "
              "they may touch or cross once rounded to doubles (eval's exact check says whether they do)");
  if (result.sub_precision_necks > 0) {
    log::info("[extraction] " + std::to_string(at_risk) + " output polygon(s) closer to themselves or another than "
              "the doubles' precision; " + std::to_string(result.sub_precision_necks) +
              " corner(s) closer to their own face's edge zipped into it (eval's exact check says whether any "
              "still touch or cross)");
    result.output_faces = result.mesh.faces.size();
  }
  result.sub_precision_edges = collapse_sub_precision_edges(result.mesh);  // the doubles' own surface (#158)
  if (result.sub_precision_edges > 0) {
    log::info("[extraction] " + std::to_string(result.sub_precision_edges) +
              " edge(s) shorter than the doubles' precision collapsed");
    result.output_faces = result.mesh.faces.size();
  }

  std::map<DirectedEdge, std::pair<int, int>> uses;  // undirected edge (min, max) -> (#min->max, #max->min)
  for (const auto& face : result.mesh.faces)
    for (std::size_t i = 0; i < face.size(); ++i) {
      const std::uint32_t a = face[i], b = face[(i + 1) % face.size()];
      auto& u = uses[{std::min(a, b), std::max(a, b)}];
      (a < b ? u.first : u.second) += 1;
    }
  for (const auto& [e, u] : uses)
    if (u.first != 1 || u.second != 1) ++result.non_manifold_edges;
  if (result.non_manifold_edges > 0 || result.non_manifold_vertices > 0)
    log::warn("extraction: the surface is not a 2-manifold: " + std::to_string(result.non_manifold_edges) +
              " edges not shared by exactly two faces, " + std::to_string(result.non_manifold_vertices) +
              " vertices where the surface pinches");

  log::info("[extraction] " + std::to_string(inside_count) + "/" + std::to_string(cx.cells.size()) + " cells inside, " +
            std::to_string(result.surface_facets) + " surface facets -> " + std::to_string(result.output_faces) +
            " faces, " + std::to_string(result.mesh.vertices.size()) + " vertices" +
            (holed ? " (" + std::to_string(holed) + " coplanar regions with holes split into disks)" : std::string()));
  return result;
}

void write_labels_dump(const CellComplex& complex, const std::vector<bool>& inside, const std::string& path_ply) {
  if (inside.size() != complex.cells.size())
    throw Error(Status::BadInput, kStage, "labels dump: " + std::to_string(inside.size()) + " labels for " +
                                              std::to_string(complex.cells.size()) + " cells");
  constexpr double kShrink = 0.85;
  std::ostringstream vertices, faces;
  vertices.precision(17);
  std::size_t num_vertices = 0, num_faces = 0, longest = 0;
  for (const Facet& f : complex.facets) longest = std::max(longest, f.vertices.size());
  for (std::size_t c = 0; c < complex.cells.size(); ++c) {
    const Vec3& centre = complex.cells[c].centroid;
    for (std::uint32_t fid : complex.cells[c].facets) {
      const Facet& f = complex.facets[fid];
      Loop loop = f.vertices;
      // The loop's normal points to cells[0]; seen from this cell, outward means reversing it when it is cells[0].
      if (f.cells[0] == static_cast<int>(c)) std::reverse(loop.begin(), loop.end());
      faces << loop.size();
      for (std::uint32_t v : loop) {
        const Vec3 p = centre + kShrink * (complex.vertices_approx[v] - centre);
        vertices << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
        faces << ' ' << num_vertices++;
      }
      faces << (inside[c] ? " 220 40 40 " : " 120 170 230 ") << c << ' ' << (inside[c] ? 1 : 0) << '\n';
      ++num_faces;
    }
  }
  AtomicFile file(path_ply, kStage);
  auto& out = file.stream();
  out << "ply\nformat ascii 1.0\ncomment hsr extraction labels: cells shrunk to 85%, red = inside\n"
      << "element vertex " << num_vertices << "\nproperty double x\nproperty double y\nproperty double z\n"
      << "element face " << num_faces << "\nproperty list " << (longest < 256 ? "uchar" : "int") << " int vertex_indices\n"
      << "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty int cell\nproperty uchar inside\n"
      << "end_header\n"
      << vertices.str() << faces.str();
  file.commit();
}

}  // namespace hsr
