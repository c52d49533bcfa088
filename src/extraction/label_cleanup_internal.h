// Stage 6's label clean-up (label_cleanup.h), internal to src/extraction: what face_regions.cpp (how output
// faces are counted: a plane's surface facets in regions), flip_evaluation.cpp (Cleanup: the regions index and
// what a flip changes) and label_cleanup.cpp (the candidate pool and the greedy flip search) share.
// DECISIONS #26, #35, #37, #38, #59, #62.
#pragma once

#include "extraction/label_cleanup.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <set>
#include <utility>
#include <vector>

namespace hsr::label_cleanup_internal {

using Edge = std::pair<std::uint32_t, std::uint32_t>;  // undirected: (min, max)

/// The area of a facet's loop (its approximate vertices).
double loop_area(const CellComplex& cx, const std::vector<std::uint32_t>& loop);

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

/// The facets of each support plane of `cx` (face_regions.cpp).
std::vector<PlaneFacets> plane_facets(const CellComplex& cx);

/// +1: the facet is on the surface with its plane's normal pointing out (cells[0] outside), -1 reversed,
/// 0 not on the surface.
inline int facet_status(const Facet& f, const std::vector<bool>& inside) {
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
inline long distinct_ids(const std::vector<int>& members, const std::vector<std::vector<int>>& ids, std::vector<int>& stamp,
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
                               const std::vector<int>& seeds, Stamps& stamps);

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
/// The clean-up's state over one labelling (flip_evaluation.cpp): the regions index, the candidates around a
/// region, and what a flip of cells would change.
class Cleanup {
 public:
  Cleanup(const CellComplex& cx, std::vector<bool>& inside, const FlipSet& flip_set,
          const LabelCleanupParams& params, const std::vector<std::size_t>& facet_points);

  FaceCount total_faces() const;
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
  /// with the same members and orientation have the same candidates while none of the cells they read
  /// flips (region_candidates' `read`: a small region's pairs read the labels around it, a flip set those of
  /// its columns).
  int region_count(int p) const { return static_cast<int>(regions_[p].size()); }
  const std::vector<int>& region_members(int p, int r) const { return regions_[p][r].members; }
  int region_side(int p, int r) const;
  /// Region r's candidates (closed under the flip set), sorted, without repeats. `read` (may be null) gets
  /// the cells whose labels they depend on beyond the region's identity (add_pairs, the flip set; with repeats):
  /// while none of them flips and the region keeps its members and orientation, its candidates stay the same.
  std::vector<std::vector<int>> region_candidates(int p, int r, std::vector<int>* read = nullptr) const;
  bool stale(int p) const { return stale_[p] != 0; }
  void listed(int p) { stale_[p] = 0; }

  /// The candidate flips around one region (see plane_candidates()).
  void add_candidates(const Region& r, std::set<std::vector<int>>& out) const;

  /// The candidate flips around one region before closing them under the flip set.
  void add_raw_candidates(const Region& r, std::vector<std::vector<int>>& out, std::vector<int>* read = nullptr) const;

  /// Cell c with each neighbour of the same label (across one of c's facets), as one flip: a sliver that
  /// no single cell removes without opening a new face is often removed by two (issue 14).
  void add_pairs(int c, std::vector<std::vector<int>>& out, std::vector<int>* read = nullptr) const;

  double area_of(const Region& r) const;

  /// The regions still under the small area, with their area share of the surface.
  std::vector<std::pair<Region, double>> small_regions();

  /// Starts a reading: the facets evaluate() and max_gain() look at until take_reads() are collected.
  void begin_reads();
  std::vector<std::uint32_t> take_reads() { return std::move(reads_); }

  /// The planes of the cells' facets (sorted).
  std::vector<int> planes_of(const std::vector<int>& cells) const;

  /// What flipping `cells` would change: the face counts (side_delta(), from the facets that change and the
  /// regions index: its cost follows the flip, not the regions it touches), the points' displacement.
  Evaluation evaluate(const std::vector<int>& cells);

  /// The same face counts by counting every region of the touched planes before and after (what the
  /// clean-up did before issue 25; kept as the reference for tests).
  FaceCount delta_by_counting(const std::vector<int>& cells);

  /// When plane p's regions were last indexed, and the clock all planes share (index_regions() ticks it).
  std::uint64_t indexed_at(int p) const { return indexed_at_[p]; }
  std::uint64_t clock() const { return clock_; }

  /// An upper bound of the weighted faces a flip of `cells` removes (gain in clean_up_labels), from the
  /// regions it touches (those on its cells' facets or next to them; the regions index makes it cheap): a
  /// small region, or one whose facets the flip may all change, at best disappears (all its faces); a larger
  /// one survives and can lose at most one face per hole the flip fills or joins and per region it joins
  /// with: each such change touches a facet the flip changes at one of its corners, so at most the flip's
  /// facets on that plane plus their corners.
  double max_gain(const std::vector<int>& cells, double small_weight);

  /// What a flip costs before dividing by the faces it removes: the larger of the surface's mean displacement
  /// (displacement()) and the points' (Evaluation::point_displacement), fractions of the box diagonal.
  double cost(const std::vector<int>& cells, const Evaluation& ev) const;

  /// With `cells` flipped (`before`: their facets' statuses before): the points on facets that left the
  /// surface move to the facets that entered it. Each facet's points are taken at its centre; their distance
  /// to an entering facet is at least the distance to its plane and to its bounding box (the larger is
  /// used: a lower bound, so the price errs towards the surface's displacement). Less point_tolerance,
  /// times the points, over all points and the diagonal. `supported` gets the points moving farther than
  /// the support distance (by the same lower bound).
  double point_displacement(const std::vector<int>& cells,
                            const std::vector<std::pair<std::uint32_t, int>>& before, std::size_t* supported) const;

  double displacement(const std::vector<int>& cells) const;

  /// False when the flip would leave no cell inside.
  bool can_flip(const std::vector<int>& cells) const;
  void flip(const std::vector<int>& cells);
  /// Records an accepted flip of `cells` (already made): the planes of their facets are indexed again. A
  /// plane's candidates depend on the labels of the cells on its facets and of their neighbours
  /// (add_pairs), so they go stale on the planes of the flipped cells' and their neighbours' facets.
  /// Returns the facets whose status the flip changed (`before`: their statuses before it).
  std::vector<std::uint32_t> commit(const std::vector<int>& cells, const Evaluation& ev,
                                    const std::vector<std::pair<std::uint32_t, int>>& before);
  /// The statuses of the cells' facets now (for commit()).
  std::vector<std::pair<std::uint32_t, int>> statuses(const std::vector<int>& cells) const;

 private:
  /// Records that the current reading looked at local facet k of plane p.
  void note(int p, int k);
  /// A region whose record a reading used: when it is not big (its area under twice the small area), every
  /// change of it matters (its members and their neighbours are noted); a big region's record enters a face
  /// count only through differences (2 - V + E - F of a part of it less its own), so changes of it away
  /// from the facets looked at do not.
  bool is_big(const RegionRecord& rec) const { return rec.count.small == 0 && rec.area >= 2.0 * small_area_; }
  void note_region(int p, const RegionRecord& rec);

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
  FaceCount side_delta(int p, int side, const std::vector<Change>& changes);

  /// Recomputes plane p's regions under inside_: faces_[p], region_of_[p], regions_[p].
  void index_regions(int p);

  std::vector<Region> regions(int p) { return regions_of(cx_, planes_[p], p, inside_, all_[p], stamps_); }

  /// Faces and small faces of plane p's regions that contain one of the local facets `seeds`.
  FaceCount count(int p, const std::vector<int>& seeds);

  /// One region's faces, all of them small when its area is under the small area.
  FaceCount face_count(const PlaneFacets& pf, const std::vector<int>& members, int faces) const;

  /// The union of the flip sets of `cells` (all on one side), sorted; `read` as in region_candidates.
  std::vector<int> closed(const std::vector<int>& cells, std::vector<int>* read = nullptr) const;

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
  std::vector<int> gain_mark_;                        ///< per plane: the max_gain() call its tallies are of
  std::vector<long> gain_facets_, gain_corners_;      ///< per plane: that call's facets on it, their corners
  std::vector<std::uint64_t> indexed_at_;             ///< per plane: clock_ when index_regions() ran
  std::uint64_t clock_ = 0;
  std::vector<char> stale_;  ///< per support plane: its candidates must be listed again (CandidatePool)
  std::vector<double> facet_area_;  ///< per complex facet
  std::size_t inside_count_ = 0;
  double scale_ = 0.0, small_area_ = 0.0, area_ = 0.0;
};

}  // namespace hsr::label_cleanup_internal
