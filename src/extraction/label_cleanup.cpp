// The label clean-up after the min-cut (label_cleanup.h). Output faces are counted the way extraction's
// merge makes them: per support plane, the surface facets of one orientation that share edges form one
// region; a region is one face, plus one per hole (a region with a hole is split into disks).
#include "extraction/label_cleanup.h"

#include "extraction/surface.h"

#include "core/error.h"
#include "core/log.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <limits>
#include <map>
#include <numeric>
#include <set>
#include <tuple>
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
  std::vector<std::vector<int>> vertex_facets;  ///< per local vertex: the local facets with it in their loop
  std::vector<std::vector<int>> edge_facets;    ///< per local edge: the local facets with it in their loop
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
    p.edge_facets.reserve(by_edge.size());
    for (const auto& [e, ks] : by_edge) {
      for (int k : ks) p.edges[k].push_back(p.edge_count);
      p.edge_facets.push_back(ks);
      ++p.edge_count;
      for (int a : ks)
        for (int b : ks)
          if (a != b) p.neighbours[a].push_back(b);
    }
    for (auto& nb : p.neighbours) {
      std::sort(nb.begin(), nb.end());
      nb.erase(std::unique(nb.begin(), nb.end()), nb.end());
    }
    for (auto& ef : p.edge_facets) ef.erase(std::unique(ef.begin(), ef.end()), ef.end());
    p.vertex_facets.resize(static_cast<std::size_t>(p.vertex_count));
    for (std::size_t k = 0; k < p.vertices.size(); ++k)
      for (int v : p.vertices[k])
        if (p.vertex_facets[v].empty() || p.vertex_facets[v].back() != static_cast<int>(k)) p.vertex_facets[v].push_back(static_cast<int>(k));
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
/// answer depends on (seeds, members, the members' neighbours; with repeats). visit also gets the region's
/// closure's vertex and edge counts.
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
    visit(members, 1 + static_cast<int>(holes), v, e);
  }
}

/// The regions of for_each_region as Region records.
std::vector<Region> regions_of(const CellComplex& cx, const PlaneFacets& p, int plane, const std::vector<bool>& inside,
                               const std::vector<int>& seeds, Stamps& stamps) {
  std::vector<Region> out;
  for_each_region(cx, p, inside, seeds, stamps, nullptr, [&](const std::vector<int>& members, int faces, long, long) {
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
  std::size_t supported_points = 0;  ///< points it moves farther than the support distance
  std::vector<int> planes;  ///< support planes whose facets the move changes (sorted)
};

/// A component of one plane's surface facets of one orientation, as index_regions() records it.
struct RegionRecord {
  FaceCount count;
  double area = 0.0;
  long vertices = 0, edges = 0;  ///< of its closure (V and E of its Euler characteristic)
  std::vector<int> members;      ///< local facets
};

class Cleanup {
 public:
  Cleanup(const CellComplex& cx, std::vector<bool>& inside, const FlipSet& flip_set,
          const LabelCleanupParams& params, const std::vector<std::size_t>& facet_points)
      : cx_(cx), inside_(inside), flip_set_(flip_set), planes_(plane_facets(cx)), stamps_(planes_),
        facet_points_(facet_points), point_tolerance_(params.point_tolerance),
        support_distance_(params.support_distance) {
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
    all_.resize(planes_.size());
    std::size_t largest = 0;
    for (std::size_t p = 0; p < planes_.size(); ++p) {
      largest = std::max(largest, planes_[p].facets.size());
      for (std::size_t k = 0; k < planes_[p].facets.size(); ++k) {
        local_[planes_[p].facets[k]] = static_cast<int>(k);
        all_[p].push_back(static_cast<int>(k));
      }
    }
    scratch_.resize(largest, stamps_);
    read_mark_.assign(cx_.facets.size(), 0);
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
    regions_.resize(planes_.size());
    region_mark_.resize(planes_.size());
    indexed_at_.resize(planes_.size());
    for (std::size_t p = 0; p < planes_.size(); ++p) index_regions(static_cast<int>(p));
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
  std::size_t plane_count() const { return planes_.size(); }
  bool has_flip_set() const { return static_cast<bool>(flip_set_); }

  /// The candidate flips around plane p's output regions (each closed under the flip set): around each
  /// region, all its inside cells out, all its outside cells in, and each of its cells alone; around a small
  /// region also each of its cells with one neighbour of the same label. A plane's candidates go stale when
  /// a flip touches a cell they depend on (commit()); with a flip set the closure depends on labels
  /// anywhere, so the caller lists every plane again after every flip.
  ///
  /// Region r of plane p as the index has it (index_regions(): the same regions, in the same order, as
  /// regions(p)): its local member facets, in the order the index found them (a function of the member set:
  /// the search starts at the lowest and follows fixed neighbour lists), and its orientation. Two regions
  /// with the same members and orientation have the same candidates, unless the region is small (its pairs
  /// read the labels of the cells around it) or there is a flip set.
  int region_count(int p) const { return static_cast<int>(regions_[p].size()); }
  const std::vector<int>& region_members(int p, int r) const { return regions_[p][r].members; }
  int region_side(int p, int r) const {
    return facet_status(cx_.facets[planes_[p].facets[regions_[p][r].members.front()]], inside_);
  }
  bool region_candidates_depend_on_labels(int p, int r) const {
    return flip_set_ || regions_[p][r].area < small_area_;
  }
  /// Region r's candidates (closed under the flip set), sorted, without repeats.
  std::vector<std::vector<int>> region_candidates(int p, int r) const {
    Region region;
    region.plane = p;
    for (int k : regions_[p][r].members) region.facets.push_back(planes_[p].facets[k]);
    std::vector<std::vector<int>> out;
    add_raw_candidates(region, out);
    for (auto& cells : out) cells = closed(cells);
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  }
  bool stale(int p) const { return stale_[p] != 0; }
  void listed(int p) { stale_[p] = 0; }

  /// The candidate flips around one region (see plane_candidates()).
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

  /// Starts a reading: the facets evaluate() and max_gain() look at until take_reads() are collected.
  void begin_reads() {
    ++read_stamp_;
    reads_.clear();
  }
  std::vector<std::uint32_t> take_reads() { return std::move(reads_); }

  /// The planes of the cells' facets (sorted).
  std::vector<int> planes_of(const std::vector<int>& cells) const {
    std::vector<int> out;
    for (int c : cells)
      for (std::uint32_t f : cx_.cells[c].facets) out.push_back(cx_.facets[f].plane);
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  }

  /// What flipping `cells` would change: the face counts (side_delta(), from the facets that change and the
  /// regions index: its cost follows the flip, not the regions it touches), the points' displacement.
  Evaluation evaluate(const std::vector<int>& cells) {
    Evaluation ev;
    std::vector<std::tuple<int, int, int>> changed;  // (plane, local facet, status before)
    for (int c : cells)
      for (std::uint32_t f : cx_.cells[c].facets) changed.emplace_back(cx_.facets[f].plane, local_[f], 0);
    std::sort(changed.begin(), changed.end());
    changed.erase(std::unique(changed.begin(), changed.end()), changed.end());
    for (auto& [p, k, before] : changed) {
      before = facet_status(cx_.facets[planes_[p].facets[k]], inside_);
      note(p, k);
    }
    std::vector<std::pair<std::uint32_t, int>> status_before;  // the flipped cells' facets
    for (const auto& [p, k, before] : changed) status_before.push_back({static_cast<std::uint32_t>(planes_[p].facets[k]), before});
    flip(cells);
    ev.point_displacement = point_displacement(cells, status_before, &ev.supported_points);
    std::vector<int> after(changed.size());
    for (std::size_t i = 0; i < changed.size(); ++i)
      after[i] = facet_status(cx_.facets[planes_[std::get<0>(changed[i])].facets[std::get<1>(changed[i])]], inside_);
    flip(cells);
    for (std::size_t i = 0; i < changed.size();) {
      const int p = std::get<0>(changed[i]);
      ev.planes.push_back(p);
      std::vector<Change> here;
      for (; i < changed.size() && std::get<0>(changed[i]) == p; ++i)
        if (std::get<2>(changed[i]) != after[i]) here.push_back({std::get<1>(changed[i]), std::get<2>(changed[i]), after[i]});
      if (here.empty()) continue;
      for (int side : {1, -1}) {
        const FaceCount d = side_delta(p, side, here);
        ev.delta_faces += d.faces;
        ev.delta_small += d.small;
      }
    }
    return ev;
  }

  /// The same face counts by counting every region of the touched planes before and after (what the
  /// clean-up did before issue 25; kept as the reference for tests).
  FaceCount delta_by_counting(const std::vector<int>& cells) {
    const std::vector<int> planes = planes_of(cells);
    FaceCount d;
    for (int p : planes) {
      const FaceCount before = count(p, all_[p]);
      d.faces -= before.faces;
      d.small -= before.small;
    }
    flip(cells);
    for (int p : planes) {
      const FaceCount after = count(p, all_[p]);
      d.faces += after.faces;
      d.small += after.small;
    }
    flip(cells);
    return d;
  }

  /// When plane p's regions were last indexed, and the clock all planes share (index_regions() ticks it).
  std::uint64_t indexed_at(int p) const { return indexed_at_[p]; }
  std::uint64_t clock() const { return clock_; }

  /// An upper bound of the weighted faces a flip of `cells` removes (gain in clean_up_labels), from the
  /// regions it touches (those on its cells' facets or next to them; the regions index makes it cheap): a
  /// small region, or one whose facets the flip may all change, at best disappears (all its faces); a larger
  /// one survives and can lose at most one face per hole the flip fills or joins and per region it joins
  /// with: each such change touches a facet the flip changes at one of its corners, so at most the flip's
  /// facets on that plane plus their corners.
  double max_gain(const std::vector<int>& cells, double small_weight) {
    std::vector<std::array<long, 3>> on_plane;  // (plane, the flip's facets on it, their corners)
    for (int c : cells)
      for (std::uint32_t f : cx_.cells[c].facets) on_plane.push_back({cx_.facets[f].plane, 1, static_cast<long>(cx_.facets[f].vertices.size())});
    std::sort(on_plane.begin(), on_plane.end());
    std::vector<std::array<long, 3>> per_plane;
    for (const auto& e : on_plane) {
      if (per_plane.empty() || per_plane.back()[0] != e[0]) per_plane.push_back({e[0], 0, 0});
      per_plane.back()[1] += 1;
      per_plane.back()[2] += e[2];
    }
    double gain = 0.0;
    const int mark = stamps_.next();
    auto add = [&](int p, int k) {
      note(p, k);
      const int r = region_of_[p][k];
      if (r < 0) return;
      int& seen = region_mark_[p][r];
      if (seen == mark) return;
      seen = mark;
      const RegionRecord& rec = regions_[p][r];
      note_region(p, rec);
      const auto it = std::lower_bound(per_plane.begin(), per_plane.end(), std::array<long, 3>{p, 0, 0});
      const long facets = it->at(1), corners = it->at(2);
      if (rec.count.small > 0 || static_cast<long>(rec.members.size()) <= facets) {
        gain += rec.count.faces + small_weight * rec.count.small;
        for (int m : rec.members) note(p, m);
      }
      else
        gain += static_cast<double>(std::min<long>(rec.count.faces, facets + corners));
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
  /// times the points, over all points and the diagonal. `supported` gets the points moving farther than
  /// the support distance (by the same lower bound).
  double point_displacement(const std::vector<int>& cells,
                            const std::vector<std::pair<std::uint32_t, int>>& before, std::size_t* supported) const {
    (void)cells;
    *supported = 0;
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
      if (d > support_distance_) *supported += facet_points_[f];
    }
    return sum * point_scale_;
  }

  double displacement(const std::vector<int>& cells) const {
    double v = 0.0;
    for (int c : cells) v += std::abs(cx_.cells[c].volume_approx);
    return v * scale_;
  }

  /// False when the flip would leave no cell inside.
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
  /// Records an accepted flip of `cells` (already made): the planes of their facets are indexed again. A
  /// plane's candidates depend on the labels of the cells on its facets and of their neighbours
  /// (add_pairs), so they go stale on the planes of the flipped cells' and their neighbours' facets.
  /// Returns the facets whose status the flip changed (`before`: their statuses before it).
  std::vector<std::uint32_t> commit(const std::vector<int>& cells, const Evaluation& ev,
                                    const std::vector<std::pair<std::uint32_t, int>>& before) {
    std::vector<std::uint32_t> changed;
    for (const auto& [f, status] : before)
      if (facet_status(cx_.facets[f], inside_) != status) changed.push_back(f);
    for (int p : ev.planes) index_regions(p);
    for (int c : cells)
      for (std::uint32_t f : cx_.cells[c].facets)
        for (int d : cx_.facets[f].cells)
          if (d >= 0)
            for (std::uint32_t g : cx_.cells[d].facets) stale_[cx_.facets[g].plane] = 1;
    return changed;
  }
  /// The statuses of the cells' facets now (for commit()).
  std::vector<std::pair<std::uint32_t, int>> statuses(const std::vector<int>& cells) const {
    std::vector<std::pair<std::uint32_t, int>> out;
    for (int c : cells)
      for (std::uint32_t f : cx_.cells[c].facets) out.push_back({f, facet_status(cx_.facets[f], inside_)});
    return out;
  }

 private:
  /// Records that the current reading looked at local facet k of plane p.
  void note(int p, int k) {
    const auto f = static_cast<std::uint32_t>(planes_[p].facets[k]);
    if (read_mark_[f] == read_stamp_) return;
    read_mark_[f] = read_stamp_;
    reads_.push_back(f);
  }
  /// A region whose record a reading used: when it is not big (its area under twice the small area), every
  /// change of it matters (its members and their neighbours are noted); a big region's record enters a face
  /// count only through differences (2 - V + E - F of a part of it less its own), so changes of it away
  /// from the facets looked at do not.
  bool is_big(const RegionRecord& rec) const { return rec.count.small == 0 && rec.area >= 2.0 * small_area_; }
  void note_region(int p, const RegionRecord& rec) {
    if (is_big(rec)) return;
    for (int k : rec.members) {
      note(p, k);
      for (int nb : planes_[p].neighbours[k]) note(p, nb);
    }
  }

  /// A facet of one plane whose status a flip changes.
  struct Change {
    int k, before, after;
  };

  /// Per-evaluation marks over one plane's local facets, vertices and edges (sized for the largest plane):
  /// the changes, the facets explored, the vertices and edges counted.
  struct Scratch {
    std::vector<int> change_mark, change_before, change_after, owner_mark, owner, region_mark, region_slot;
    std::vector<int> vertex_mark, edge_mark;
    int mark = 0;
    void resize(std::size_t facets, const Stamps& s) {
      for (auto* v : {&change_mark, &change_before, &change_after, &owner_mark, &owner, &region_mark, &region_slot})
        v->assign(facets, 0);
      vertex_mark.assign(s.vertex.size(), 0);
      edge_mark.assign(s.edge.size(), 0);
    }
  };

  /// The change of the output faces (and small faces) of plane p's regions of orientation `side` when the
  /// facets `changes` change status. Exactly what counting every region before and after gives
  /// (delta_by_counting), from the region index and the neighbourhood of the change:
  ///   * the regions that change, K: those holding a facet that leaves (R) or next to one that joins (A);
  ///   * what they become: each region of K that lost facets is explored from the facets next to the lost
  ///     ones, all fronts at once, until at most one front is still open (the others are the pieces it
  ///     split into; the open one is the rest of the region, known from the index: its area, facets,
  ///     vertices and edges less the explored parts'); the joining facets glue pieces, whole regions of K
  ///     and each other into the new regions;
  ///   * each new region's faces: 2 - (V - E + F) of its closure, counted from its largest part's index
  ///     plus the other parts' vertices and edges not on it (one face plus one per hole, as for_each_region
  ///     counts); small when its area is under the small area.
  FaceCount side_delta(int p, int side, const std::vector<Change>& changes) {
    const PlaneFacets& pf = planes_[p];
    const std::vector<int>& region_of = region_of_[p];
    const std::vector<RegionRecord>& records = regions_[p];
    Scratch& s = scratch_;
    const int mark = ++s.mark;
    std::vector<int> removed, added;  // R and A, ascending (changes are)
    for (const Change& c : changes) {
      s.change_mark[c.k] = mark;
      s.change_before[c.k] = c.before;
      s.change_after[c.k] = c.after;
      if (c.before == side && c.after != side) removed.push_back(c.k);
      if (c.after == side && c.before != side) added.push_back(c.k);
    }
    if (removed.empty() && added.empty()) return {};
    auto status_now = [&](int k) {
      note(p, k);
      return facet_status(cx_.facets[pf.facets[k]], inside_);
    };
    auto changed = [&](int k) { return s.change_mark[k] == mark; };
    auto before_in = [&](int k) { return (changed(k) ? s.change_before[k] : status_now(k)) == side; };
    auto after_in = [&](int k) { return (changed(k) ? s.change_after[k] : status_now(k)) == side; };
    auto leaves = [&](int k) { return changed(k) && s.change_before[k] == side && s.change_after[k] != side; };
    // K: the regions that change, with their kind (1: intact, next to a joining facet; 2: losing facets).
    std::vector<int> affected, kind;
    auto touch = [&](int r, int k) {
      if (s.region_mark[r] != mark) {
        s.region_mark[r] = mark;
        s.region_slot[r] = static_cast<int>(affected.size());
        affected.push_back(r);
        kind.push_back(0);
      }
      kind[static_cast<std::size_t>(s.region_slot[r])] = std::max(kind[static_cast<std::size_t>(s.region_slot[r])], k);
    };
    for (int k : removed) touch(region_of[k], 2);
    for (int k : added)
      for (int nb : pf.neighbours[k])
        if (before_in(nb) && !leaves(nb)) touch(region_of[nb], 1);
    FaceCount delta;
    for (int r : affected) {
      delta.faces -= records[r].count.faces;
      delta.small -= records[r].count.small;
      note_region(p, records[r]);
    }
    // The parts of the new regions: the joining facets (parts 0 .. |A| - 1, in `added` order), the intact
    // regions of K, and what each losing region falls into (its closed fronts, and its open rest).
    struct Part {
      int region = -1;           ///< region of K it comes from (-1: a joining facet)
      bool whole = false;        ///< the whole (intact) region
      bool rest = false;         ///< a losing region's rest: its facets no closed front took
      std::vector<int> facets;   ///< explicit facets (a joining facet; a front's explored facets)
      double area = 0.0;
    };
    std::vector<Part> parts;
    for (int k : added) parts.push_back({-1, false, false, {k}, facet_area_[pf.facets[k]]});
    std::vector<int> slot_part(affected.size(), -1);  // intact: its part; losing: its rest part (or -1)
    for (std::size_t i = 0; i < affected.size(); ++i)
      if (kind[i] == 1) {
        slot_part[i] = static_cast<int>(parts.size());
        parts.push_back({affected[i], true, false, {}, records[affected[i]].area});
      }
    std::vector<int> front_part;  // front id (owner) -> part
    for (std::size_t i = 0; i < affected.size(); ++i) {
      if (kind[i] != 2) continue;
      const int r = affected[i];
      // The rim: the region's facets that stay, next to a leaving one; one front each.
      const int first = static_cast<int>(front_part.size());
      std::vector<int> rim;
      for (int k : removed)
        if (region_of[k] == r)
          for (int nb : pf.neighbours[k])
            if (before_in(nb) && !leaves(nb) && s.owner_mark[nb] != mark) {
              s.owner_mark[nb] = mark;
              s.owner[nb] = first + static_cast<int>(rim.size());
              rim.push_back(nb);
            }
      if (rim.empty()) continue;  // the whole region leaves
      const int fronts = static_cast<int>(rim.size());
      std::vector<int> fparent(static_cast<std::size_t>(fronts));
      std::iota(fparent.begin(), fparent.end(), 0);
      auto ffind = [&](int x) {
        while (fparent[x] != x) x = fparent[x] = fparent[fparent[x]];
        return x;
      };
      std::vector<std::vector<int>> queue(static_cast<std::size_t>(fronts)), explored(queue.size());
      std::vector<std::size_t> head(queue.size(), 0);
      for (int f = 0; f < fronts; ++f) queue[f] = explored[f] = {rim[f]};
      // All fronts at once, one facet per open class and round, until at most one class is open: the
      // closed ones are the pieces the region falls into, the open one is its rest.
      for (;;) {
        int open = 0;
        for (int f = 0; f < fronts; ++f) open += ffind(f) == f && head[f] < queue[f].size();
        if (open <= 1) break;
        for (int f = 0; f < fronts; ++f) {
          if (ffind(f) != f || head[f] >= queue[f].size()) continue;
          const int k = queue[f][head[f]++];
          for (int nb : pf.neighbours[k]) {
            if (!before_in(nb) || leaves(nb)) continue;
            const int root = ffind(f);
            if (s.owner_mark[nb] != mark) {
              s.owner_mark[nb] = mark;
              s.owner[nb] = first + root;
              queue[root].push_back(nb);
              explored[root].push_back(nb);
              continue;
            }
            const int other = ffind(s.owner[nb] - first);
            if (other == root) continue;
            const int lo = std::min(root, other), hi = std::max(root, other);  // the fronts meet: one class
            fparent[hi] = lo;
            queue[lo].insert(queue[lo].end(), queue[hi].begin() + static_cast<std::ptrdiff_t>(head[hi]), queue[hi].end());
            explored[lo].insert(explored[lo].end(), explored[hi].begin(), explored[hi].end());
            std::vector<int>().swap(queue[hi]);
            std::vector<int>().swap(explored[hi]);
            head[hi] = 0;
          }
        }
      }
      std::vector<int> class_part(static_cast<std::size_t>(fronts), -1);
      double lost = 0.0;  // the leaving facets' and closed pieces' area
      for (int k : removed)
        if (region_of[k] == r) lost += facet_area_[pf.facets[k]];
      for (int f = 0; f < fronts; ++f) {
        if (ffind(f) != f) continue;
        Part q{r, false, head[f] < queue[f].size(), std::move(explored[f]), 0.0};
        for (int k : q.facets) q.area += facet_area_[pf.facets[k]];
        class_part[f] = static_cast<int>(parts.size());
        if (q.rest) slot_part[i] = class_part[f];
        else lost += q.area;
        parts.push_back(std::move(q));
      }
      if (slot_part[i] >= 0) parts[slot_part[i]].area = records[r].area - lost;
      for (int f = 0; f < fronts; ++f) front_part.push_back(class_part[ffind(f)]);
    }
    // The part of a facet after the flip (-1: not in a new region of K).
    auto part_of = [&](int k) -> int {
      if (!after_in(k)) return -1;
      if (changed(k)) return static_cast<int>(std::lower_bound(added.begin(), added.end(), k) - added.begin());
      const int r = region_of[k];
      if (r < 0 || s.region_mark[r] != mark) return -1;  // a region the flip does not change
      const int i = s.region_slot[r];
      if (kind[i] == 1 || s.owner_mark[k] != mark) return slot_part[i];
      return front_part[static_cast<std::size_t>(s.owner[k])];
    };
    std::vector<int> parent(parts.size());
    std::iota(parent.begin(), parent.end(), 0);
    auto find = [&](int x) {
      while (parent[x] != x) x = parent[x] = parent[parent[x]];
      return x;
    };
    for (std::size_t i = 0; i < added.size(); ++i)
      for (int nb : pf.neighbours[added[i]]) {
        const int q = part_of(nb);
        if (q >= 0) parent[find(static_cast<int>(i))] = find(q);
      }
    auto facet_count = [&](const Part& q) -> long {
      if (!q.whole && !q.rest) return static_cast<long>(q.facets.size());
      long n = static_cast<long>(records[q.region].members.size());
      if (q.whole) return n;
      for (int k : removed) n -= region_of[k] == q.region;
      for (const Part& o : parts)
        if (o.region == q.region && !o.rest && !o.whole) n -= static_cast<long>(o.facets.size());
      return n;
    };
    // Each new region: its faces from the Euler characteristic of its closure, V - E + F, counted from its
    // largest part's (from the index when that part is a whole region or a rest) plus the other parts'
    // vertices and edges that its largest part does not have.
    std::vector<std::vector<int>> pieces(parts.size());
    for (std::size_t q = 0; q < parts.size(); ++q) pieces[find(static_cast<int>(q))].push_back(static_cast<int>(q));
    for (const std::vector<int>& piece : pieces) {
      if (piece.empty()) continue;
      int base = piece[0];
      long f = 0, base_facets = -1;
      double area = 0.0;
      for (int q : piece) {
        const long n = facet_count(parts[q]);
        f += n;
        area += parts[q].area;
        if (n > base_facets) base = q, base_facets = n;
      }
      const Part& b = parts[base];
      if ((b.whole || b.rest) && area < 3.0 * small_area_)  // near the small area: the region's area decides
        for (int k : records[b.region].members) note(p, k);
      auto on_base = [&](const std::vector<int>& facets) {
        for (int g : facets)
          if (part_of(g) == base) return true;
        return false;
      };
      long v = 0, e = 0;
      const int bmark = ++s.mark;
      if (b.whole || b.rest) {
        v = records[b.region].vertices;
        e = records[b.region].edges;
        if (b.rest) {  // less the vertices and edges of the region that no facet of the rest has
          auto drop_lost = [&](int k) {
            for (int vid : pf.vertices[k])
              if (s.vertex_mark[vid] != bmark) {
                s.vertex_mark[vid] = bmark;
                v -= !on_base(pf.vertex_facets[vid]);
              }
            for (int eid : pf.edges[k])
              if (s.edge_mark[eid] != bmark) {
                s.edge_mark[eid] = bmark;
                e -= !on_base(pf.edge_facets[eid]);
              }
          };
          for (int k : removed)
            if (region_of[k] == b.region) drop_lost(k);
          for (const Part& o : parts)
            if (o.region == b.region && !o.rest && !o.whole)
              for (int k : o.facets) drop_lost(k);
        }
      } else {
        for (int k : b.facets) {
          for (int vid : pf.vertices[k])
            if (s.vertex_mark[vid] != bmark) s.vertex_mark[vid] = bmark, ++v;
          for (int eid : pf.edges[k])
            if (s.edge_mark[eid] != bmark) s.edge_mark[eid] = bmark, ++e;
        }
      }
      const int omark = ++s.mark;
      for (int q : piece) {
        if (q == base) continue;
        const Part& o = parts[q];
        std::vector<int> facets = o.facets;
        if (o.whole || o.rest) {
          facets.clear();
          for (int k : records[o.region].members)
            if (part_of(k) == q) facets.push_back(k);
        }
        for (int k : facets) {
          for (int vid : pf.vertices[k])
            if (s.vertex_mark[vid] != omark) {
              s.vertex_mark[vid] = omark;
              v += !on_base(pf.vertex_facets[vid]);
            }
          for (int eid : pf.edges[k])
            if (s.edge_mark[eid] != omark) {
              s.edge_mark[eid] = omark;
              e += !on_base(pf.edge_facets[eid]);
            }
        }
      }
      const int faces = 1 + static_cast<int>(std::max(0L, 1 - (v - e + f)));
      delta.faces += faces;
      if (area < small_area_) delta.small += faces;
    }
    return delta;
  }

  /// Recomputes plane p's regions under inside_: faces_[p], region_of_[p], regions_[p].
  void index_regions(int p) {
    indexed_at_[p] = ++clock_;
    const PlaneFacets& pf = planes_[p];
    FaceCount total;
    region_of_[p].assign(pf.facets.size(), -1);
    regions_[p].clear();
    for_each_region(cx_, pf, inside_, all_[p], stamps_, nullptr,
                    [&](const std::vector<int>& members, int faces, long v, long e) {
                      for (int k : members) region_of_[p][k] = static_cast<int>(regions_[p].size());
                      RegionRecord rec;
                      rec.count = face_count(pf, members, faces);
                      for (int k : members) rec.area += facet_area_[pf.facets[k]];
                      rec.vertices = v;
                      rec.edges = e;
                      rec.members = members;
                      total.faces += rec.count.faces;
                      total.small += rec.count.small;
                      regions_[p].push_back(std::move(rec));
                    });
    faces_[p] = total;
    region_mark_[p].assign(regions_[p].size(), 0);
  }

  std::vector<Region> regions(int p) { return regions_of(cx_, planes_[p], p, inside_, all_[p], stamps_); }

  /// Faces and small faces of plane p's regions that contain one of the local facets `seeds`.
  FaceCount count(int p, const std::vector<int>& seeds) {
    FaceCount total;
    const PlaneFacets& pf = planes_[p];
    for_each_region(cx_, pf, inside_, seeds, stamps_, nullptr, [&](const std::vector<int>& members, int faces, long, long) {
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
  Scratch scratch_;
  std::vector<int> read_mark_;            ///< per complex facet: the reading's mark (note())
  int read_stamp_ = 0;
  std::vector<std::uint32_t> reads_;      ///< the complex facets the current reading looked at
  const std::vector<std::size_t>& facet_points_;  ///< per facet: the points assigned to it (empty: none known)
  double point_tolerance_ = 0.0;                  ///< LabelCleanupParams::point_tolerance
  double support_distance_ = 0.0;                 ///< LabelCleanupParams::support_distance
  double point_scale_ = 0.0;                      ///< 1 / (points * box diagonal)
  std::vector<BBox> facet_box_;                   ///< per facet
  std::vector<Vec3> facet_centre_;                ///< per facet: the mean of its vertices
  std::vector<int> local_;              ///< per complex facet: its index in its plane's facets
  std::vector<std::vector<int>> all_;   ///< per plane: 0 .. its facet count - 1
  std::vector<FaceCount> faces_;  ///< per support plane: its output faces under inside_
  std::vector<std::vector<int>> region_of_;           ///< per plane and local facet: its region (-1: none)
  std::vector<std::vector<RegionRecord>> regions_;    ///< per plane and region
  std::vector<std::vector<int>> region_mark_;         ///< per plane and region: max_gain()'s stamp
  std::vector<std::uint64_t> indexed_at_;             ///< per plane: clock_ when index_regions() ran
  std::uint64_t clock_ = 0;
  std::vector<char> stale_;  ///< per support plane: its candidates must be listed again (CandidatePool)
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

/// The flip would move a part the points support (LabelCleanupParams::support_points): never made.
bool moves_supported_points(const Evaluation& ev, const LabelCleanupParams& params) {
  return params.support_points > 0 && ev.supported_points >= params.support_points;
}

/// The candidate flips and their prices, kept up to date flip by flip. A candidate's key is a lower bound of
/// its price (its displacement over the most faces it could remove, Cleanup::max_gain) until it is
/// evaluated, then its price (ties: fewer cells, then the cells' order). A key holds until a flip changes
/// the status of a facet its computation looked at (Cleanup::note: the candidate's facets, their
/// neighbours, what the face count explored, and the whole of any region it used that is not big); it is
/// then recomputed at once (a new bound may be lower). So the first key, once it is a price, is the
/// cheapest candidate, and each flip costs the candidates around it.
class CandidatePool {
 public:
  struct Entry {
    std::vector<int> cells;
    int refs = 0;                 ///< planes listing it
    double key = 0.0;
    bool valid = false;           ///< key (and eval, when exact) hold for the current labels
    bool exact = false;           ///< key is the price
    bool queued = false;          ///< in the queue
    bool held = false;            ///< out of the queue until the next accepted flip (refused, cannot flip)
    bool dead = false;            ///< evaluated: removes no face, or moves supported points
    std::uint32_t generation = 0; ///< readers_ entries of older keys are void
    Evaluation eval;
  };

  CandidatePool(Cleanup& cleanup, const LabelCleanupParams& params, std::size_t facets)
      : cleanup_(cleanup), params_(params), lists_(cleanup.plane_count()), readers_(facets) {}

  /// Brings candidates and keys up to the current labels after a flip that changed the status of the facets
  /// `changed`: stale planes' lists are rebuilt (every plane's with a flip set), the keys that looked at a
  /// changed facet recomputed, new and held candidates queued.
  void sync(const std::vector<std::uint32_t>& changed) {
    for (int p = 0; p < static_cast<int>(lists_.size()); ++p)
      if (cleanup_.stale(p) || cleanup_.has_flip_set() || !listed_) relist(p);
    listed_ = true;
    for (std::uint32_t f : changed) {
      for (const auto& [e, generation] : readers_[f])
        if (e->generation == generation) e->valid = false, touched_.push_back(e);
      records_ -= readers_[f].size();
      readers_[f].clear();
    }
    if (cleanup_.has_flip_set())  // the closures depend on labels anywhere: everything again
      for (auto& [cells, e] : entries_) e->valid = false, touched_.push_back(e.get());
    for (Entry* e : held_) touched_.push_back(e);
    held_.clear();
    for (Entry* e : touched_) {
      if (e->refs == 0) continue;  // released by a relist
      e->held = false;
      if (!e->valid) rekey(*e);
      else if (!e->dead) queue(*e);
    }
    touched_.clear();
    purge_readers();
  }

  /// The cheapest candidate that can flip and removes faces, not supported (nullptr: none), evaluating lazily.
  Entry* cheapest(std::set<std::vector<int>>& supported) {
    while (!queue_.empty()) {
      Entry* e = *queue_.begin();
      if (!cleanup_.can_flip(e->cells)) {
        hold(*e);
        continue;
      }
      if (e->exact) return e;
      unqueue(*e);
      cleanup_.begin_reads();
      e->eval = cleanup_.evaluate(e->cells);
      watch(*e, cleanup_.take_reads());
      const double gain = gain_of(e->eval, params_);
      e->exact = true;
      e->dead = gain == 0.0 || moves_supported_points(e->eval, params_);
      if (e->dead) {  // out of the queue until a facet it looked at changes
        if (gain != 0.0) supported.insert(e->cells);
        continue;
      }
      e->key = cleanup_.cost(e->cells, e->eval) / gain;
      queue(*e);
    }
    return nullptr;
  }

  /// Out of the queue until the next accepted flip (refused as not manifold, or it cannot flip now).
  void hold(Entry& e) {
    unqueue(e);
    if (!e.held) held_.push_back(&e);
    e.held = true;
  }

 private:
  struct Cheaper {
    bool operator()(const Entry* a, const Entry* b) const {
      if (a->key != b->key) return a->key < b->key;
      if (a->cells.size() != b->cells.size()) return a->cells.size() < b->cells.size();
      return a->cells < b->cells;
    }
  };

  /// A fresh lower bound as the key (queued when the candidate could remove a face).
  void rekey(Entry& e) {
    unqueue(e);
    ++e.generation;
    e.exact = e.dead = false;
    e.valid = true;
    cleanup_.begin_reads();
    const double gain = cleanup_.max_gain(e.cells, params_.small_weight);
    watch(e, cleanup_.take_reads());
    if (!(gain > 0)) {
      e.dead = true;
      return;
    }
    e.key = cleanup_.displacement(e.cells) / gain;
    queue(e);
  }
  /// The key of `e` holds until one of these facets changes status.
  void watch(Entry& e, const std::vector<std::uint32_t>& reads) {
    records_ += reads.size();
    for (std::uint32_t f : reads) readers_[f].push_back({&e, e.generation});
  }
  void queue(Entry& e) {
    if (e.queued) return;
    queue_.insert(&e);
    e.queued = true;
  }
  void unqueue(Entry& e) {
    if (!e.queued) return;
    queue_.erase(&e);
    e.queued = false;
  }
  /// One region's listing: its identity (Cleanup::region_members) and its candidates.
  struct Listed {
    std::uint64_t hash = 0;
    int side = 0;
    std::vector<int> members;
    std::vector<std::vector<int>> candidates;
  };
  static std::uint64_t identity_hash(int side, const std::vector<int>& members) {
    std::uint64_t h = 1469598103934665603ull ^ static_cast<std::uint64_t>(side + 2);
    for (int k : members) h = (h ^ static_cast<std::uint64_t>(k)) * 1099511628211ull;
    return h;
  }

  /// Plane p's candidates again, region by region (issue 25: a hall's floor holds thousands of facets, and
  /// most flips touch a cell on it): a region whose identity the flip left alone keeps its listing, the
  /// others are listed anew. Entries are counted by the regions listing them, gone at zero; every new
  /// listing is counted before any old one is released, so an entry listed before and after stays.
  void relist(int p) {
    std::vector<Listed> old = std::move(lists_[p]);
    std::vector<std::pair<std::uint64_t, int>> by_hash;
    for (std::size_t i = 0; i < old.size(); ++i) by_hash.push_back({old[i].hash, static_cast<int>(i)});
    std::sort(by_hash.begin(), by_hash.end());
    std::vector<char> kept(old.size(), 0);
    std::vector<Listed> next;
    for (int r = 0; r < cleanup_.region_count(p); ++r) {
      const std::vector<int>& members = cleanup_.region_members(p, r);
      const int side = cleanup_.region_side(p, r);
      const std::uint64_t hash = identity_hash(side, members);
      int same = -1;
      if (!cleanup_.region_candidates_depend_on_labels(p, r))
        for (auto it = std::lower_bound(by_hash.begin(), by_hash.end(), std::make_pair(hash, -1));
             it != by_hash.end() && it->first == hash; ++it)
          if (!kept[it->second] && old[it->second].side == side && old[it->second].members == members) {
            same = it->second;
            break;
          }
      if (same >= 0) {
        kept[same] = 1;
        next.push_back(std::move(old[same]));
        continue;
      }
      next.push_back({hash, side, members, cleanup_.region_candidates(p, r)});
      for (const auto& cells : next.back().candidates) acquire(cells);
    }
    for (std::size_t i = 0; i < old.size(); ++i)
      if (!kept[i])
        for (const auto& cells : old[i].candidates) release(cells);
    lists_[p] = std::move(next);
    cleanup_.listed(p);
  }
  void acquire(const std::vector<int>& cells) {
    auto [it, added] = entries_.try_emplace(cells);
    if (added) {
      it->second = std::make_unique<Entry>();
      it->second->cells = cells;
      touched_.push_back(it->second.get());
    }
    ++it->second->refs;
  }
  /// One listing fewer; at none the entry leaves the pool (sync() skips it in touched_ and held_, and the
  /// readers_ records of it are void: purge_readers() drops them).
  void release(const std::vector<int>& cells) {
    auto it = entries_.find(cells);
    Entry& e = *it->second;
    if (--e.refs > 0) return;
    unqueue(e);
    ++e.generation;
    std::vector<int>().swap(e.cells);
    e.eval = Evaluation{};
    retired_.push_back(std::move(it->second));
    entries_.erase(it);
  }
  /// Drops the void readers_ records (of older keys, of entries no region lists) once they are most of them:
  /// without it they pile up on the facets no flip changes (issue 25: 49 M records, 0.8 GB, on a hall of
  /// 8,744 cells). Amortised over the records watched.
  void purge_readers() {
    if (records_ < 2 * live_records_ + (std::size_t{1} << 16)) return;
    records_ = 0;
    for (auto& list : readers_) {
      list.erase(std::remove_if(list.begin(), list.end(), [](const auto& r) { return r.first->generation != r.second; }),
                 list.end());
      records_ += list.size();
    }
    live_records_ = records_;
    retired_.clear();  // nothing points at them any more
  }

  Cleanup& cleanup_;
  const LabelCleanupParams& params_;
  std::map<std::vector<int>, std::unique_ptr<Entry>> entries_;  ///< the queue and readers_ point at them
  std::vector<std::vector<Listed>> lists_;  ///< per plane: its regions' listings
  std::vector<std::vector<std::pair<Entry*, std::uint32_t>>> readers_;  ///< per facet: (entry, generation)
  std::set<Entry*, Cheaper> queue_;
  std::vector<Entry*> touched_, held_;
  std::vector<std::unique_ptr<Entry>> retired_;  ///< entries no region lists any more (readers_ may hold them)
  std::size_t records_ = 0, live_records_ = 0;   ///< readers_ records, and how many were live at the last purge
  bool listed_ = false;
};

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
    std::size_t flippable = 0, supported = 0;
    for (const auto& cand : cands) {
      if (!cleanup.can_flip(cand)) continue;
      ++flippable;
      const Evaluation ev = cleanup.evaluate(cand);
      const double gain = gain_of(ev, params);
      if (gain == 0.0) {
        fewest_added = std::min(fewest_added, ev.delta_faces);
        continue;
      }
      if (moves_supported_points(ev, params)) {
        ++supported;
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
    else if (supported > 0)
      why = "the points support it: every flip that removes it moves " + std::to_string(params.support_points) +
            " points or more farther than the support distance";
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
  CandidatePool pool(cleanup, params, cx.facets.size());
  std::set<std::vector<int>> supported;  // candidates found to move supported points
  std::vector<std::uint32_t> changed;    // the facets the last accepted flip changed
  while (result.moves < params.max_moves) {
    // The cheapest offer that keeps the surface a 2-manifold; the refused ones are tried again after the
    // next accepted flip (it may have changed their neighbourhood).
    pool.sync(changed);
    bool accepted = false;
    while (CandidatePool::Entry* offer = pool.cheapest(supported)) {
      if (offer->key > params.face_price) break;
      const std::vector<int> cells = offer->cells;
      const auto before = cleanup.statuses(cells);
      cleanup.flip(cells);
      if (defects.count_with(inside, cells) > defects_before) {
        cleanup.flip(cells);
        pool.hold(*offer);
        ++result.rejected;
        continue;
      }
      defects.commit(inside, cells);
      const Evaluation ev = offer->eval;
      changed = cleanup.commit(cells, ev, before);
      ++result.moves;
      result.cells_flipped += cells.size();
      result.displacement += cleanup.displacement(cells);
      accepted = true;
      break;
    }
    if (!accepted) break;
  }
  if (log::level() >= log::Level::Verbose) explain_small_regions(cleanup, params, defects, defects_before, inside);
  result.supported = supported.size();
  result.faces_after = static_cast<std::size_t>(cleanup.total_faces().faces);
  result.small_after = static_cast<std::size_t>(cleanup.total_faces().small);
  return result;
}

FaceDeltas face_deltas_for_tests(const CellComplex& cx, std::vector<bool>& inside, const std::vector<int>& cells,
                                 double small_share) {
  LabelCleanupParams params;
  params.face_price = 1.0;
  params.small_share = small_share;
  const std::vector<std::size_t> no_points;
  Cleanup cleanup(cx, inside, FlipSet{}, params, no_points);
  const Evaluation ev = cleanup.evaluate(cells);
  const FaceCount counted = cleanup.delta_by_counting(cells);
  return {ev.delta_faces, ev.delta_small, counted.faces, counted.small};
}

}  // namespace hsr
