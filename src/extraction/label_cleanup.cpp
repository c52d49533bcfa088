// The label clean-up after the min-cut (label_cleanup.h). Output faces are counted the way extraction's
// merge makes them: per support plane, the surface facets of one orientation that share edges form one
// region; a region is one face, plus one per hole (a region with a hole is split into disks).
#include "extraction/label_cleanup.h"

#include "extraction/surface.h"

#include "core/error.h"
#include "core/log.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <utility>

namespace hsr {
namespace {

using Edge = std::pair<std::uint32_t, std::uint32_t>;  // undirected: (min, max)

double loop_area(const CellComplex& cx, const std::vector<std::uint32_t>& loop) {
  Vec3 n = Vec3::Zero();
  for (std::size_t i = 0; i < loop.size(); ++i)
    n += cx.vertices_approx[loop[i]].cross(cx.vertices_approx[loop[(i + 1) % loop.size()]]);
  return 0.5 * n.norm();
}

/// The facets of one support plane, with their vertices and edges (T-junction vertices inserted) as
/// plane-local ids, and which facets of the plane share an edge.
struct PlaneFacets {
  std::vector<int> facets;
  std::vector<std::vector<int>> vertices;    ///< per local facet: local ids of its loop's vertices
  std::vector<std::vector<int>> edges;       ///< per local facet: local ids of its edges
  std::vector<std::vector<int>> neighbours;  ///< per local facet: local facets sharing an edge
  int vertex_count = 0, edge_count = 0;
};

std::vector<PlaneFacets> plane_facets(const CellComplex& cx) {
  std::vector<PlaneFacets> out(cx.planes.size());
  for (std::size_t f = 0; f < cx.facets.size(); ++f) out[cx.facets[f].plane].facets.push_back(static_cast<int>(f));
  for (PlaneFacets& p : out) {
    std::vector<std::vector<std::uint32_t>> loops;
    for (int f : p.facets) loops.push_back(cx.facets[f].vertices);
    insert_t_junctions(cx, loops);  // a complex built without flat vertices meets in T-junctions
    std::map<std::uint32_t, int> vertex_id;
    std::map<Edge, std::vector<int>> by_edge;
    p.edges.resize(loops.size());
    p.vertices.resize(loops.size());
    for (std::size_t k = 0; k < loops.size(); ++k) {
      const auto& l = loops[k];
      for (std::size_t i = 0; i < l.size(); ++i) {
        const auto [it, added] = vertex_id.emplace(l[i], p.vertex_count);
        p.vertex_count += added;
        p.vertices[k].push_back(it->second);
        by_edge[{std::min(l[i], l[(i + 1) % l.size()]), std::max(l[i], l[(i + 1) % l.size()])}].push_back(
            static_cast<int>(k));
      }
    }
    p.neighbours.resize(loops.size());
    for (const auto& [e, ks] : by_edge) {
      for (int k : ks) p.edges[k].push_back(p.edge_count);
      ++p.edge_count;
      for (int a : ks)
        for (int b : ks)
          if (a != b) p.neighbours[a].push_back(b);
    }
    for (auto& nb : p.neighbours) {
      std::sort(nb.begin(), nb.end());
      nb.erase(std::unique(nb.begin(), nb.end()), nb.end());
    }
  }
  return out;
}

/// +1: the facet is on the surface with its plane's normal pointing out (cells[0] outside), -1 reversed,
/// 0 not on the surface.
int facet_status(const Facet& f, const std::vector<bool>& inside) {
  const bool in0 = f.cells[0] >= 0 && inside[f.cells[0]], in1 = f.cells[1] >= 0 && inside[f.cells[1]];
  if (in0 == in1) return 0;
  return in1 ? 1 : -1;
}

/// One output region: surface facets of one plane and orientation connected through shared edges.
struct Region {
  int plane = -1;
  std::vector<int> facets;  ///< complex facet ids
  int faces = 1;            ///< 1 + holes
};

/// Stamp arrays for regions_of, sized for the largest plane, so that the clean-up's inner loop neither
/// allocates per plane nor sorts.
struct Stamps {
  std::vector<int> facet, vertex, edge;
  std::vector<int> members;  ///< for_each_region's current region
  int mark = 0;
  explicit Stamps(const std::vector<PlaneFacets>& planes) {
    std::size_t f = 0, v = 0, e = 0;
    for (const PlaneFacets& p : planes) {
      f = std::max(f, p.facets.size());
      v = std::max(v, static_cast<std::size_t>(p.vertex_count));
      e = std::max(e, static_cast<std::size_t>(p.edge_count));
    }
    facet.assign(f, 0);
    vertex.assign(v, 0);
    edge.assign(e, 0);
  }
  int next() { return ++mark; }
};

/// Distinct ids among a region's facets' id lists (marked with `mark` in `stamp`).
long distinct_ids(const std::vector<int>& members, const std::vector<std::vector<int>>& ids, std::vector<int>& stamp,
                  int mark) {
  long n = 0;
  for (int k : members)
    for (int id : ids[k])
      if (stamp[id] != mark) {
        stamp[id] = mark;
        ++n;
      }
  return n;
}

/// Visits the regions of one plane under `inside` (components of equal status through shared edges) that
/// contain one of the plane's local facets `seeds`, each once, in the order of their first seed:
/// visit(local member facets, faces = 1 + holes). `read`, if given, gets the local facets whose status the
/// answer depends on (seeds, members, the members' neighbours; with repeats).
template <class Visit>
void for_each_region(const CellComplex& cx, const PlaneFacets& p, const std::vector<bool>& inside,
                     const std::vector<int>& seeds, Stamps& stamps, std::vector<int>* read, Visit&& visit) {
  auto status = [&](int k) { return facet_status(cx.facets[p.facets[k]], inside); };
  const int seen = stamps.next();
  std::vector<int>& members = stamps.members;
  if (read) read->insert(read->end(), seeds.begin(), seeds.end());
  for (int s : seeds) {
    const int side = status(s);
    if (side == 0 || stamps.facet[s] == seen) continue;
    members.assign(1, s);
    stamps.facet[s] = seen;
    for (std::size_t i = 0; i < members.size(); ++i) {
      const std::vector<int>& nbs = p.neighbours[members[i]];
      if (read) read->insert(read->end(), nbs.begin(), nbs.end());
      for (int nb : nbs)
        if (stamps.facet[nb] != seen && status(nb) == side) {
          stamps.facet[nb] = seen;
          members.push_back(nb);
        }
    }
    // Holes from the Euler characteristic of the region: V - E + F = 1 - holes.
    const int mark = stamps.next();
    const long v = distinct_ids(members, p.vertices, stamps.vertex, mark);
    const long e = distinct_ids(members, p.edges, stamps.edge, mark);
    const long holes = std::max(0L, 1 - (v - e + static_cast<long>(members.size())));
    visit(members, 1 + static_cast<int>(holes));
  }
}

/// The regions of for_each_region as Region records.
std::vector<Region> regions_of(const CellComplex& cx, const PlaneFacets& p, int plane, const std::vector<bool>& inside,
                               const std::vector<int>& seeds, Stamps& stamps) {
  std::vector<Region> out;
  for_each_region(cx, p, inside, seeds, stamps, nullptr, [&](const std::vector<int>& members, int faces) {
    Region r;
    r.plane = plane;
    r.faces = faces;
    for (int k : members) r.facets.push_back(p.facets[k]);
    out.push_back(std::move(r));
  });
  return out;
}

/// Output faces of some regions, and how many of them are small (a region under the small area: all its faces).
struct FaceCount {
  int faces = 0, small = 0;
};

struct Evaluation {
  int delta_faces = 0, delta_small = 0;
  double point_displacement = 0.0;  ///< mean displacement of the points (Cleanup::cost())
  std::vector<int> planes;  ///< support planes whose facets the move changes (sorted)
  std::vector<int> read;    ///< complex facets whose status the deltas depend on: valid while none changes
};

class Cleanup {
 public:
  Cleanup(const CellComplex& cx, std::vector<bool>& inside, const FlipSet& flip_set,
          const LabelCleanupParams& params, const std::vector<std::size_t>& facet_points)
      : cx_(cx), inside_(inside), flip_set_(flip_set), planes_(plane_facets(cx)), stamps_(planes_),
        facet_points_(facet_points), point_tolerance_(params.point_tolerance) {
    const double small_share = params.small_share;
    std::size_t points = 0;
    for (std::size_t n : facet_points_) points += n;
    point_scale_ = 1.0 / std::max(static_cast<double>(points) * cx_.box.diagonal(), 1e-300);
    for (const Facet& f : cx_.facets) {
      BBox b;
      Vec3 c = Vec3::Zero();
      for (std::uint32_t v : f.vertices) {
        b.extend(cx_.vertices_approx[v]);
        c += cx_.vertices_approx[v];
      }
      facet_box_.push_back(b);
      facet_centre_.push_back(c / static_cast<double>(f.vertices.size()));
    }
    local_.resize(cx_.facets.size());
    read_stamp_.assign(cx_.facets.size(), 0);
    all_.resize(planes_.size());
    for (std::size_t p = 0; p < planes_.size(); ++p)
      for (std::size_t k = 0; k < planes_[p].facets.size(); ++k) {
        local_[planes_[p].facets[k]] = static_cast<int>(k);
        all_[p].push_back(static_cast<int>(k));
      }
    inside_count_ = static_cast<std::size_t>(std::count(inside_.begin(), inside_.end(), true));
    double area = 0.0;
    facet_area_.reserve(cx_.facets.size());
    for (const Facet& f : cx_.facets) {
      facet_area_.push_back(loop_area(cx_, f.vertices));
      if (facet_status(f, inside_) != 0) area += facet_area_.back();
    }
    // Displacement of a flip: flipped volume / (surface area * diagonal); both areas fixed at the surface
    // the clean-up starts from.
    scale_ = 1.0 / std::max(area * cx_.box.diagonal(), 1e-300);
    small_area_ = small_share * area;
    area_ = area;
    faces_.resize(planes_.size());
    region_of_.resize(planes_.size());
    region_faces_.resize(planes_.size());
    region_mark_.resize(planes_.size());
    indexed_at_.resize(planes_.size());
    for (std::size_t p = 0; p < planes_.size(); ++p) index_regions(static_cast<int>(p));
    raw_.resize(planes_.size());
    stale_.assign(planes_.size(), 1);
  }

  FaceCount total_faces() const {
    FaceCount t;
    for (const FaceCount& f : faces_) {
      t.faces += f.faces;
      t.small += f.small;
    }
    return t;
  }

  /// Candidate flips around every output region: all its inside cells out, all its outside cells in, and
  /// each of its cells alone; around a small region also each of its cells with one neighbour of the same
  /// label (each with the cells its flip drags along). Sorted, without duplicates. A plane's candidates
  /// before closing are kept until a flip touches a cell they depend on (commit()); closing them under
  /// the flip set depends on labels anywhere, so it is redone here unless there is no flip set.
  std::vector<std::vector<int>> candidates() {
    std::set<std::vector<int>> out;
    for (std::size_t p = 0; p < planes_.size(); ++p) {
      if (stale_[p]) {
        raw_[p].clear();
        for (const Region& r : regions(static_cast<int>(p))) add_raw_candidates(r, raw_[p]);
        if (!flip_set_)
          for (auto& cells : raw_[p]) cells = closed(cells);
        stale_[p] = 0;
      }
      for (const auto& cells : raw_[p]) out.insert(flip_set_ ? closed(cells) : cells);
    }
    return {out.begin(), out.end()};
  }

  /// The candidate flips around one region (see candidates()).
  void add_candidates(const Region& r, std::set<std::vector<int>>& out) const {
    std::vector<std::vector<int>> raw;
    add_raw_candidates(r, raw);
    for (const auto& cells : raw) out.insert(closed(cells));
  }

  /// The candidate flips around one region before closing them under the flip set.
  void add_raw_candidates(const Region& r, std::vector<std::vector<int>>& out) const {
    std::vector<int> in_cells, out_cells;
    for (int f : r.facets)
      for (int c : cx_.facets[f].cells)
        if (c >= 0) (inside_[c] ? in_cells : out_cells).push_back(c);
    for (auto* side : {&in_cells, &out_cells}) {
      std::sort(side->begin(), side->end());
      side->erase(std::unique(side->begin(), side->end()), side->end());
      if (side->empty()) continue;
      for (int c : *side) out.push_back({c});
      if (side->size() > 1) out.push_back(*side);
      if (area_of(r) < small_area_)
        for (int c : *side) add_pairs(c, out);
    }
  }

  /// Cell c with each neighbour of the same label (across one of c's facets), as one flip: a sliver that
  /// no single cell removes without opening a new face is often removed by two (issue 14).
  void add_pairs(int c, std::vector<std::vector<int>>& out) const {
    for (std::uint32_t f : cx_.cells[c].facets)
      for (int d : cx_.facets[f].cells)
        if (d >= 0 && d != c && inside_[d] == inside_[c]) out.push_back({c, d});
  }

  double area_of(const Region& r) const {
    double area = 0.0;
    for (int f : r.facets) area += facet_area_[f];
    return area;
  }

  /// The regions still under the small area, with their area share of the surface.
  std::vector<std::pair<Region, double>> small_regions() {
    std::vector<std::pair<Region, double>> out;
    for (std::size_t p = 0; p < planes_.size(); ++p)
      for (Region& r : regions(static_cast<int>(p))) {
        const double area = area_of(r);
        if (area < small_area_) out.emplace_back(std::move(r), area / area_);
      }
    return out;
  }

  /// The change of the face counts if `cells` flipped. Only the regions on the flipped cells' facets or
  /// next to them can change, so only those are counted, before and after.
  Evaluation evaluate(const std::vector<int>& cells) {
    Evaluation ev;
    std::vector<std::pair<int, int>> touched;  // (plane, local facet): the flipped facets and their neighbours
    for (int c : cells)
      for (std::uint32_t f : cx_.cells[c].facets) {
        const int p = cx_.facets[f].plane;
        ev.planes.push_back(p);
        touched.push_back({p, local_[f]});
        for (int nb : planes_[p].neighbours[local_[f]]) touched.push_back({p, nb});
      }
    std::sort(ev.planes.begin(), ev.planes.end());
    ev.planes.erase(std::unique(ev.planes.begin(), ev.planes.end()), ev.planes.end());
    std::sort(touched.begin(), touched.end());
    touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
    std::vector<std::vector<int>> seeds(ev.planes.size());
    for (std::size_t i = 0, j = 0; i < touched.size(); ++i) {
      while (ev.planes[j] != touched[i].first) ++j;
      seeds[j].push_back(touched[i].second);
    }
    std::vector<int> read;
    const int mark = ++read_mark_;
    auto keep_read = [&](int p) {  // plane-local ids to complex facet ids, each once
      for (int k : read) {
        const int f = planes_[p].facets[k];
        if (read_stamp_[f] != mark) {
          read_stamp_[f] = mark;
          ev.read.push_back(f);
        }
      }
      read.clear();
    };
    for (std::size_t j = 0; j < ev.planes.size(); ++j) {
      const FaceCount before = count(ev.planes[j], seeds[j], &read);
      keep_read(ev.planes[j]);
      ev.delta_faces -= before.faces;
      ev.delta_small -= before.small;
    }
    std::vector<std::pair<std::uint32_t, int>> status_before;  // the flipped cells' facets
    for (int c : cells)
      for (std::uint32_t f : cx_.cells[c].facets) status_before.push_back({f, facet_status(cx_.facets[f], inside_)});
    flip(cells);
    ev.point_displacement = point_displacement(cells, status_before);
    for (std::size_t j = 0; j < ev.planes.size(); ++j) {
      const FaceCount after = count(ev.planes[j], seeds[j], &read);
      keep_read(ev.planes[j]);
      ev.delta_faces += after.faces;
      ev.delta_small += after.small;
    }
    flip(cells);
    return ev;
  }

  /// When plane p's regions were last indexed, and the clock all planes share (index_regions() ticks it).
  std::uint64_t indexed_at(int p) const { return indexed_at_[p]; }
  std::uint64_t clock() const { return clock_; }

  /// An upper bound of the weighted faces a flip of `cells` removes (gain in clean_up_labels): at best every
  /// region it touches (evaluate()'s seeds) disappears. Cheap: the regions are indexed.
  double max_gain(const std::vector<int>& cells, double small_weight) {
    double gain = 0.0;
    const int mark = stamps_.next();
    auto add = [&](int p, int k) {
      const int r = region_of_[p][k];
      if (r < 0) return;
      int& seen = region_mark_[p][r];
      if (seen == mark) return;
      seen = mark;
      gain += region_faces_[p][r].faces + small_weight * region_faces_[p][r].small;
    };
    for (int c : cells)
      for (std::uint32_t f : cx_.cells[c].facets) {
        const int p = cx_.facets[f].plane;
        add(p, local_[f]);
        for (int nb : planes_[p].neighbours[local_[f]]) add(p, nb);
      }
    return gain;
  }

  /// What a flip costs before dividing by the faces it removes: the larger of the surface's mean displacement
  /// (displacement()) and the points' (Evaluation::point_displacement), fractions of the box diagonal.
  double cost(const std::vector<int>& cells, const Evaluation& ev) const {
    return std::max(displacement(cells), ev.point_displacement);
  }

  /// With `cells` flipped (`before`: their facets' statuses before): the points on facets that left the
  /// surface move to the facets that entered it. Each facet's points are taken at its centre; their distance
  /// to an entering facet is at least the distance to its plane and to its bounding box (the larger is
  /// used: a lower bound, so the price errs towards the surface's displacement). Less point_tolerance,
  /// times the points, over all points and the diagonal.
  double point_displacement(const std::vector<int>& cells,
                            const std::vector<std::pair<std::uint32_t, int>>& before) const {
    if (facet_points_.empty()) return 0.0;
    std::vector<std::uint32_t> left, entered;
    for (const auto& [f, status] : before) {
      const int now = facet_status(cx_.facets[f], inside_);
      if (status != 0 && now == 0 && facet_points_[f] > 0) left.push_back(f);
      if (status == 0 && now != 0) entered.push_back(f);
    }
    double sum = 0.0;
    for (std::uint32_t f : left) {
      const Vec3& c = facet_centre_[f];
      double d = entered.empty() ? cx_.box.diagonal() : std::numeric_limits<double>::infinity();
      for (std::uint32_t g : entered) {
        const Plane& plane = cx_.planes[cx_.facets[g].plane].approx;
        const BBox& b = facet_box_[g];
        const Vec3 out = (b.min - c).cwiseMax(c - b.max).cwiseMax(Vec3::Zero());
        d = std::min(d, std::max(std::abs(plane.normal.dot(c) + plane.offset), out.norm()));
      }
      sum += static_cast<double>(facet_points_[f]) * std::max(0.0, d - point_tolerance_);
    }
    return sum * point_scale_;
  }

  double displacement(const std::vector<int>& cells) const {
    double v = 0.0;
    for (int c : cells) v += std::abs(cx_.cells[c].volume_approx);
    return v * scale_;
  }

  /// Flips the cells; false (and nothing changed) if no cell would be left inside.
  bool can_flip(const std::vector<int>& cells) const {
    std::size_t out = 0, in = 0;
    for (int c : cells) (inside_[c] ? out : in) += 1;
    return inside_count_ + in - out > 0;
  }
  void flip(const std::vector<int>& cells) {
    for (int c : cells) {
      inside_count_ += inside_[c] ? -1 : 1;
      inside_[c] = !inside_[c];
    }
  }
  /// Records an accepted flip of `cells`. A plane's candidates depend on the labels of the cells on its
  /// facets and of their neighbours (add_pairs), so they go stale on the planes of the flipped cells' and
  /// their neighbours' facets.
  void commit(const std::vector<int>& cells, const Evaluation& ev) {
    for (int p : ev.planes) index_regions(p);
    for (int c : cells)
      for (std::uint32_t f : cx_.cells[c].facets)
        for (int d : cx_.facets[f].cells)
          if (d >= 0)
            for (std::uint32_t g : cx_.cells[d].facets) stale_[cx_.facets[g].plane] = 1;
  }

 private:
  /// Recomputes plane p's regions under inside_: faces_[p], region_of_[p], region_faces_[p].
  void index_regions(int p) {
    indexed_at_[p] = ++clock_;
    const PlaneFacets& pf = planes_[p];
    FaceCount total;
    region_of_[p].assign(pf.facets.size(), -1);
    region_faces_[p].clear();
    for_each_region(cx_, pf, inside_, all_[p], stamps_, nullptr, [&](const std::vector<int>& members, int faces) {
      for (int k : members) region_of_[p][k] = static_cast<int>(region_faces_[p].size());
      const FaceCount here = face_count(pf, members, faces);
      region_faces_[p].push_back(here);
      total.faces += here.faces;
      total.small += here.small;
    });
    faces_[p] = total;
    region_mark_[p].assign(region_faces_[p].size(), 0);
  }

  std::vector<Region> regions(int p) { return regions_of(cx_, planes_[p], p, inside_, all_[p], stamps_); }

  /// Faces and small faces of plane p's regions that contain one of the local facets `seeds`.
  FaceCount count(int p, const std::vector<int>& seeds, std::vector<int>* read = nullptr) {
    FaceCount total;
    const PlaneFacets& pf = planes_[p];
    for_each_region(cx_, pf, inside_, seeds, stamps_, read, [&](const std::vector<int>& members, int faces) {
      const FaceCount here = face_count(pf, members, faces);
      total.faces += here.faces;
      total.small += here.small;
    });
    return total;
  }

  /// One region's faces, all of them small when its area is under the small area.
  FaceCount face_count(const PlaneFacets& pf, const std::vector<int>& members, int faces) const {
    double area = 0.0;
    for (int k : members) area += facet_area_[pf.facets[k]];
    return {faces, area < small_area_ ? faces : 0};
  }

  /// The union of the flip sets of `cells` (all on one side), sorted.
  std::vector<int> closed(const std::vector<int>& cells) const {
    std::vector<int> out;
    if (!flip_set_) out = cells;
    else
      for (int c : cells) {
        const std::vector<int> s = flip_set_(inside_, c);
        out.insert(out.end(), s.begin(), s.end());
      }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  }

  const CellComplex& cx_;
  std::vector<bool>& inside_;
  const FlipSet& flip_set_;
  std::vector<PlaneFacets> planes_;
  Stamps stamps_;
  const std::vector<std::size_t>& facet_points_;  ///< per facet: the points assigned to it (empty: none known)
  double point_tolerance_ = 0.0;                  ///< LabelCleanupParams::point_tolerance
  double point_scale_ = 0.0;                      ///< 1 / (points * box diagonal)
  std::vector<BBox> facet_box_;                   ///< per facet
  std::vector<Vec3> facet_centre_;                ///< per facet: the mean of its vertices
  std::vector<int> local_;              ///< per complex facet: its index in its plane's facets
  std::vector<int> read_stamp_;         ///< per complex facet: evaluate()'s mark when it was read
  int read_mark_ = 0;
  std::vector<std::vector<int>> all_;   ///< per plane: 0 .. its facet count - 1
  std::vector<FaceCount> faces_;  ///< per support plane: its output faces under inside_
  std::vector<std::vector<int>> region_of_;           ///< per plane and local facet: its region (-1: none)
  std::vector<std::vector<FaceCount>> region_faces_;  ///< per plane and region: its faces and small faces
  std::vector<std::vector<int>> region_mark_;         ///< per plane and region: max_gain()'s stamp
  std::vector<std::uint64_t> indexed_at_;             ///< per plane: clock_ when index_regions() ran
  std::uint64_t clock_ = 0;
  std::vector<std::vector<std::vector<int>>> raw_;  ///< per support plane: its candidates (closed if no flip set)
  std::vector<char> stale_;                         ///< per support plane: raw_ must be rebuilt
  std::vector<double> facet_area_;  ///< per complex facet
  std::size_t inside_count_ = 0;
  double scale_ = 0.0, small_area_ = 0.0, area_ = 0.0;
};

/// The weighted faces a flip removes (a small face counts small_weight faces), or 0 when it removes none or
/// adds one: never more faces.
double gain_of(const Evaluation& ev, const LabelCleanupParams& params) {
  const double gain = -ev.delta_faces - params.small_weight * ev.delta_small;
  return ev.delta_faces > 0 || !(gain > 0) ? 0.0 : gain;
}

/// Why each small region the clean-up stopped at is still there (shown with --verbose): of the candidate
/// flips around it, the cheapest that removes faces without adding any, and whether it was over the price or
/// would leave the surface non-manifold; or, if none, the fewest faces a candidate adds.
void explain_small_regions(Cleanup& cleanup, const LabelCleanupParams& params, DefectCounter& defects,
                           std::size_t defects_before, const std::vector<bool>& inside) {
  for (const auto& [region, share] : cleanup.small_regions()) {
    std::set<std::vector<int>> cands;
    cleanup.add_candidates(region, cands);
    double best_price = std::numeric_limits<double>::infinity(), best_manifold = best_price;
    int fewest_added = std::numeric_limits<int>::max();
    std::size_t best_size = 0;
    std::size_t flippable = 0;
    for (const auto& cand : cands) {
      if (!cleanup.can_flip(cand)) continue;
      ++flippable;
      const Evaluation ev = cleanup.evaluate(cand);
      const double gain = gain_of(ev, params);
      if (gain == 0.0) {
        fewest_added = std::min(fewest_added, ev.delta_faces);
        continue;
      }
      const double price = cleanup.cost(cand, ev) / gain;
      cleanup.flip(cand);
      const bool manifold = defects.count_with(inside, cand) <= defects_before;
      cleanup.flip(cand);
      if (price < best_price) {
        best_price = price;
        best_size = cand.size();
      }
      if (manifold) best_manifold = std::min(best_manifold, price);
    }
    std::string why;
    if (std::isfinite(best_manifold))
      why = "cheapest manifold flip costs " + std::to_string(best_manifold / params.face_price) + " x face_price";
    else if (std::isfinite(best_price))
      why = "only non-manifold flips remove faces (cheapest " + std::to_string(best_price / params.face_price) +
            " x face_price, " + std::to_string(best_size) + " cells)";
    else if (flippable == 0)
      why = "every candidate flip would leave no cell inside: it is a face of the model's last inside cells";
    else
      why = "no candidate flip removes a face without adding one (fewest added: " + std::to_string(fewest_added) +
            "; 0: it only moves the small face)";
    log::verbose("[extraction] clean-up: small face left on plane " + std::to_string(region.plane) + ", share " +
                 std::to_string(share) + ", " + std::to_string(region.faces) + " face(s), " +
                 std::to_string(region.facets.size()) + " facets, " +
                 std::to_string(cands.size()) + " candidate flips: " + why);
  }
}

/// Evaluations of candidate flips (and their gain bounds), kept while they hold: an evaluation holds until a
/// flip changes the label of a cell on a facet it read; a bound until one of its planes is indexed again.
class EvaluationCache {
 public:
  explicit EvaluationCache(const CellComplex& cx) : cx_(cx), readers_(cx.facets.size()) {}

  /// Cleanup::max_gain of the cells, kept until one of their facets' planes is indexed again.
  double max_gain(Cleanup& cleanup, const std::vector<int>& cells, double small_weight) {
    Entry& e = entry(cells);
    if (e.planes.empty()) {
      for (int c : cells)
        for (std::uint32_t f : cx_.cells[c].facets) e.planes.push_back(cx_.facets[f].plane);
      std::sort(e.planes.begin(), e.planes.end());
      e.planes.erase(std::unique(e.planes.begin(), e.planes.end()), e.planes.end());
    }
    const bool holds = e.gain_at > 0 && std::all_of(e.planes.begin(), e.planes.end(),
                                                    [&](int p) { return cleanup.indexed_at(p) < e.gain_at; });
    if (!holds) {
      e.gain = cleanup.max_gain(cells, small_weight);
      e.gain_at = cleanup.clock() + 1;  // held while none of its planes is indexed after now
    }
    return e.gain;
  }

  const Evaluation& get(Cleanup& cleanup, const std::vector<int>& cells) {
    Entry& e = entry(cells);
    if (!e.holds) {
      e.eval = cleanup.evaluate(cells);
      e.holds = true;
      ++e.generation;
      for (int f : e.eval.read) readers_[f].push_back({&e, e.generation});
    }
    return e.eval;
  }
  /// Every facet of a flipped cell may change status: the evaluations that read one no longer hold.
  void flipped(const std::vector<int>& cells) {
    for (int c : cells)
      for (std::uint32_t f : cx_.cells[c].facets) {
        for (const auto& [e, generation] : readers_[f])
          if (e->generation == generation) e->holds = false;
        readers_[f].clear();
      }
  }

 private:
  struct Entry {
    Evaluation eval;
    bool holds = false;            ///< eval is that of the current labels
    std::uint32_t generation = 0;  ///< evaluations made so far (readers_ entries of older ones are void)
    std::vector<int> planes;    ///< the planes of the cells' facets (sorted)
    double gain = 0.0;
    std::uint64_t gain_at = 0;  ///< 0: never computed; else held while every plane's indexed_at < gain_at
  };
  Entry& entry(const std::vector<int>& cells) {
    auto it = entries_.find(cells);
    if (it == entries_.end()) it = entries_.emplace(cells, Entry{}).first;
    return it->second;
  }
  const CellComplex& cx_;
  std::map<std::vector<int>, Entry> entries_;  ///< nodes stay put: readers_ points at them
  std::vector<std::vector<std::pair<Entry*, std::uint32_t>>> readers_;  ///< per facet: (entry, generation) that read it
};

/// A candidate flip that removes faces and adds none, at `price` (displacement per face removed).
struct Offer {
  double price = 0.0;
  std::size_t index = 0;  ///< in the candidates
  const Evaluation* eval = nullptr;
};

/// The cheapest offer among the candidates not refused (ties: fewer cells, then the candidates' order), if
/// any. Candidates are evaluated in the order of their lowest possible price (`by_bound`: (bound, index),
/// sorted) until that bound exceeds the best price found, so the answer is the one a full scan gives.
std::optional<Offer> cheapest_offer(Cleanup& cleanup, const std::vector<std::vector<int>>& candidates,
                                    const std::vector<std::pair<double, std::size_t>>& by_bound,
                                    const std::vector<char>& refused, EvaluationCache& cache,
                                    const LabelCleanupParams& params) {
  std::optional<Offer> best;
  auto better = [&](const Offer& a, const Offer& b) {
    if (a.price != b.price) return a.price < b.price;
    const std::size_t na = candidates[a.index].size(), nb = candidates[b.index].size();
    return na != nb ? na < nb : a.index < b.index;
  };
  for (const auto& [bound, i] : by_bound) {
    if (best && bound > best->price) break;
    if (refused[i]) continue;
    const std::vector<int>& cells = candidates[i];
    const Evaluation& ev = cache.get(cleanup, cells);
    const double gain = gain_of(ev, params);
    if (gain == 0.0) continue;
    const Offer offer{cleanup.cost(cells, ev) / gain, i, &ev};
    if (!best || better(offer, *best)) best = offer;
  }
  return best;
}

/// The candidates that can flip, with the lowest price each could have (displacement / max_gain), sorted.
std::vector<std::pair<double, std::size_t>> price_bounds(Cleanup& cleanup,
                                                         const std::vector<std::vector<int>>& candidates,
                                                         EvaluationCache& cache, const LabelCleanupParams& params) {
  std::vector<std::pair<double, std::size_t>> out;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    if (!cleanup.can_flip(candidates[i])) continue;
    const double gain = cache.max_gain(cleanup, candidates[i], params.small_weight);
    if (gain > 0) out.push_back({cleanup.displacement(candidates[i]) / gain, i});
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

LabelCleanupResult clean_up_labels(const CellComplex& cx, std::vector<bool>& inside, const LabelCleanupParams& params,
                                   const FlipSet& flip_set, const std::vector<std::size_t>& facet_points) {
  LabelCleanupResult result;
  if (!(params.face_price > 0.0) || cx.cells.empty()) return result;
  Cleanup cleanup(cx, inside, flip_set, params, facet_points);
  result.faces_before = result.faces_after = static_cast<std::size_t>(cleanup.total_faces().faces);
  result.small_before = result.small_after = static_cast<std::size_t>(cleanup.total_faces().small);
  DefectCounter defects(cx, inside);
  const std::size_t defects_before = defects.count();
  EvaluationCache cache(cx);
  bool accepted = true;
  while (accepted && result.moves < params.max_moves) {
    // The cheapest offer that keeps the surface a 2-manifold; the refused ones are tried again after the
    // next accepted flip (it may have changed their neighbourhood).
    accepted = false;
    const auto candidates = cleanup.candidates();
    const auto by_bound = price_bounds(cleanup, candidates, cache, params);
    std::vector<char> refused(candidates.size(), 0);
    for (;;) {
      const std::optional<Offer> offer = cheapest_offer(cleanup, candidates, by_bound, refused, cache, params);
      if (!offer || offer->price > params.face_price) break;
      const std::vector<int>& cells = candidates[offer->index];
      cleanup.flip(cells);
      if (defects.count_with(inside, cells) > defects_before) {
        cleanup.flip(cells);
        refused[offer->index] = 1;
        ++result.rejected;
        continue;
      }
      defects.commit(inside, cells);
      cleanup.commit(cells, *offer->eval);
      ++result.moves;
      result.cells_flipped += cells.size();
      result.displacement += cleanup.displacement(cells);
      cache.flipped(cells);
      accepted = true;
      break;
    }
  }
  if (log::level() >= log::Level::Verbose) explain_small_regions(cleanup, params, defects, defects_before, inside);
  result.faces_after = static_cast<std::size_t>(cleanup.total_faces().faces);
  result.small_after = static_cast<std::size_t>(cleanup.total_faces().small);
  return result;
}

}  // namespace hsr
