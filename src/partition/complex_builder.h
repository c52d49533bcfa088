// Internal to src/partition: the mutable cell complex the partitioners refine, one exact plane split at a
// time, and its conversion to the plain CellComplex.
//
// Conformity. Facets are shared objects referenced by the (one or two) cells they bound. The complex is
// kept *edge-conforming*: every edge of every facet is an edge of every other facet containing it. When a
// split creates a vertex on an edge, that vertex is inserted into every facet around the edge (found
// through an edge -> facets map), so facets of neighbouring cells may carry vertices with a flat (180°)
// angle; when a facet shared by cells A and B is split because A is split, both halves replace it in B's
// facet list. This is what makes validate()'s "each edge twice within a cell" check exact.
#pragma once

#include "partition/exact_geometry.h"


#include <algorithm>
#include <cstdint>
#include <deque>
#include <map>
#include <unordered_map>
#include <vector>

namespace hsr::partition_internal {

/// The facets around one edge, in the order they were added: up to four inline (the usual 2 to 4), more on the
/// heap. 24 bytes, where boost::container::small_vector<std::uint32_t, 4> takes 40 (its size and capacity are 8-byte
/// words, and Boost 1.74 has no stored_size option for it): the edge map's slot is 32 bytes, not 48 (DECISIONS #238).
class FacetList {
 public:
  FacetList() {}
  FacetList(const FacetList& o) { assign(o); }
  FacetList(FacetList&& o) noexcept { take(o); }
  FacetList& operator=(const FacetList& o) {
    if (this != &o) {
      release();
      assign(o);
    }
    return *this;
  }
  FacetList& operator=(FacetList&& o) noexcept {
    if (this != &o) {
      release();
      take(o);
    }
    return *this;
  }
  ~FacetList() { release(); }

  std::uint32_t* begin() { return data(); }
  std::uint32_t* end() { return data() + size_; }
  const std::uint32_t* begin() const { return data(); }
  const std::uint32_t* end() const { return data() + size_; }
  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  void push_back(std::uint32_t f) {
    if (size_ == capacity_) grow();
    data()[size_++] = f;
  }
  /// Removes the element at `it`, the later ones moved up (their order kept).
  void erase(std::uint32_t* it) {
    std::copy(it + 1, end(), it);
    --size_;
  }
  void clear() { size_ = 0; }

 private:
  static constexpr std::uint32_t kInline = 4;
  bool on_heap() const { return capacity_ > kInline; }
  std::uint32_t* data() { return on_heap() ? heap_ : inline_; }
  const std::uint32_t* data() const { return on_heap() ? heap_ : inline_; }
  void grow() {
    auto* p = new std::uint32_t[2 * capacity_];
    std::copy(begin(), end(), p);
    if (on_heap()) delete[] heap_;
    heap_ = p;
    capacity_ *= 2;
  }
  void release() {
    if (on_heap()) delete[] heap_;
    capacity_ = kInline;
    size_ = 0;
  }
  void assign(const FacetList& o) {  // *this empty and inline
    if (o.size_ > kInline) {
      heap_ = new std::uint32_t[o.size_];
      capacity_ = o.size_;
    }
    std::copy(o.begin(), o.end(), data());
    size_ = o.size_;
  }
  void take(FacetList& o) {  // *this empty and inline
    if (o.on_heap()) heap_ = o.heap_;
    else std::copy(o.begin(), o.end(), inline_);
    size_ = o.size_;
    capacity_ = o.capacity_;
    o.capacity_ = kInline;
    o.size_ = 0;
  }
  std::uint32_t size_ = 0, capacity_ = kInline;
  union {
    std::uint32_t inline_[kInline];
    std::uint32_t* heap_;
  };
};

/// The facets around each edge of the complex (an edge key u < v, never 0): open addressing with linear probing
/// and backward-shift deletion, the short lists inline. (std::unordered_map allocated one node per edge and its
/// lookups were a tenth of a large partition's time.)
class EdgeFacetMap {
 public:
  using List = FacetList;
  /// The list of `key`, or null.
  List* find(std::uint64_t key);
  /// The list of `key`, created empty if absent.
  List& operator[](std::uint64_t key);
  void erase(std::uint64_t key);

 private:
  struct Slot {
    std::uint64_t key = 0;  // 0: empty
    List list;
  };
  std::size_t home(std::uint64_t key) const {
    std::uint64_t z = key + 0x9e3779b97f4a7c15ull;  // splitmix64 finaliser
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return static_cast<std::size_t>(z ^ (z >> 31)) & (slots_.size() - 1);
  }
  void grow();
  std::vector<Slot, TableAllocator<Slot>> slots_;
  std::size_t used_ = 0;
};

class ComplexBuilder {
 public:
  /// The box [lo, hi] (positive volume): 8 vertices, 6 BoxSide planes (ids 0..5), 6 facets, 1 cell.
  ComplexBuilder(const ExactPoint& lo, const ExactPoint& hi);

  /// Id of the support plane with these canonical coefficients, created (kind Input) if new.
  int add_plane(const ExactPlane& canonical);
  SupportPlane& plane(int id) { return planes_[id].support; }
  const SupportPlane& plane(int id) const { return planes_[id].support; }
  const PlaneFrame& frame(int id) const { return planes_[id].frame; }
  int num_planes() const { return static_cast<int>(planes_.size()); }
  int num_cells() const { return static_cast<int>(cells_.size()); }

  /// Conservative double test: false only if plane `h` certainly misses the interior of `cell`'s bbox.
  bool may_cross(int cell, int h) const;
  /// Exact: the cell has vertices strictly on both sides of plane `h`.
  bool crosses(int cell, int h);
  /// The same without the builder's sign cache: safe to call from several threads at once (with section_of).
  bool crosses_of(int cell, int h) const;
  /// Conservative double test: false only if the convex polygon with these vertices certainly misses
  /// the cell (all its vertices strictly outside one facet plane).
  bool may_meet_polygon(int cell, const std::vector<Vec3>& polygon) const;
  /// Exact: the point is strictly inside the cell (strictly on the inner side of every facet's plane).
  bool contains_strictly(int cell, const ExactPoint& p) const;
  /// The integer coefficients of support plane `id` (exact_geometry.h).
  const IntPlane& int_plane_of(int id) const { return planes_[id].integer; }
  /// Exact 2D section (frame of `h`) of the cell by plane h, convex CCW; requires crosses(cell, h).
  std::vector<P2> section(int cell, int h);
  /// The same without the sign cache (thread-safe, like crosses_of).
  std::vector<P2> section_of(int cell, int h) const;
  /// Double bbox of the cell.
  const BBox& cell_bbox(int cell) const { return cells_[cell].bbox; }

  /// Splits `cell` by plane `h` (requires crosses(cell, h)). The positive side keeps the id `cell`, the
  /// negative side gets id num_cells() - 1 afterwards. The new cap facet gets `level`.
  void split(int cell, int h, int level);

  /// Merges the cells of `group` (distinct, alive, at least 2) into one: the facets between two members are
  /// removed, the others are kept (coplanar neighbours on the union's boundary stay separate facets, so the
  /// complex stays edge-conforming). The caller guarantees that the union is convex. The smallest id keeps
  /// the union, the other ids die (alive() false, skipped by finish()).
  void merge_cells(std::vector<int> group);
  bool alive(int cell) const { return cells_[cell].alive; }

  /// Id of the support plane with these canonical coefficients, or -1.
  int find_plane(const ExactPlane& canonical) const {
    auto it = plane_index_.find(canonical);
    return it == plane_index_.end() ? -1 : it->second;
  }
  // Read access for the kinetic partitioners.
  const std::vector<std::uint32_t>& cell_facets(int cell) const { return cells_[cell].facets; }
  int facet_plane(std::uint32_t f) const { return facets_[f].plane; }
  const std::array<int, 2>& facet_cells(std::uint32_t f) const { return facets_[f].cells; }
  const std::vector<std::uint32_t>& facet_vertices(std::uint32_t f) const { return facets_[f].vertices; }
  const ExactPoint& vertex(std::uint32_t v) const { return vertices_[v]; }
  const Vec3& vertex_approx(std::uint32_t v) const { return vertices_approx_[v]; }

  /// Compacts and converts: exact volumes (only when `exact_volumes`: they cost ~15% of a large partition
  /// and nothing but validate() needs them, which recomputes them), double centroids, approximate
  /// coordinates. Dead cells and vertices no facet uses any more (after merges) are dropped. Consumes the
  /// builder (DECISIONS #234): its lookup tables are freed first and its vertices, planes and lists are moved,
  /// not copied, so the complex is not held twice at the partition's peak of memory.
  CellComplex finish(bool exact_volumes = true) &&;

 private:
  struct PlaneData {
    SupportPlane support;
    IntPlane integer;  // the plane's integer coefficients (gcd-free exact signs and constructions)
    PlaneFrame frame;
    double da = 0, db = 0, dc = 0, dd = 0;  // canonical coefficients rounded to double (filter)
    bool trusted = false;                   // all four are trusted_double images
  };
  struct WFacet {
    std::vector<std::uint32_t> vertices;
    int plane = -1;
    std::array<int, 2> cells = {-1, -1};
    int level = 0;
    bool alive = true;
  };
  struct WCell {
    std::vector<std::uint32_t> facets;
    BBox bbox;
    bool alive = true;
  };

  std::uint32_t vertex_id(ExactPoint p);
  int sign(std::uint32_t vertex, int h);  ///< exact side of a vertex, cached for the last plane asked
  int sign_uncached(std::uint32_t vertex, int h) const;
  template <class Sign>
  bool crosses_by(int cell, Sign&& sign) const;
  template <class Sign>
  std::vector<P2> section_by(int cell, int h, Sign&& sign) const;
  /// Exact side of a point that is not a vertex, filtered_sign first with its double image `d` (trusted: the three
  /// coordinates are trusted_double images).
  int side_of(int h, const ExactPoint& p, const Vec3& d, bool trusted) const;
  /// The edges (u < v) of `cell` that plane h crosses (vertices strictly on both sides), sorted, each with two
  /// distinct support planes through it (second -1 when only one is known).
  struct CrossedEdge {
    std::uint32_t u, v;
    int plane1, plane2;
  };
  template <class Sign>
  std::vector<CrossedEdge> crossed_edges(int cell, Sign&& sign) const;
  /// The point where plane h crosses a crossed edge: the common point of h and the edge's two planes (Cramer on
  /// integers), or of h and the segment when the edge lies on one known plane only.
  ExactPoint crossing_point(const CrossedEdge& e, int h) const;
  /// Its image in the frame of h (one gcd fewer: sections need no third coordinate).
  P2 crossing_point_2d(const CrossedEdge& e, int h) const;
  void use_plane(int h);
  void add_edges(std::uint32_t facet);
  void remove_edges(std::uint32_t facet);
  void split_edge(std::uint32_t u, std::uint32_t v, std::uint32_t w);
  std::uint32_t new_facet(WFacet f);
  /// The edge map after facet f (dead) was split into facets `first` and `second` along a chord.
  void hand_edges_to_halves(std::uint32_t f, std::uint32_t first, std::uint32_t second);
  void update_bbox(int cell);
  /// Frees what only refinement looks up (the edge map, the vertex index, the sign cache, the plane index):
  /// finish() needs none of them.
  void release_lookups();
  static std::uint64_t edge_key(std::uint32_t u, std::uint32_t v) {
    if (u > v) std::swap(u, v);
    return (static_cast<std::uint64_t>(u) << 32) | v;
  }

  ExactPoint lo_, hi_;
  // A deque: GMP 6.2's rationals have no noexcept move, so a growing vector would copy every vertex.
  std::deque<ExactPoint> vertices_;
  std::vector<Vec3> vertices_approx_;
  std::vector<char> vertex_trusted_;  // the three coordinates of vertices_approx_ are trusted_double images
  ExactPointIndex vertex_index_;
  std::vector<PlaneData> planes_;
  std::map<ExactPlane, int, bool (*)(const ExactPlane&, const ExactPlane&)> plane_index_{plane_less};
  std::vector<WFacet> facets_;
  std::vector<WCell> cells_;
  // The facets around each edge (usually 2 to 4: kept inline). Mutable: find() is logically const.
  mutable EdgeFacetMap edge_facets_;
  // Sign of each vertex w.r.t. plane `cached_plane_`, valid where its stamp equals sign_generation_ (a new plane
  // starts a new generation instead of clearing the whole cache). Stamp and sign side by side: one cache line.
  int cached_plane_ = -1;
  std::uint32_t sign_generation_ = 0;
  struct SignEntry {
    std::uint32_t stamp = 0;
    int sign = 2;
  };
  std::vector<SignEntry> sign_cache_;
};

}  // namespace hsr::partition_internal
