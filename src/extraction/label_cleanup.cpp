// The label clean-up after the min-cut (label_cleanup.h). Output faces are counted the way extraction's
// merge makes them: per support plane, the surface facets of one orientation that share edges form one
// region; a region is one face, plus one per hole (a region with a hole is split into disks).
#include "extraction/label_cleanup.h"

#include "core/error.h"
#include "core/log.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
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

/// The facets of one support plane, with their edges (T-junction vertices inserted) and which facets of
/// the plane share an edge.
struct PlaneFacets {
  std::vector<int> facets;
  std::vector<std::vector<std::uint32_t>> vertices;  ///< per local facet: its loop's vertices, sorted
  std::vector<std::vector<Edge>> edges;              ///< per local facet: its edges, undirected
  std::vector<std::vector<int>> neighbours;          ///< per local facet: local facets sharing an edge
};

std::vector<PlaneFacets> plane_facets(const CellComplex& cx) {
  std::vector<PlaneFacets> out(cx.planes.size());
  for (std::size_t f = 0; f < cx.facets.size(); ++f) out[cx.facets[f].plane].facets.push_back(static_cast<int>(f));
  for (PlaneFacets& p : out) {
    std::vector<std::vector<std::uint32_t>> loops;
    for (int f : p.facets) loops.push_back(cx.facets[f].vertices);
    insert_t_junctions(cx, loops);  // a complex built without flat vertices meets in T-junctions
    std::map<Edge, std::vector<int>> by_edge;
    p.edges.resize(loops.size());
    p.vertices.resize(loops.size());
    for (std::size_t k = 0; k < loops.size(); ++k) {
      const auto& l = loops[k];
      for (std::size_t i = 0; i < l.size(); ++i) {
        const Edge e{std::min(l[i], l[(i + 1) % l.size()]), std::max(l[i], l[(i + 1) % l.size()])};
        p.edges[k].push_back(e);
        by_edge[e].push_back(static_cast<int>(k));
      }
      p.vertices[k] = l;
      std::sort(p.vertices[k].begin(), p.vertices[k].end());
    }
    p.neighbours.resize(loops.size());
    for (const auto& [e, ks] : by_edge)
      for (int a : ks)
        for (int b : ks)
          if (a != b) p.neighbours[a].push_back(b);
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

/// The regions of one plane under `inside` (components of equal status through shared edges).
std::vector<Region> regions_of(const CellComplex& cx, const PlaneFacets& p, int plane, const std::vector<bool>& inside) {
  const std::size_t n = p.facets.size();
  std::vector<int> status(n), seen(n, 0);
  for (std::size_t k = 0; k < n; ++k) status[k] = facet_status(cx.facets[p.facets[k]], inside);
  std::vector<Region> out;
  std::vector<std::uint32_t> verts;
  std::vector<Edge> edges;
  for (std::size_t s = 0; s < n; ++s) {
    if (status[s] == 0 || seen[s]) continue;
    std::vector<int> members{static_cast<int>(s)};
    seen[s] = 1;
    for (std::size_t i = 0; i < members.size(); ++i)
      for (int nb : p.neighbours[members[i]])
        if (!seen[nb] && status[nb] == status[s]) {
          seen[nb] = 1;
          members.push_back(nb);
        }
    // Holes from the Euler characteristic of the region: V - E + F = 1 - holes.
    verts.clear();
    edges.clear();
    for (int k : members) {
      verts.insert(verts.end(), p.vertices[k].begin(), p.vertices[k].end());
      edges.insert(edges.end(), p.edges[k].begin(), p.edges[k].end());
    }
    std::sort(verts.begin(), verts.end());
    std::sort(edges.begin(), edges.end());
    const long v = std::unique(verts.begin(), verts.end()) - verts.begin();
    const long e = std::unique(edges.begin(), edges.end()) - edges.begin();
    const long holes = std::max(0L, 1 - (v - e + static_cast<long>(members.size())));
    Region r;
    r.plane = plane;
    r.faces = 1 + static_cast<int>(holes);
    for (int k : members) r.facets.push_back(p.facets[k]);
    out.push_back(std::move(r));
  }
  return out;
}

/// Output faces of one plane, and how many of them are small (a region under the small area: all its faces).
struct FaceCount {
  int faces = 0, small = 0;
};

FaceCount faces_of(const CellComplex& cx, const PlaneFacets& p, int plane, const std::vector<bool>& inside,
                   const std::vector<double>& facet_area, double small_area) {
  FaceCount total;
  for (const Region& r : regions_of(cx, p, plane, inside)) {
    total.faces += r.faces;
    double area = 0.0;
    for (int f : r.facets) area += facet_area[f];
    if (area < small_area) total.small += r.faces;
  }
  return total;
}

struct Evaluation {
  int delta_faces = 0, delta_small = 0;
  std::vector<int> planes;  ///< support planes whose facets the move changes (sorted)
};

class Cleanup {
 public:
  Cleanup(const CellComplex& cx, std::vector<bool>& inside, const FlipSet& flip_set, double small_share)
      : cx_(cx), inside_(inside), flip_set_(flip_set), planes_(plane_facets(cx)) {
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
    for (std::size_t p = 0; p < planes_.size(); ++p) faces_[p] = count(static_cast<int>(p));
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
  /// label (each with the cells its flip drags along). Sorted, without duplicates.
  std::vector<std::vector<int>> candidates() const {
    std::set<std::vector<int>> out;
    for (std::size_t p = 0; p < planes_.size(); ++p)
      for (const Region& r : regions_of(cx_, planes_[p], static_cast<int>(p), inside_)) add_candidates(r, out);
    return {out.begin(), out.end()};
  }

  /// The candidate flips around one region (see candidates()).
  void add_candidates(const Region& r, std::set<std::vector<int>>& out) const {
    std::vector<int> in_cells, out_cells;
    for (int f : r.facets)
      for (int c : cx_.facets[f].cells)
        if (c >= 0) (inside_[c] ? in_cells : out_cells).push_back(c);
    for (auto* side : {&in_cells, &out_cells}) {
      std::sort(side->begin(), side->end());
      side->erase(std::unique(side->begin(), side->end()), side->end());
      if (side->empty()) continue;
      for (int c : *side) out.insert(closed(std::vector<int>{c}));
      if (side->size() > 1) out.insert(closed(*side));
      if (area_of(r) < small_area_)
        for (int c : *side) add_pairs(c, out);
    }
  }

  /// Cell c with each neighbour of the same label (across one of c's facets), as one flip: a sliver that
  /// no single cell removes without opening a new face is often removed by two (issue 14).
  void add_pairs(int c, std::set<std::vector<int>>& out) const {
    for (std::uint32_t f : cx_.cells[c].facets)
      for (int d : cx_.facets[f].cells)
        if (d >= 0 && d != c && inside_[d] == inside_[c]) out.insert(closed(std::vector<int>{c, d}));
  }

  double area_of(const Region& r) const {
    double area = 0.0;
    for (int f : r.facets) area += facet_area_[f];
    return area;
  }

  /// The regions still under the small area, with their area share of the surface.
  std::vector<std::pair<Region, double>> small_regions() const {
    std::vector<std::pair<Region, double>> out;
    for (std::size_t p = 0; p < planes_.size(); ++p)
      for (Region& r : regions_of(cx_, planes_[p], static_cast<int>(p), inside_)) {
        const double area = area_of(r);
        if (area < small_area_) out.emplace_back(std::move(r), area / area_);
      }
    return out;
  }

  Evaluation evaluate(const std::vector<int>& cells) {
    Evaluation ev;
    for (int c : cells)
      for (std::uint32_t f : cx_.cells[c].facets) ev.planes.push_back(cx_.facets[f].plane);
    std::sort(ev.planes.begin(), ev.planes.end());
    ev.planes.erase(std::unique(ev.planes.begin(), ev.planes.end()), ev.planes.end());
    flip(cells);
    for (int p : ev.planes) {
      const FaceCount now = count(p);
      ev.delta_faces += now.faces - faces_[p].faces;
      ev.delta_small += now.small - faces_[p].small;
    }
    flip(cells);
    return ev;
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
  void commit(const Evaluation& ev) {
    for (int p : ev.planes) faces_[p] = count(p);
  }

 private:
  FaceCount count(int p) const { return faces_of(cx_, planes_[p], p, inside_, facet_area_, small_area_); }

  /// The union of the flip sets of `cells` (all on one side), sorted.
  std::vector<int> closed(const std::vector<int>& cells) const {
    std::vector<int> out;
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
  std::vector<FaceCount> faces_;  ///< per support plane: its output faces under inside_
  std::vector<double> facet_area_;  ///< per complex facet
  std::size_t inside_count_ = 0;
  double scale_ = 0.0, small_area_ = 0.0, area_ = 0.0;
};

bool intersects(const std::vector<int>& a, const std::vector<int>& b) {
  auto i = a.begin(), j = b.begin();
  while (i != a.end() && j != b.end()) {
    if (*i == *j) return true;
    (*i < *j) ? ++i : ++j;
  }
  return false;
}

/// Why each small region the clean-up stopped at is still there (shown with --verbose): of the candidate
/// flips around it, the cheapest that removes faces without adding any, and whether it was over the price or
/// would leave the surface non-manifold; or, if none, the fewest faces a candidate adds.
void explain_small_regions(Cleanup& cleanup, const LabelCleanupParams& params, const DefectCount& defects,
                           std::size_t defects_before, const std::vector<bool>& inside) {
  for (const auto& [region, share] : cleanup.small_regions()) {
    std::set<std::vector<int>> cands;
    cleanup.add_candidates(region, cands);
    double best_price = std::numeric_limits<double>::infinity(), best_manifold = best_price;
    int fewest_added = std::numeric_limits<int>::max();
    std::size_t best_size = 0;
    for (const auto& cand : cands) {
      if (!cleanup.can_flip(cand)) continue;
      const Evaluation ev = cleanup.evaluate(cand);
      const double gain = -ev.delta_faces - params.small_weight * ev.delta_small;
      if (ev.delta_faces > 0 || !(gain > 0)) {
        fewest_added = std::min(fewest_added, ev.delta_faces);
        continue;
      }
      const double price = cleanup.displacement(cand) / gain;
      cleanup.flip(cand);
      const bool manifold = defects(inside) <= defects_before;
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
                                   const FlipSet& flip_set, const DefectCount& defects) {
  LabelCleanupResult result;
  if (!(params.face_price > 0.0) || cx.cells.empty()) return result;
  Cleanup cleanup(cx, inside, flip_set, params.small_share);
  result.faces_before = result.faces_after = static_cast<std::size_t>(cleanup.total_faces().faces);
  result.small_before = result.small_after = static_cast<std::size_t>(cleanup.total_faces().small);
  const std::size_t defects_before = defects(inside);
  std::map<std::vector<int>, Evaluation> cache;  // valid while none of its planes changed
  std::set<std::vector<int>> refused;            // not manifold; cleared when a flip is accepted
  while (result.moves < params.max_moves) {
    // The cheapest flip per face removed (ties: fewer cells, then the smaller cell list).
    const std::vector<int>* best = nullptr;
    Evaluation best_eval;
    double best_price = std::numeric_limits<double>::infinity();
    const auto candidates = cleanup.candidates();
    for (const auto& cells : candidates) {
      if (refused.count(cells) || !cleanup.can_flip(cells)) continue;
      auto it = cache.find(cells);
      if (it == cache.end()) it = cache.emplace(cells, cleanup.evaluate(cells)).first;
      const Evaluation& ev = it->second;
      // Never more faces; a small face removed counts small_weight faces.
      const double gain = -ev.delta_faces - params.small_weight * ev.delta_small;
      if (ev.delta_faces > 0 || !(gain > 0)) continue;
      const double price = cleanup.displacement(cells) / gain;
      if (price < best_price || (price == best_price && best && cells.size() < best->size())) {
        best = &cells;
        best_eval = ev;
        best_price = price;
      }
    }
    if (!best || best_price > params.face_price) break;
    cleanup.flip(*best);
    if (defects(inside) > defects_before) {
      cleanup.flip(*best);
      refused.insert(*best);
      ++result.rejected;
      continue;
    }
    cleanup.commit(best_eval);
    for (auto it = cache.begin(); it != cache.end();)
      it = intersects(it->second.planes, best_eval.planes) ? cache.erase(it) : std::next(it);
    refused.clear();
    ++result.moves;
    result.cells_flipped += best->size();
    result.displacement += cleanup.displacement(*best);
  }
  if (log::level() >= log::Level::Verbose) explain_small_regions(cleanup, params, defects, defects_before, inside);
  result.faces_after = static_cast<std::size_t>(cleanup.total_faces().faces);
  result.small_after = static_cast<std::size_t>(cleanup.total_faces().small);
  return result;
}

}  // namespace hsr
