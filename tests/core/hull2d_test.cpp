// core/hull2d: a plane's frame, and containment in a convex hull grown by a margin, on known answers.
#include "core/hull2d.h"

#include <gtest/gtest.h>

#include <cmath>

namespace hsr {
namespace {

TEST(Hull2d, TheFrameIsOrthonormalAndRightHandedAboutTheNormal) {
  for (const Vec3& n : {Vec3(0, 0, 1), Vec3(1, 0, 0), Vec3(0.6, -0.8, 0), Vec3(1, 2, 3).normalized()}) {
    Vec3 u, v;
    plane_frame(n, u, v);
    EXPECT_NEAR(u.norm(), 1.0, 1e-12);
    EXPECT_NEAR(v.norm(), 1.0, 1e-12);
    EXPECT_NEAR(u.dot(n), 0.0, 1e-12);
    EXPECT_NEAR(v.dot(n), 0.0, 1e-12);
    EXPECT_NEAR((u.cross(v) - n).norm(), 0.0, 1e-12);
  }
}

TEST(Hull2d, WithinAConvexHullGrownByAMargin) {
  const std::vector<Vec2> square = convex_hull_2d({{0, 0}, {2, 0}, {2, 2}, {0, 2}, {1, 1}});
  ASSERT_EQ(square.size(), 4u);  // the inner point is no vertex
  EXPECT_TRUE(within_convex(square, {1, 1}, 0.0));
  EXPECT_TRUE(within_convex(square, {2, 1}, 0.0));    // on an edge
  EXPECT_FALSE(within_convex(square, {2.3, 1}, 0.2));  // 0.3 beyond an edge
  EXPECT_TRUE(within_convex(square, {2.3, 1}, 0.3 + 1e-12));
  EXPECT_FALSE(within_convex(square, {-0.1, 1}, 0.05));
  // A hull of two vertices (points on a line) is its segment grown by the margin; an empty one holds nothing.
  const std::vector<Vec2> segment = convex_hull_2d({{0, 0}, {1, 0}, {2, 0}});
  ASSERT_LT(segment.size(), 3u);
  ASSERT_FALSE(segment.empty());
  const std::vector<Vec2> ends = segment.size() == 2 ? segment : std::vector<Vec2>{{0, 0}, {2, 0}};
  EXPECT_TRUE(within_convex(ends, {1, 0.1}, 0.1 + 1e-12));
  EXPECT_FALSE(within_convex(ends, {1, 0.2}, 0.1));
  EXPECT_FALSE(within_convex(ends, {2.2, 0}, 0.1));
  EXPECT_FALSE(within_convex({}, {0, 0}, 1.0));
}

// offset_convex (the outline prism's edge beyond its points, DECISIONS #219): every edge moved out by d, a
// square's corners where its moved edges meet; a corner sharper than 60 degrees cut square (no spike).
TEST(Hull2d, AConvexPolygonsEdgesMovedOut) {
  const std::vector<Vec2> square{{0, 0}, {2, 0}, {2, 2}, {0, 2}};
  const std::vector<Vec2> grown = offset_convex(square, 0.25);
  ASSERT_EQ(grown.size(), 4u);
  const std::vector<Vec2> expected{{-0.25, -0.25}, {2.25, -0.25}, {2.25, 2.25}, {-0.25, 2.25}};
  for (std::size_t i = 0; i < 4; ++i) EXPECT_NEAR((grown[i] - expected[i]).norm(), 0.0, 1e-12) << i;
  EXPECT_EQ(offset_convex(square, 0.0), square);
  const std::vector<Vec2> thin{{0, 0}, {10, 0}, {0, 1}};  // 5.7 degrees at (10, 0)
  const std::vector<Vec2> t = offset_convex(thin, 0.1);
  ASSERT_EQ(t.size(), 4u);  // the sharp corner as two vertices
  for (const Vec2& q : t) {
    double nearest = 1e9;
    for (const Vec2& v : thin) nearest = std::min(nearest, (q - v).norm());
    EXPECT_LE(nearest, 0.2 + 1e-12) << q.transpose();  // no vertex farther than 2 d from the original's
  }
  for (std::size_t i = 0; i < thin.size(); ++i) {  // each edge's middle moved out by d is on the new boundary
    const Vec2 a = thin[i], b = thin[(i + 1) % thin.size()], e = (b - a).normalized();
    const Vec2 moved = 0.5 * (a + b) + 0.1 * Vec2(e.y(), -e.x());
    EXPECT_TRUE(within_convex(t, moved, 1e-9)) << i;
    EXPECT_FALSE(within_convex(t, moved, -1e-9)) << i;
    EXPECT_TRUE(within_convex(t, a, -1e-6)) << i;  // and the old corners inside (the cut corner by d cos 87°)
  }
}

}  // namespace
}  // namespace hsr
