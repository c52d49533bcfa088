// Stage 6's label clean-up, the search (label_cleanup.h; DECISIONS #26, #35, #37, #59, #62): greedy, cheapest
// first, over the candidate flips around each output face, kept in a pool whose keys are recomputed only where
// a flip changed something; a flip is made while its price is at most the face price and the surface stays a
// 2-manifold. How faces are counted: face_regions.cpp; what a flip changes: flip_evaluation.cpp.
#include "extraction/label_cleanup.h"

#include "extraction/label_cleanup_internal.h"
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

using namespace label_cleanup_internal;

namespace {

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

  /// `reuse` false: every listing and key is computed again after every flip (the search before DECISIONS
  /// #144, kept as the reference for tests).
  CandidatePool(Cleanup& cleanup, const LabelCleanupParams& params, std::size_t facets, std::size_t cells, bool reuse)
      : cleanup_(cleanup), params_(params), lists_(cleanup.plane_count()), readers_(facets), flipped_at_(cells, 0),
        reuse_(reuse) {}

  /// Brings candidates and keys up to the current labels after a flip of `flipped` that changed the status of
  /// the facets `changed`: stale planes' lists are rebuilt (with a flip set every plane's, keeping the
  /// listings of regions that did not change and read no flipped cell), the keys that looked at a changed
  /// facet recomputed, new and held candidates queued.
  void sync(const std::vector<std::uint32_t>& changed, const std::vector<int>& flipped) {
    ++clock_;
    for (int c : flipped) flipped_at_[c] = clock_;
    for (int p = 0; p < static_cast<int>(lists_.size()); ++p)
      if (cleanup_.stale(p) || cleanup_.has_flip_set() || !listed_) relist(p);
    listed_ = true;
    for (std::uint32_t f : changed) {
      for (const auto& [e, generation] : readers_[f])
        if (e->generation == generation) e->valid = false, touched_.push_back(e);
      records_ -= readers_[f].size();
      readers_[f].clear();
    }
    if (!reuse_)
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
  /// One region's listing: its identity (Cleanup::region_members), its candidates, the cells whose labels
  /// they read beyond the identity (sorted, distinct) and when it was listed (clock_).
  struct Listed {
    std::uint64_t hash = 0;
    int side = 0;
    std::vector<int> members;
    std::vector<std::vector<int>> candidates;
    std::vector<int> read;
    std::uint64_t listed_at = 0;
  };
  /// Whether a listing still holds for a region of the same identity: no cell it read has flipped since.
  bool still_holds(const Listed& l) const {
    return reuse_ && std::none_of(l.read.begin(), l.read.end(), [&](int c) { return flipped_at_[c] > l.listed_at; });
  }
  static std::uint64_t identity_hash(int side, const std::vector<int>& members) {
    std::uint64_t h = 1469598103934665603ull ^ static_cast<std::uint64_t>(side + 2);
    for (int k : members) h = (h ^ static_cast<std::uint64_t>(k)) * 1099511628211ull;
    return h;
  }

  /// Plane p's candidates again, region by region (issue 25: a hall's floor holds thousands of facets, and
  /// most flips touch a cell on it): a region whose identity the flip left alone, and none of whose read
  /// cells flipped (DECISIONS #144: a building's flip sets read the labels of whole columns), keeps its
  /// listing, the others are listed anew. Entries are counted by the regions listing them, gone at zero;
  /// every new listing is counted before any old one is released, so an entry listed before and after stays.
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
      for (auto it = std::lower_bound(by_hash.begin(), by_hash.end(), std::make_pair(hash, -1));
           it != by_hash.end() && it->first == hash; ++it)
        if (!kept[it->second] && old[it->second].side == side && old[it->second].members == members &&
            still_holds(old[it->second])) {
          same = it->second;
          break;
        }
      if (same >= 0) {
        kept[same] = 1;
        next.push_back(std::move(old[same]));
        continue;
      }
      Listed l{hash, side, members, {}, {}, clock_};
      l.candidates = cleanup_.region_candidates(p, r, &l.read);
      std::sort(l.read.begin(), l.read.end());
      l.read.erase(std::unique(l.read.begin(), l.read.end()), l.read.end());
      next.push_back(std::move(l));
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
  std::vector<std::uint64_t> flipped_at_;        ///< per cell: clock_ of its last flip (0: never)
  std::uint64_t clock_ = 0;                      ///< sync() calls
  bool reuse_ = true;
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

/// The search of clean_up_labels; `reuse` as in CandidatePool.
LabelCleanupResult search(const CellComplex& cx, std::vector<bool>& inside, const LabelCleanupParams& params,
                          const FlipSet& flip_set, const std::vector<std::size_t>& facet_points, bool reuse) {
  LabelCleanupResult result;
  if (!(params.face_price > 0.0) || cx.cells.empty()) return result;
  Cleanup cleanup(cx, inside, flip_set, params, facet_points);
  result.faces_before = result.faces_after = static_cast<std::size_t>(cleanup.total_faces().faces);
  result.small_before = result.small_after = static_cast<std::size_t>(cleanup.total_faces().small);
  DefectCounter defects(cx, inside);
  const std::size_t defects_before = defects.count();
  CandidatePool pool(cleanup, params, cx.facets.size(), cx.cells.size(), reuse);
  std::set<std::vector<int>> supported;  // candidates found to move supported points
  std::vector<std::uint32_t> changed;    // the facets the last accepted flip changed
  std::vector<int> flipped;              // its cells
  while (result.moves < params.max_moves) {
    // The cheapest offer that keeps the surface a 2-manifold; the refused ones are tried again after the
    // next accepted flip (it may have changed their neighbourhood).
    pool.sync(changed, flipped);
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
      flipped = cells;
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

}  // namespace

LabelCleanupResult clean_up_labels(const CellComplex& cx, std::vector<bool>& inside, const LabelCleanupParams& params,
                                   const FlipSet& flip_set, const std::vector<std::size_t>& facet_points) {
  return search(cx, inside, params, flip_set, facet_points, true);
}

LabelCleanupResult clean_up_labels_without_reuse_for_tests(const CellComplex& cx, std::vector<bool>& inside,
                                                           const LabelCleanupParams& params, const FlipSet& flip_set,
                                                           const std::vector<std::size_t>& facet_points) {
  return search(cx, inside, params, flip_set, facet_points, false);
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
