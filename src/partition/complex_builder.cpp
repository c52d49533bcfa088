#include "partition/complex_builder.h"

#include "core/error.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace hsr::partition_internal {

namespace {


Plane approx_plane(const ExactPlane& e) {
  Vec3 n(e.a.get_d(), e.b.get_d(), e.c.get_d());
  double len = n.norm();
  Plane p;
  p.normal = n / len;
  p.offset = e.d.get_d() / len;
  return p;
}

}  // namespace

EdgeFacetMap::List* EdgeFacetMap::find(std::uint64_t key) {
  if (slots_.empty()) return nullptr;
  for (std::size_t i = home(key);; i = (i + 1) & (slots_.size() - 1)) {
    if (slots_[i].key == key) return &slots_[i].list;
    if (slots_[i].key == 0) return nullptr;
  }
}

EdgeFacetMap::List& EdgeFacetMap::operator[](std::uint64_t key) {
  if (2 * (used_ + 1) > slots_.size()) grow();
  std::size_t i = home(key);
  for (; slots_[i].key != 0; i = (i + 1) & (slots_.size() - 1))
    if (slots_[i].key == key) return slots_[i].list;
  slots_[i].key = key;
  ++used_;
  return slots_[i].list;
}

void EdgeFacetMap::erase(std::uint64_t key) {
  if (slots_.empty()) return;
  const std::size_t mask = slots_.size() - 1;
  std::size_t i = home(key);
  for (; slots_[i].key != key; i = (i + 1) & mask)
    if (slots_[i].key == 0) return;
  // Backward shift: move later entries of the probe run into the hole when their home allows it.
  for (std::size_t j = (i + 1) & mask; slots_[j].key != 0; j = (j + 1) & mask) {
    const std::size_t h = home(slots_[j].key);
    // j's entry may fill the hole at i when h is not in the cyclic range (i, j].
    if (((j - h) & mask) >= ((j - i) & mask)) {
      slots_[i].key = slots_[j].key;
      slots_[i].list = std::move(slots_[j].list);
      i = j;
    }
  }
  slots_[i].key = 0;
  slots_[i].list.clear();
  --used_;
}

void EdgeFacetMap::grow() {
  std::vector<Slot, TableAllocator<Slot>> old = std::move(slots_);
  slots_ = std::vector<Slot, TableAllocator<Slot>>(old.empty() ? 1024 : 2 * old.size());
  used_ = 0;
  for (Slot& s : old)
    if (s.key != 0) (*this)[s.key] = std::move(s.list);
}

ComplexBuilder::ComplexBuilder(const ExactPoint& lo, const ExactPoint& hi) : lo_(lo), hi_(hi) {
  HSR_ASSERT(lo.x < hi.x && lo.y < hi.y && lo.z < hi.z, "box must have positive volume");
  std::uint32_t corner[8];
  for (int i = 0; i < 8; ++i)
    corner[i] = vertex_id({(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z});
  cells_.push_back({});
  for (int side = 0; side < 6; ++side) {
    const int axis = side / 2;
    const bool high = side % 2 == 1;
    const Rational& value = axis == 0 ? (high ? hi.x : lo.x) : axis == 1 ? (high ? hi.y : lo.y) : (high ? hi.z : lo.z);
    int id = add_plane(axis_plane(axis, value));
    HSR_ASSERT(id == side, "box planes come first");
    planes_[id].support.kind = SupportPlane::Kind::BoxSide;
    planes_[id].support.box_side = side;
    std::vector<std::uint32_t> on_face;
    for (int i = 0; i < 8; ++i)
      if (((i >> axis) & 1) == (high ? 1 : 0)) on_face.push_back(corner[i]);
    std::vector<P2> pts;
    for (auto v : on_face) pts.push_back(to_2d(planes_[id].frame, vertices_[v]));
    WFacet f;
    for (int k : sort_ccw(pts)) f.vertices.push_back(on_face[k]);
    f.plane = id;
    // The canonical normal of a box side points to +axis: the box is on the positive side of its low side.
    f.cells = high ? std::array<int, 2>{-1, 0} : std::array<int, 2>{0, -1};
    f.level = 0;
    cells_[0].facets.push_back(new_facet(std::move(f)));
  }
  update_bbox(0);
}

std::uint32_t ComplexBuilder::vertex_id(ExactPoint p) {
  const std::size_t hash = ExactPointHash()(p);
  const std::int64_t found = vertex_index_.find(p, hash, vertices_);
  if (found >= 0) return static_cast<std::uint32_t>(found);
  auto id = static_cast<std::uint32_t>(vertices_.size());
  vertices_approx_.push_back(to_double(p));
  const Vec3& d = vertices_approx_.back();
  vertex_trusted_.push_back(trusted_double(p.x, d.x()) && trusted_double(p.y, d.y()) && trusted_double(p.z, d.z()));
  vertices_.push_back(std::move(p));
  vertex_index_.insert(hash, id);
  return id;
}

int ComplexBuilder::add_plane(const ExactPlane& canonical) {
  auto it = plane_index_.find(canonical);
  if (it != plane_index_.end()) return it->second;
  PlaneData d;
  d.support.kind = SupportPlane::Kind::Input;
  d.support.exact = canonical;
  d.integer = int_plane(canonical);
  d.support.approx = approx_plane(canonical);
  d.frame = frame_of(canonical);
  d.da = canonical.a.get_d();
  d.db = canonical.b.get_d();
  d.dc = canonical.c.get_d();
  d.dd = canonical.d.get_d();
  d.trusted = trusted_double(canonical.a, d.da) && trusted_double(canonical.b, d.db) &&
              trusted_double(canonical.c, d.dc) && trusted_double(canonical.d, d.dd);
  int id = static_cast<int>(planes_.size());
  planes_.push_back(std::move(d));
  plane_index_.emplace(canonical, id);
  return id;
}

void ComplexBuilder::use_plane(int h) {
  if (cached_plane_ == h) return;
  cached_plane_ = h;
  if (++sign_generation_ == 0) {  // wrapped around: every stamp is stale again
    for (SignEntry& e : sign_cache_) e.stamp = 0;
    sign_generation_ = 1;
  }
}

int ComplexBuilder::sign(std::uint32_t v, int h) {
  use_plane(h);
  if (v >= sign_cache_.size()) sign_cache_.resize(vertices_.size());
  SignEntry& e = sign_cache_[v];
  if (e.stamp != sign_generation_) {
    e.stamp = sign_generation_;
    e.sign = sign_uncached(v, h);
  }
  return e.sign;
}

int ComplexBuilder::sign_uncached(std::uint32_t v, int h) const {
  const PlaneData& p = planes_[h];
  if (p.trusted && vertex_trusted_[v]) {
    const Vec3& q = vertices_approx_[v];
    const double tx = p.da * q.x(), ty = p.db * q.y(), tz = p.dc * q.z();
    if (int s = filtered_sign(tx + ty + tz + p.dd, std::abs(tx) + std::abs(ty) + std::abs(tz) + std::abs(p.dd)))
      return s;
  }
  return side_exact(p.integer, vertices_[v]);
}

int ComplexBuilder::side_of(int h, const ExactPoint& x, const Vec3& d, bool trusted) const {
  const PlaneData& p = planes_[h];
  if (p.trusted && trusted) {
    const double tx = p.da * d.x(), ty = p.db * d.y(), tz = p.dc * d.z();
    if (int s = filtered_sign(tx + ty + tz + p.dd, std::abs(tx) + std::abs(ty) + std::abs(tz) + std::abs(p.dd)))
      return s;
  }
  return side_exact(p.integer, x);
}

template <class Sign>
std::vector<ComplexBuilder::CrossedEdge> ComplexBuilder::crossed_edges(int cell, Sign&& sign) const {
  std::vector<CrossedEdge> all;
  for (auto f : cells_[cell].facets) {
    const auto& loop = facets_[f].vertices;
    const std::size_t n = loop.size();
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint32_t u = loop[i], v = loop[(i + 1) % n];
      if (sign(u) * sign(v) < 0) all.push_back({std::min(u, v), std::max(u, v), facets_[f].plane, -1});
    }
  }
  std::sort(all.begin(), all.end(), [](const CrossedEdge& a, const CrossedEdge& b) {
    return a.u != b.u ? a.u < b.u : a.v != b.v ? a.v < b.v : a.plane1 < b.plane1;
  });
  std::vector<CrossedEdge> out;
  for (const CrossedEdge& e : all) {
    if (!out.empty() && out.back().u == e.u && out.back().v == e.v) {
      if (out.back().plane2 < 0 && e.plane1 != out.back().plane1) out.back().plane2 = e.plane1;
      continue;
    }
    out.push_back(e);
  }
  // An edge between two coplanar facets of the cell (after a merge): a facet of a neighbouring cell may give
  // its second plane.
  for (CrossedEdge& e : out) {
    if (e.plane2 >= 0) continue;
    const EdgeFacetMap::List* around = edge_facets_.find(edge_key(e.u, e.v));
    if (!around) continue;
    for (auto f : *around)
      if (facets_[f].plane != e.plane1) { e.plane2 = facets_[f].plane; break; }
  }
  return out;
}

ExactPoint ComplexBuilder::crossing_point(const CrossedEdge& e, int h) const {
  ExactPoint p;
  if (e.plane2 >= 0 && meet_planes(planes_[e.plane1].integer, planes_[e.plane2].integer, planes_[h].integer, p))
    return p;
  return intersect_segment(planes_[h].integer, vertices_[e.u], vertices_[e.v]);
}

P2 ComplexBuilder::crossing_point_2d(const CrossedEdge& e, int h) const {
  const PlaneFrame& fr = planes_[h].frame;
  P2 q;
  if (e.plane2 >= 0 && meet_planes(planes_[e.plane1].integer, planes_[e.plane2].integer, planes_[h].integer, fr, q))
    return q;
  return to_2d(fr, intersect_segment(planes_[h].integer, vertices_[e.u], vertices_[e.v]));
}

bool ComplexBuilder::may_cross(int cell, int h) const {
  if (!filters_on()) return true;
  const PlaneData& p = planes_[h];
  const BBox& b = cells_[cell].bbox;
  const double coefs[3] = {p.da, p.db, p.dc};
  double lo = p.dd, hi = p.dd, mag = std::abs(p.dd);
  for (int k = 0; k < 3; ++k) {
    const double t0 = coefs[k] * b.min[k], t1 = coefs[k] * b.max[k];
    lo += std::min(t0, t1);
    hi += std::max(t0, t1);
    mag += std::max(std::abs(t0), std::abs(t1));
  }
  // The bbox holds double images of the exact vertices (relative error below 2^-52, or an absolute one below
  // 2^-1074 for a tiny coordinate): the slack covers both, and anything not finite answers "may".
  const double slack = 1e-9 * mag + (std::abs(p.da) + std::abs(p.db) + std::abs(p.dc)) * 1e-300;
  if (!std::isfinite(lo) || !std::isfinite(hi) || !std::isfinite(slack)) return true;
  return lo < slack && hi > -slack;
}

template <class Sign>
bool ComplexBuilder::crosses_by(int cell, Sign&& sign) const {
  bool pos = false, neg = false;
  for (auto f : cells_[cell].facets)
    for (auto v : facets_[f].vertices) {
      const int s = sign(v);
      pos |= s > 0;
      neg |= s < 0;
      if (pos && neg) return true;
    }
  return false;
}

bool ComplexBuilder::crosses(int cell, int h) {
  return crosses_by(cell, [&](std::uint32_t v) { return sign(v, h); });
}

bool ComplexBuilder::crosses_of(int cell, int h) const {
  return crosses_by(cell, [&](std::uint32_t v) { return sign_uncached(v, h); });
}

bool ComplexBuilder::may_meet_polygon(int cell, const std::vector<Vec3>& polygon) const {
  if (!filters_on()) return true;
  for (auto f : cells_[cell].facets) {
    const WFacet& g = facets_[f];
    const PlaneData& p = planes_[g.plane];
    const double inner = g.cells[0] == cell ? 1.0 : -1.0;
    bool all_outside = true;
    for (const Vec3& q : polygon) {
      const double tx = p.da * q.x(), ty = p.db * q.y(), tz = p.dc * q.z();
      const double value = inner * (tx + ty + tz + p.dd);
      const double slack = 1e-9 * (std::abs(tx) + std::abs(ty) + std::abs(tz) + std::abs(p.dd)) +
                           (std::abs(p.da) + std::abs(p.db) + std::abs(p.dc)) * 1e-300;  // as in may_cross
      if (!(value < -slack) || !std::isfinite(slack)) { all_outside = false; break; }
    }
    if (all_outside) return false;
  }
  return true;
}

template <class Sign>
std::vector<P2> ComplexBuilder::section_by(int cell, int h, Sign&& sign) const {
  const PlaneFrame& fr = planes_[h].frame;
  std::vector<std::uint32_t> on_plane;
  for (auto f : cells_[cell].facets)
    for (auto u : facets_[f].vertices)
      if (sign(u) == 0) on_plane.push_back(u);
  // Each vertex and edge is seen from several facets: compute each point once.
  std::sort(on_plane.begin(), on_plane.end());
  on_plane.erase(std::unique(on_plane.begin(), on_plane.end()), on_plane.end());
  const std::vector<CrossedEdge> crossed = crossed_edges(cell, sign);
  std::vector<P2> pts;
  pts.reserve(on_plane.size() + crossed.size());  // (a growing vector of rationals copies them)
  for (auto v : on_plane) pts.push_back(to_2d(fr, vertices_[v]));
  for (const CrossedEdge& e : crossed) pts.push_back(crossing_point_2d(e, h));
  return convex_hull(std::move(pts));
}

std::vector<P2> ComplexBuilder::section(int cell, int h) {
  return section_by(cell, h, [&](std::uint32_t v) { return sign(v, h); });
}

std::vector<P2> ComplexBuilder::section_of(int cell, int h) const {
  return section_by(cell, h, [&](std::uint32_t v) { return sign_uncached(v, h); });
}

void ComplexBuilder::add_edges(std::uint32_t f) {
  const auto& loop = facets_[f].vertices;
  for (std::size_t i = 0; i < loop.size(); ++i)
    edge_facets_[edge_key(loop[i], loop[(i + 1) % loop.size()])].push_back(f);
}

void ComplexBuilder::remove_edges(std::uint32_t f) {
  const auto& loop = facets_[f].vertices;
  for (std::size_t i = 0; i < loop.size(); ++i) {
    const std::uint64_t key = edge_key(loop[i], loop[(i + 1) % loop.size()]);
    EdgeFacetMap::List* list = edge_facets_.find(key);
    HSR_ASSERT(list, "edge map out of sync");
    list->erase(std::find(list->begin(), list->end(), f));
    if (list->empty()) edge_facets_.erase(key);
  }
}

void ComplexBuilder::hand_edges_to_halves(std::uint32_t f, std::uint32_t first, std::uint32_t second) {
  // Each half's loop runs from one end of the chord to the other: its closing edge is the chord (new), every other
  // edge one of f's. The lists end as remove_edges(f) then add_edges of both halves would leave them (f taken out,
  // the half appended; the chord: first, second), with one lookup an edge instead of two.
  for (const std::uint32_t half : {first, second}) {
    const auto& loop = facets_[half].vertices;
    const std::size_t n = loop.size();
    for (std::size_t i = 0; i + 1 < n; ++i) {
      EdgeFacetMap::List* list = edge_facets_.find(edge_key(loop[i], loop[i + 1]));
      HSR_ASSERT(list, "edge map out of sync");
      list->erase(std::find(list->begin(), list->end(), f));
      list->push_back(half);
    }
    edge_facets_[edge_key(loop[n - 1], loop[0])].push_back(half);
  }
}

std::uint32_t ComplexBuilder::new_facet(WFacet f) {
  auto id = static_cast<std::uint32_t>(facets_.size());
  facets_.push_back(std::move(f));
  add_edges(id);
  return id;
}

void ComplexBuilder::split_edge(std::uint32_t u, std::uint32_t v, std::uint32_t w) {
  EdgeFacetMap::List* found = edge_facets_.find(edge_key(u, v));
  HSR_ASSERT(found, "split_edge: unknown edge");
  EdgeFacetMap::List around = std::move(*found);
  edge_facets_.erase(edge_key(u, v));
  for (auto f : around) {
    auto& loop = facets_[f].vertices;
    const std::size_t n = loop.size();
    bool done = false;
    for (std::size_t i = 0; i < n && !done; ++i) {
      const std::uint32_t a = loop[i], b = loop[(i + 1) % n];
      if ((a == u && b == v) || (a == v && b == u)) {
        loop.insert(loop.begin() + static_cast<std::ptrdiff_t>(i + 1), w);
        done = true;
      }
    }
    HSR_ASSERT(done, "split_edge: facet does not hold the edge");
  }
  edge_facets_[edge_key(u, w)] = around;
  edge_facets_[edge_key(w, v)] = std::move(around);
}

void ComplexBuilder::update_bbox(int cell) {
  BBox b;
  for (auto f : cells_[cell].facets)
    for (auto v : facets_[f].vertices) b.extend(vertices_approx_[v]);
  cells_[cell].bbox = b;
}

void ComplexBuilder::split(int cell, int h, int level) {
  // 1. Cut every edge of the cell that crosses h, in every facet around it (keeps the complex conforming).
  // (May be none: the plane can cross the cell only through vertices already on it.)
  for (const CrossedEdge& e : crossed_edges(cell, [&](std::uint32_t v) { return sign(v, h); })) {
    const std::uint32_t w = vertex_id(crossing_point(e, h));
    HSR_ASSERT(sign(w, h) == 0, "split: crossing point off the plane");
    split_edge(e.u, e.v, w);
  }

  // 2. Distribute the facets; split those with vertices on both sides along their chord.
  const std::vector<std::uint32_t> old_facets = cells_[cell].facets;
  const int other = static_cast<int>(cells_.size());
  cells_.push_back({});
  std::vector<std::uint32_t> pos, neg;
  for (auto f : old_facets) {
    bool has_pos = false, has_neg = false;
    for (auto v : facets_[f].vertices) {
      int s = sign(v, h);
      has_pos |= s > 0;
      has_neg |= s < 0;
    }
    HSR_ASSERT(has_pos || has_neg, "split: a facet of a crossed cell lies on the splitting plane");
    if (!has_neg) {
      pos.push_back(f);
      continue;
    }
    if (!has_pos) {
      for (auto& c : facets_[f].cells)
        if (c == cell) c = other;
      neg.push_back(f);
      continue;
    }
    const std::vector<std::uint32_t> loop = facets_[f].vertices;
    const std::size_t n = loop.size();
    std::vector<std::size_t> zeros;
    for (std::size_t i = 0; i < n; ++i)
      if (sign(loop[i], h) == 0) zeros.push_back(i);
    HSR_ASSERT(zeros.size() == 2, "split: a crossed convex facet must have exactly two vertices on the plane");
    std::vector<std::uint32_t> first, second;  // zeros[0] -> zeros[1] and zeros[1] -> zeros[0]
    for (std::size_t i = zeros[0];; i = (i + 1) % n) {
      first.push_back(loop[i]);
      if (i == zeros[1]) break;
    }
    for (std::size_t i = zeros[1];; i = (i + 1) % n) {
      second.push_back(loop[i]);
      if (i == zeros[0]) break;
    }
    HSR_ASSERT(first.size() >= 3 && second.size() >= 3, "split: degenerate facet piece");
    if (sign(first[1], h) < 0) std::swap(first, second);
    WFacet fp, fn;
    fp.vertices = std::move(first);
    fn.vertices = std::move(second);
    fp.plane = fn.plane = facets_[f].plane;
    fp.level = fn.level = facets_[f].level;
    fp.cells = fn.cells = facets_[f].cells;
    for (auto& c : fn.cells)
      if (c == cell) c = other;
    int neighbour = facets_[f].cells[0] == cell ? facets_[f].cells[1] : facets_[f].cells[0];
    facets_[f].alive = false;
    const auto ip = static_cast<std::uint32_t>(facets_.size());
    facets_.push_back(std::move(fp));
    const auto in = static_cast<std::uint32_t>(facets_.size());
    facets_.push_back(std::move(fn));
    hand_edges_to_halves(f, ip, in);
    if (neighbour >= 0) {
      auto& list = cells_[neighbour].facets;
      auto it = std::find(list.begin(), list.end(), f);
      HSR_ASSERT(it != list.end(), "split: neighbour does not list the shared facet");
      *it = ip;
      list.push_back(in);
    }
    pos.push_back(ip);
    neg.push_back(in);
  }

  // 3. The cap: every vertex of the cell on h, in convex position on the section's boundary.
  std::vector<std::uint32_t> on_plane;
  for (const auto* list : {&pos, &neg})
    for (auto f : *list)
      for (auto v : facets_[f].vertices)
        if (sign(v, h) == 0) on_plane.push_back(v);
  std::sort(on_plane.begin(), on_plane.end());
  on_plane.erase(std::unique(on_plane.begin(), on_plane.end()), on_plane.end());
  HSR_ASSERT(on_plane.size() >= 3, "split: cap with fewer than 3 vertices");
  std::vector<P2> pts;
  pts.reserve(on_plane.size());
  for (auto v : on_plane) pts.push_back(to_2d(planes_[h].frame, vertices_[v]));
  WFacet cap;
  for (int k : sort_ccw(pts)) cap.vertices.push_back(on_plane[k]);
  cap.plane = h;
  cap.cells = {cell, other};  // the kept id is the positive side
  cap.level = level;
  const std::uint32_t cap_id = new_facet(std::move(cap));
  pos.push_back(cap_id);
  neg.push_back(cap_id);
  cells_[cell].facets = std::move(pos);
  cells_[other].facets = std::move(neg);
  update_bbox(cell);
  update_bbox(other);
}

void ComplexBuilder::merge_cells(std::vector<int> group) {
  std::sort(group.begin(), group.end());
  HSR_ASSERT(group.size() >= 2 && std::adjacent_find(group.begin(), group.end()) == group.end(),
             "merge_cells: needs at least two distinct cells");
  const int target = group[0];
  auto member = [&](int c) { return c >= 0 && std::binary_search(group.begin(), group.end(), c); };
  std::vector<std::uint32_t> kept;
  for (int c : group) {
    HSR_ASSERT(cells_[c].alive, "merge_cells: dead cell");
    for (auto f : cells_[c].facets) {
      WFacet& g = facets_[f];
      if (!g.alive) continue;  // an inner facet seen from its second cell
      if (member(g.cells[0]) && member(g.cells[1])) {
        remove_edges(f);
        g.alive = false;
        continue;
      }
      for (auto& side : g.cells)
        if (side == c) side = target;
      kept.push_back(f);
    }
  }
  for (int c : group) {
    cells_[c].facets.clear();
    cells_[c].alive = false;
  }
  cells_[target].facets = std::move(kept);
  cells_[target].alive = true;
  update_bbox(target);
}

bool ComplexBuilder::contains_strictly(int cell, const ExactPoint& p) const {
  const Vec3 d = to_double(p);
  const bool trusted = trusted_double(p.x, d.x()) && trusted_double(p.y, d.y()) && trusted_double(p.z, d.z());
  for (auto f : cells_[cell].facets) {
    const WFacet& g = facets_[f];
    const int inner = g.cells[0] == cell ? 1 : -1;  // cells[0] is on the plane's positive side
    if (side_of(g.plane, p, d, trusted) != inner) return false;
  }
  return true;
}

void ComplexBuilder::release_lookups() {
  edge_facets_ = EdgeFacetMap();
  vertex_index_ = ExactPointIndex();
  std::vector<SignEntry>().swap(sign_cache_);
  cached_plane_ = -1;
  plane_index_.clear();
}

CellComplex ComplexBuilder::finish(bool exact_volumes) && {
  release_lookups();
  CellComplex out;
  out.exact_volumes = exact_volumes;
  // Only the vertices some live facet uses (merges can orphan vertices of removed facets).
  std::vector<std::int64_t> vertex_remap(vertices_.size(), -1);
  for (const WFacet& f : facets_)
    if (f.alive)
      for (auto v : f.vertices) vertex_remap[v] = 0;
  const auto used = static_cast<std::size_t>(std::count(vertex_remap.begin(), vertex_remap.end(), 0));
  out.vertices.reserve(used);
  out.vertices_approx.reserve(used);
  for (std::size_t v = 0; v < vertices_.size(); ++v)
    if (vertex_remap[v] >= 0) {
      vertex_remap[v] = static_cast<std::int64_t>(out.vertices.size());
      out.vertices.push_back(std::move(vertices_[v]));
      out.vertices_approx.push_back(vertices_approx_[v]);
    }
  std::deque<ExactPoint>().swap(vertices_);
  std::vector<Vec3>().swap(vertices_approx_);
  std::vector<int> cell_remap(cells_.size(), -1);
  int live_cells = 0;
  for (std::size_t c = 0; c < cells_.size(); ++c)
    if (cells_[c].alive) cell_remap[c] = live_cells++;
  out.planes.reserve(planes_.size());
  for (auto& p : planes_) out.planes.push_back(std::move(p.support));
  out.box_min = lo_;
  out.box_max = hi_;
  out.box.min = to_double(lo_);
  out.box.max = to_double(hi_);

  std::vector<std::int64_t> remap(facets_.size(), -1);
  std::size_t live_facets = 0;
  for (const WFacet& f : facets_) live_facets += f.alive ? 1 : 0;
  out.facets.reserve(live_facets);
  for (std::size_t f = 0; f < facets_.size(); ++f) {
    WFacet& w = facets_[f];
    if (!w.alive) {
      std::vector<std::uint32_t>().swap(w.vertices);
      continue;
    }
    remap[f] = static_cast<std::int64_t>(out.facets.size());
    Facet g;
    for (auto& v : w.vertices) v = static_cast<std::uint32_t>(vertex_remap[v]);
    g.vertices = std::move(w.vertices);
    g.plane = w.plane;
    for (int k = 0; k < 2; ++k) g.cells[k] = w.cells[k] < 0 ? -1 : cell_remap[w.cells[k]];
    g.level = w.level;
    out.facets.push_back(std::move(g));
  }
  std::vector<WFacet>().swap(facets_);

  // Exact volume by the divergence theorem: a facet with 2D area A2 (frame of its plane, CCW seen from
  // the positive side) has vector area A2 * n / |n_drop|, so its flux term (vector area . any vertex) / 3
  // is A2 * (-d) / (3 |n_drop|); the sign follows the facet's outward orientation for the cell.
  std::vector<Rational> flux(exact_volumes ? out.facets.size() : 0);
  for (std::size_t f = 0; f < flux.size(); ++f) {
    const Facet& g = out.facets[f];
    const PlaneData& p = planes_[g.plane];
    const SupportPlane& support = out.planes[g.plane];  // moved out of p above
    std::vector<P2> poly;
    for (auto v : g.vertices) poly.push_back(to_2d(p.frame, out.vertices[v]));
    flux[f] = twice_area(poly) * (-support.exact.d) / (6 * abs(support.exact.coef(p.frame.drop)));
  }

  out.cells.resize(static_cast<std::size_t>(live_cells));
  for (std::size_t wc = 0; wc < cells_.size(); ++wc) {
    if (!cells_[wc].alive) continue;
    const std::size_t c = static_cast<std::size_t>(cell_remap[wc]);
    Cell& cell = out.cells[c];
    Rational volume = 0;
    for (auto& f : cells_[wc].facets) {
      HSR_ASSERT(remap[f] >= 0, "cell lists a dead facet");
      f = static_cast<std::uint32_t>(remap[f]);
    }
    cell.facets = std::move(cells_[wc].facets);
    for (auto nf : cell.facets) {
      if (!exact_volumes) continue;
      // Outward normal is +n when the cell is on the negative side (cells[1]).
      if (out.facets[nf].cells[1] == static_cast<int>(c)) volume += flux[nf];
      else volume -= flux[nf];
    }
    cell.volume = volume;
    // Double centroid: signed tetrahedra from the first vertex, facets oriented outward.
    const Vec3 ref = out.vertices_approx[out.facets[cell.facets[0]].vertices[0]];
    Vec3 acc = Vec3::Zero();
    double total = 0;
    Vec3 vertex_sum = Vec3::Zero();
    std::size_t vertex_count = 0;
    for (auto nf : cell.facets) {
      const Facet& g = out.facets[nf];
      const bool outward_is_positive = g.cells[1] == static_cast<int>(c);
      const std::size_t n = g.vertices.size();
      for (std::size_t i = 1; i + 1 < n; ++i) {
        Vec3 a = out.vertices_approx[g.vertices[0]] - ref;
        Vec3 b = out.vertices_approx[g.vertices[i]] - ref;
        Vec3 d = out.vertices_approx[g.vertices[i + 1]] - ref;
        double v6 = a.dot(b.cross(d));
        if (!outward_is_positive) v6 = -v6;
        total += v6;
        acc += v6 * (a + b + d) / 4.0;
      }
      for (auto v : g.vertices) vertex_sum += out.vertices_approx[v];
      vertex_count += n;
    }
    cell.centroid = total > 0 ? Vec3(ref + acc / total) : Vec3(vertex_sum / static_cast<double>(vertex_count));
    cell.volume_approx = total / 6;
  }
  return out;
}

}  // namespace hsr::partition_internal
