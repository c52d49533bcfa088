// The incremental defect count of the label clean-up (src/extraction/surface.h, DefectCounter) against the
// global count it replaces (find_defects on the whole surface), on complexes built by the real
// partitioners and random labellings full of non-manifold edges and pinched vertices.
#include "extraction/surface.h"

#include "extraction/box_complex.h"
#include "partition/partition.h"
#include "partition/partition_fixtures.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace hsr {
namespace {

std::size_t global_count(const CellComplex& cx, const std::vector<bool>& inside) {
  return find_defects(cx, surface_of(cx, inside)).list.size();
}

/// Flips random sets of one to three neighbouring cells; each time the counter's answer must equal the
/// global count, and about half of the flips are kept.
void check_counter(const CellComplex& cx, std::uint64_t seed, int flips) {
  std::mt19937_64 rng(seed);
  std::vector<bool> inside(cx.cells.size());
  for (std::size_t c = 0; c < inside.size(); ++c) inside[c] = rng() % 2 == 0;
  DefectCounter counter(cx, inside);
  ASSERT_EQ(counter.count(), global_count(cx, inside));
  std::size_t seen_defects = 0;
  for (int i = 0; i < flips; ++i) {
    std::vector<int> cells{static_cast<int>(rng() % cx.cells.size())};
    for (int extra = static_cast<int>(rng() % 3); extra > 0; --extra) {  // a neighbour across a facet
      const Cell& cell = cx.cells[cells.back()];
      const Facet& f = cx.facets[cell.facets[rng() % cell.facets.size()]];
      const int other = f.cells[0] == cells.back() ? f.cells[1] : f.cells[0];
      if (other >= 0 && std::find(cells.begin(), cells.end(), other) == cells.end()) cells.push_back(other);
    }
    std::vector<bool> after = inside;
    for (int c : cells) after[c] = !after[c];
    const std::size_t expected = global_count(cx, after);
    ASSERT_EQ(counter.count_with(after, cells), expected) << "flip " << i;
    seen_defects += expected;
    if (rng() % 2 == 0) {
      counter.commit(after, cells);
      inside = after;
      ASSERT_EQ(counter.count(), expected);
    }
  }
  EXPECT_GT(seen_defects, 0u) << "the labellings never made a defect: the test would not see a wrong count";
}

TEST(DefectCounter, EqualsTheGlobalCountOnRandomPolygons) {
  for (Partitioner method : {Partitioner::Exhaustive, Partitioner::Hierarchical}) {
    PartitionInput in;
    in.polygons = random_polygons(3, 6);
    in.points_bbox = unit_box();
    PartitionParams params;
    params.method = method;
    const CellComplex cx = run_partition(in, params);
    SCOPED_TRACE(partitioner_name(method));
    check_counter(cx, 7, 300);
  }
}

// Non-conforming kd-tree tilings (tests/extraction/box_complex.h): neighbouring facets meet in
// T-junctions, so the surface loops carry vertices that are no corner of their facet.
TEST(DefectCounter, EqualsTheGlobalCountWithTJunctions) {
  const test::VoxelSet plus = {{2, 1, 1}, {1, 2, 1}, {2, 2, 1}, {3, 2, 1}, {2, 3, 1}, {2, 2, 2}};
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    const test::BoxComplex bc = test::build_box_complex(test::kd_boxes({5, 5, 5}, plus, seed));
    const CellComplex& cx = bc.cx;
    std::vector<Loop> loops;
    for (const Facet& f : cx.facets) loops.push_back(f.vertices);
    insert_t_junctions(cx, loops);
    std::size_t extra = 0;
    for (std::size_t f = 0; f < loops.size(); ++f) extra += loops[f].size() - cx.facets[f].vertices.size();
    ASSERT_GT(extra, 0u) << "seed " << seed << ": no T-junction, the test would not exercise them";
    SCOPED_TRACE(seed);
    check_counter(cx, seed, 400);
  }
}

}  // namespace
}  // namespace hsr

namespace hsr {
namespace {

/// The point (u, v) of the tilted plane z = u / 3 + v / 7 + 1 / 11, exactly.
ExactPoint on_tilted(const Rational& u, const Rational& v) { return {u, v, u / 3 + v / 7 + Rational(1, 11)}; }

TEST(Surface, AStraightCornerIsOneWhereTheLoopGoesOnAlongOneLine) {
  const ExactPlane tilted{Rational(1, 3), Rational(1, 7), -1, Rational(1, 11)};
  const auto at = [](const Rational& t) { return on_tilted(t, 2 * t); };  // the line (t, 2t) of the plane
  EXPECT_TRUE(is_straight(at(0), at(1), at(Rational(5, 2)), tilted));
  EXPECT_TRUE(is_straight(at(3), at(1), at(Rational(-1, 9)), tilted)) << "the other way along it";
  EXPECT_FALSE(is_straight(at(0), at(1), on_tilted(2, 1), tilted)) << "a turn";
  EXPECT_FALSE(is_straight(at(0), at(1), at(Rational(1, 2)), tilted)) << "back along the line: a spike";
  EXPECT_FALSE(is_straight(at(1), at(1), at(2), tilted)) << "a repeated corner";
  EXPECT_FALSE(is_straight(at(0), at(1), at(1), tilted));
  // Off the line by 10^-30 within the plane: no double sees it, the exact test does.
  const Rational tiny(1, mpz_class("1000000000000000000000000000000"));
  EXPECT_FALSE(is_straight(at(0), on_tilted(1 + tiny, 2), at(2), tilted));
  // A vertical plane x = 1 (its frame drops x): straight along z, a turn into y.
  const ExactPlane wall{1, 0, 0, -1};
  EXPECT_TRUE(is_straight({1, 0, 0}, {1, 0, Rational(1, 3)}, {1, 0, 2}, wall));
  EXPECT_FALSE(is_straight({1, 0, 0}, {1, 0, Rational(1, 3)}, {1, 1, 2}, wall));
}

}  // namespace
}  // namespace hsr
