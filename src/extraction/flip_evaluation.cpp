// Stage 6's label clean-up, what a flip of cells changes (label_cleanup.h; DECISIONS #26, #35, #37, #38, #59):
// the candidate flips around a region, the regions index per support plane, the change of the output faces and
// small faces computed from the flip's neighbourhood (side_delta, issue 25), the surface's and the points'
// displacement, and whether the points support what the flip would remove. The search is in label_cleanup.cpp.
#include "extraction/label_cleanup_internal.h"

#include <cmath>
#include <limits>
#include <numeric>
#include <tuple>

namespace hsr::label_cleanup_internal {

Cleanup::Cleanup(const CellComplex& cx, std::vector<bool>& inside, const FlipSet& flip_set,
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
  gain_mark_.assign(planes_.size(), 0);
  gain_facets_.assign(planes_.size(), 0);
  gain_corners_.assign(planes_.size(), 0);
  indexed_at_.resize(planes_.size());
  for (std::size_t p = 0; p < planes_.size(); ++p) index_regions(static_cast<int>(p));
  stale_.assign(planes_.size(), 1);
}

FaceCount Cleanup::total_faces() const {
  FaceCount t;
  for (const FaceCount& f : faces_) {
    t.faces += f.faces;
    t.small += f.small;
  }
  return t;
}

int Cleanup::region_side(int p, int r) const {
  return facet_status(cx_.facets[planes_[p].facets[regions_[p][r].members.front()]], inside_);
}

std::vector<std::vector<int>> Cleanup::region_candidates(int p, int r, std::vector<int>* read) const {
  Region region;
  region.plane = p;
  for (int k : regions_[p][r].members) region.facets.push_back(planes_[p].facets[k]);
  std::vector<std::vector<int>> out;
  add_raw_candidates(region, out, read);
  for (auto& cells : out) cells = closed(cells, read);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

void Cleanup::add_candidates(const Region& r, std::set<std::vector<int>>& out) const {
  std::vector<std::vector<int>> raw;
  add_raw_candidates(r, raw);
  for (const auto& cells : raw) out.insert(closed(cells));
}

void Cleanup::add_raw_candidates(const Region& r, std::vector<std::vector<int>>& out, std::vector<int>* read) const {
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
      for (int c : *side) add_pairs(c, out, read);
  }
}

void Cleanup::add_pairs(int c, std::vector<std::vector<int>>& out, std::vector<int>* read) const {
  if (read) read->push_back(c);
  for (std::uint32_t f : cx_.cells[c].facets)
    for (int d : cx_.facets[f].cells) {
      if (d < 0 || d == c) continue;
      if (read) read->push_back(d);
      if (inside_[d] == inside_[c]) out.push_back({c, d});
    }
}

double Cleanup::area_of(const Region& r) const {
  double area = 0.0;
  for (int f : r.facets) area += facet_area_[f];
  return area;
}

std::vector<std::pair<Region, double>> Cleanup::small_regions() {
  std::vector<std::pair<Region, double>> out;
  for (std::size_t p = 0; p < planes_.size(); ++p)
    for (Region& r : regions(static_cast<int>(p))) {
      const double area = area_of(r);
      if (area < small_area_) out.emplace_back(std::move(r), area / area_);
    }
  return out;
}

void Cleanup::begin_reads() {
  ++read_stamp_;
  reads_.clear();
}

std::vector<int> Cleanup::planes_of(const std::vector<int>& cells) const {
  std::vector<int> out;
  for (int c : cells)
    for (std::uint32_t f : cx_.cells[c].facets) out.push_back(cx_.facets[f].plane);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

Evaluation Cleanup::evaluate(const std::vector<int>& cells) {
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

FaceCount Cleanup::delta_by_counting(const std::vector<int>& cells) {
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

double Cleanup::max_gain(const std::vector<int>& cells, double small_weight) {
  // Per plane, the flip's facets on it and their corners (tallied where gain_mark_ is this call's mark: a call
  // costs what its cells hold, not a sort and two lists of its own).
  const int mark = stamps_.next();
  for (int c : cells)
    for (std::uint32_t f : cx_.cells[c].facets) {
      const int p = cx_.facets[f].plane;
      if (gain_mark_[p] != mark) {
        gain_mark_[p] = mark;
        gain_facets_[p] = gain_corners_[p] = 0;
      }
      gain_facets_[p] += 1;
      gain_corners_[p] += static_cast<long>(cx_.facets[f].vertices.size());
    }
  double gain = 0.0;
  auto add = [&](int p, int k) {
    note(p, k);
    const int r = region_of_[p][k];
    if (r < 0) return;
    int& seen = region_mark_[p][r];
    if (seen == mark) return;
    seen = mark;
    const RegionRecord& rec = regions_[p][r];
    note_region(p, rec);
    const long facets = gain_facets_[p], corners = gain_corners_[p];
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

double Cleanup::cost(const std::vector<int>& cells, const Evaluation& ev) const {
  return std::max(displacement(cells), ev.point_displacement);
}

double Cleanup::point_displacement(const std::vector<int>& cells,
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

double Cleanup::displacement(const std::vector<int>& cells) const {
  double v = 0.0;
  for (int c : cells) v += std::abs(cx_.cells[c].volume_approx);
  return v * scale_;
}

bool Cleanup::can_flip(const std::vector<int>& cells) const {
  std::size_t out = 0, in = 0;
  for (int c : cells) (inside_[c] ? out : in) += 1;
  return inside_count_ + in - out > 0;
}

void Cleanup::flip(const std::vector<int>& cells) {
  for (int c : cells) {
    inside_count_ += inside_[c] ? -1 : 1;
    inside_[c] = !inside_[c];
  }
}

std::vector<std::uint32_t> Cleanup::commit(const std::vector<int>& cells, const Evaluation& ev,
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

std::vector<std::pair<std::uint32_t, int>> Cleanup::statuses(const std::vector<int>& cells) const {
  std::vector<std::pair<std::uint32_t, int>> out;
  for (int c : cells)
    for (std::uint32_t f : cx_.cells[c].facets) out.push_back({f, facet_status(cx_.facets[f], inside_)});
  return out;
}

void Cleanup::note(int p, int k) {
  const auto f = static_cast<std::uint32_t>(planes_[p].facets[k]);
  if (read_mark_[f] == read_stamp_) return;
  read_mark_[f] = read_stamp_;
  reads_.push_back(f);
}

void Cleanup::note_region(int p, const RegionRecord& rec) {
  if (is_big(rec)) return;
  for (int k : rec.members) {
    note(p, k);
    for (int nb : planes_[p].neighbours[k]) note(p, nb);
  }
}

FaceCount Cleanup::side_delta(int p, int side, const std::vector<Change>& changes) {
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

void Cleanup::index_regions(int p) {
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

FaceCount Cleanup::count(int p, const std::vector<int>& seeds) {
  FaceCount total;
  const PlaneFacets& pf = planes_[p];
  for_each_region(cx_, pf, inside_, seeds, stamps_, nullptr, [&](const std::vector<int>& members, int faces, long, long) {
    const FaceCount here = face_count(pf, members, faces);
    total.faces += here.faces;
    total.small += here.small;
  });
  return total;
}

FaceCount Cleanup::face_count(const PlaneFacets& pf, const std::vector<int>& members, int faces) const {
  double area = 0.0;
  for (int k : members) area += facet_area_[pf.facets[k]];
  return {faces, area < small_area_ ? faces : 0};
}

std::vector<int> Cleanup::closed(const std::vector<int>& cells, std::vector<int>* read) const {
  std::vector<int> out;
  if (!flip_set_) out = cells;
  else
    for (int c : cells) {
      const std::vector<int> s = flip_set_(inside_, c, read);
      out.insert(out.end(), s.begin(), s.end());
    }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

}  // namespace hsr::label_cleanup_internal
