// The label clean-up's face count change (src/extraction/label_cleanup.cpp, issue 25: computed from the
// region index and the flip's neighbourhood, no longer by counting every region of the planes it touches)
// against the count it replaces, on complexes of the real partitioners and kd-tree tilings with
// T-junctions, under random labellings full of holes, pinches, splits and merges of regions.
#include "extraction/label_cleanup.h"

#include "extraction/box_complex.h"
#include "partition/partition.h"
#include "partition/partition_fixtures.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace hsr {
namespace {

/// Random flips of one to four neighbouring cells: the clean-up's change of the faces and of the small
/// faces must be the counted one; about half of the flips are kept, so the labellings wander. Returns how
/// many flips changed the face count (the test must see some of each kind to mean anything).
struct Seen {
  int changed = 0, split_or_merge = 0, small = 0;
};
Seen check_deltas(const CellComplex& cx, std::uint64_t seed, int flips, double small_share) {
  std::mt19937_64 rng(seed);
  std::vector<bool> inside(cx.cells.size());
  for (std::size_t c = 0; c < inside.size(); ++c) inside[c] = rng() % 3 == 0;
  Seen seen;
  for (int i = 0; i < flips; ++i) {
    std::vector<int> cells{static_cast<int>(rng() % cx.cells.size())};
    for (int extra = static_cast<int>(rng() % 4); extra > 0; --extra) {
      const Cell& cell = cx.cells[cells[rng() % cells.size()]];
      const Facet& f = cx.facets[cell.facets[rng() % cell.facets.size()]];
      for (int other : f.cells)
        if (other >= 0 && std::find(cells.begin(), cells.end(), other) == cells.end()) cells.push_back(other);
    }
    std::sort(cells.begin(), cells.end());
    const FaceDeltas d = face_deltas_for_tests(cx, inside, cells, small_share);
    EXPECT_EQ(d.faces, d.counted_faces) << "flip " << i << " of seed " << seed;
    EXPECT_EQ(d.small, d.counted_small) << "flip " << i << " of seed " << seed;
    if (d.faces != d.counted_faces || d.small != d.counted_small) return seen;
    seen.changed += d.counted_faces != 0;
    seen.split_or_merge += std::abs(d.counted_faces) >= 2;
    seen.small += d.counted_small != 0;
    if (rng() % 2 == 0)
      for (int c : cells) inside[c] = !inside[c];
  }
  return seen;
}

TEST(CleanupDelta, EqualsTheCountOnRandomPolygons) {
  for (Partitioner method : {Partitioner::Exhaustive, Partitioner::Hierarchical, Partitioner::Bsp}) {
    PartitionInput in;
    in.polygons = random_polygons(5, 8);
    in.points_bbox = unit_box();
    PartitionParams params;
    params.method = method;
    const CellComplex cx = run_partition(in, params);
    SCOPED_TRACE(partitioner_name(method));
    for (double small_share : {0.001, 0.05}) {
      const Seen seen = check_deltas(cx, 11, 400, small_share);
      EXPECT_GT(seen.changed, 50);
      EXPECT_GT(seen.split_or_merge, 5);
      if (small_share > 0.01) EXPECT_GT(seen.small, 5);
    }
  }
}

TEST(CleanupDelta, EqualsTheCountWithTJunctions) {
  const test::VoxelSet plus = {{2, 1, 1}, {1, 2, 1}, {2, 2, 1}, {3, 2, 1}, {2, 3, 1}, {2, 2, 2}};
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    const test::BoxComplex bc = test::build_box_complex(test::kd_boxes({6, 6, 6}, plus, seed));
    SCOPED_TRACE(seed);
    const Seen seen = check_deltas(bc.cx, seed, 500, 0.02);
    EXPECT_GT(seen.changed, 50);
    EXPECT_GT(seen.split_or_merge, 5);
  }
}

}  // namespace
}  // namespace hsr
