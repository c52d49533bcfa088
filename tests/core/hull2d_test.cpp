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

}  // namespace
}  // namespace hsr
