// The label clean-up's search (src/extraction/label_cleanup.cpp, DECISIONS #144): the candidate listings and
// keys it keeps from one flip to the next must give exactly the labels of a search that computes every listing
// and every key again after each flip, with building orders (flip sets that follow whole columns) and without.
#include "extraction/label_cleanup.h"

#include "extraction/box_complex.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace hsr {
namespace {

/// Terraced columns of unit voxels: random heights per (x, y) with single-voxel bumps and pits, so that the
/// clean-up has many small faces to remove.
test::VoxelSet terraces(int n, int nz, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  test::VoxelSet solid;
  for (int x = 0; x < n; ++x)
    for (int y = 0; y < n; ++y) {
      int h = 1 + static_cast<int>((x / 3 + y / 2) % (nz - 2));
      if (rng() % 4 == 0) h += rng() % 2 == 0 ? 1 : -1;
      for (int z = 0; z < std::clamp(h, 1, nz - 1); ++z) solid.insert({x, y, z});
    }
  return solid;
}

/// The building orders of a box complex as the extraction makes them (extraction.cpp add_building_orders):
/// across every interior horizontal facet, the upper cell inside needs the lower one inside. The flip set of
/// a cell follows them: turning it inside turns the cells below inside, turning it outside the cells above out.
struct Orders {
  std::vector<std::vector<int>> below, above;
  explicit Orders(const test::BoxComplex& bc) : below(bc.cx.cells.size()), above(bc.cx.cells.size()) {
    for (std::size_t f = 0; f < bc.cx.facets.size(); ++f) {
      const Facet& facet = bc.cx.facets[f];
      if (bc.facet_axis[f] != 2 || facet.cells[0] < 0 || facet.cells[1] < 0) continue;
      int lo = facet.cells[0], hi = facet.cells[1];
      if (bc.boxes[lo].lo[2] > bc.boxes[hi].lo[2]) std::swap(lo, hi);
      above[lo].push_back(hi);
      below[hi].push_back(lo);
    }
  }
  std::vector<int> flip_set(const std::vector<bool>& inside, int c, std::vector<int>* read) const {
    std::vector<int> set{c};
    if (read) read->push_back(c);
    const bool to_inside = !inside[c];
    const auto& next = to_inside ? below : above;
    for (std::size_t k = 0; k < set.size(); ++k)
      for (int to : next[set[k]]) {
        if (read) read->push_back(to);
        if (inside[to] != to_inside && std::find(set.begin(), set.end(), to) == set.end()) set.push_back(to);
      }
    return set;
  }
};

struct Outcome {
  std::vector<bool> inside;
  LabelCleanupResult result;
};

Outcome run(const test::BoxComplex& bc, const std::vector<bool>& start, const FlipSet& flip_set, bool reuse,
            std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<std::size_t> facet_points(bc.cx.facets.size());
  for (auto& n : facet_points) n = rng() % 5;
  LabelCleanupParams params;
  params.face_price = 0.02;
  params.small_share = 0.02;
  params.point_tolerance = 0.5;
  Outcome o{start, {}};
  o.result = reuse ? clean_up_labels(bc.cx, o.inside, params, flip_set, facet_points)
                   : clean_up_labels_without_reuse_for_tests(bc.cx, o.inside, params, flip_set, facet_points);
  return o;
}

void expect_same(const Outcome& a, const Outcome& b) {
  EXPECT_EQ(a.inside, b.inside);
  EXPECT_EQ(a.result.moves, b.result.moves);
  EXPECT_EQ(a.result.cells_flipped, b.result.cells_flipped);
  EXPECT_EQ(a.result.rejected, b.result.rejected);
  EXPECT_EQ(a.result.supported, b.result.supported);
  EXPECT_EQ(a.result.faces_after, b.result.faces_after);
  EXPECT_EQ(a.result.small_after, b.result.small_after);
  EXPECT_DOUBLE_EQ(a.result.displacement, b.result.displacement);
}

TEST(CleanupSearch, KeptListingsGiveTheLabelsOfASearchFromScratchWithBuildingOrders) {
  std::size_t moves = 0, multi_cell = 0;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    SCOPED_TRACE(seed);
    const test::VoxelSet solid = terraces(8, 6, seed);
    const test::BoxComplex bc = test::build_box_complex(test::kd_boxes({8, 8, 6}, solid, seed));
    std::vector<bool> start(bc.cx.cells.size());
    for (std::size_t c = 0; c < start.size(); ++c) start[c] = test::box_in_solid(bc.boxes[c], solid);
    const Orders orders(bc);
    const FlipSet flip_set = [&](const std::vector<bool>& inside, int c, std::vector<int>* read) {
      return orders.flip_set(inside, c, read);
    };
    const Outcome kept = run(bc, start, flip_set, true, seed), scratch = run(bc, start, flip_set, false, seed);
    expect_same(kept, scratch);
    moves += kept.result.moves;
    multi_cell += kept.result.cells_flipped - kept.result.moves;
    // Every order still holds.
    for (std::size_t c = 0; c < kept.inside.size(); ++c)
      for (int lo : orders.below[c]) EXPECT_TRUE(!kept.inside[c] || kept.inside[lo]) << c << " over " << lo;
  }
  EXPECT_GT(moves, 30u);      // the search did something to compare
  EXPECT_GT(multi_cell, 10u);  // and flipped columns, not only single cells
}

TEST(CleanupSearch, KeptListingsGiveTheLabelsOfASearchFromScratchWithoutOrders) {
  std::size_t moves = 0;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    SCOPED_TRACE(seed);
    const test::VoxelSet solid = terraces(8, 6, seed + 10);
    const test::BoxComplex bc = test::build_box_complex(test::kd_boxes({8, 8, 6}, solid, seed));
    std::mt19937_64 rng(seed);
    std::vector<bool> start(bc.cx.cells.size());
    for (std::size_t c = 0; c < start.size(); ++c)
      start[c] = test::box_in_solid(bc.boxes[c], solid) != (rng() % 12 == 0);  // and some noise
    const Outcome kept = run(bc, start, FlipSet{}, true, seed), scratch = run(bc, start, FlipSet{}, false, seed);
    expect_same(kept, scratch);
    moves += kept.result.moves;
  }
  EXPECT_GT(moves, 30u);
}

}  // namespace
}  // namespace hsr
