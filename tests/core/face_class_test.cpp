// core/face_class: names round-trip, Newell vector, classification by normal.
#include "core/face_class.h"
#include "test_meshes.h"

#include <gtest/gtest.h>

namespace hsr {
namespace {

using test::unit_cube;

TEST(FaceClass, NamesRoundTrip) {
  for (FaceClass c : {FaceClass::Unknown, FaceClass::Roof, FaceClass::Wall, FaceClass::Ground, FaceClass::Closure}) {
    FaceClass back = FaceClass::Unknown;
    ASSERT_TRUE(parse_face_class(face_class_name(c), back));
    EXPECT_EQ(back, c);
  }
  FaceClass out = FaceClass::Roof;
  EXPECT_FALSE(parse_face_class("floor", out));
  EXPECT_EQ(out, FaceClass::Roof);
}

TEST(FaceClass, NewellVectorIsTwiceTheAreaAlongTheNormal) {
  const PolygonMesh m = unit_cube();
  EXPECT_EQ(newell_vector(m.vertices, m.faces[0]), Vec3(0, 0, -2));
  EXPECT_EQ(newell_vector(m.vertices, m.faces[1]), Vec3(0, 0, 2));
  EXPECT_EQ(newell_vector(m.vertices, m.faces[2]), Vec3(0, -2, 0));
}

TEST(FaceClass, ByNormalCubeHasOneRoofOneGroundFourWalls) {
  const std::vector<FaceClass> c = classify_faces_by_normal(unit_cube());
  const std::vector<FaceClass> expected{FaceClass::Ground, FaceClass::Roof, FaceClass::Wall,
                                        FaceClass::Wall,   FaceClass::Wall, FaceClass::Wall};
  EXPECT_EQ(c, expected);
}

TEST(FaceClass, ByNormalSteepRoofIsRoofNearVerticalIsWall) {
  PolygonMesh m;
  // A 60-degree slope (n_z = 0.5) is a roof; a face 5 degrees off vertical (n_z ~ 0.087) is a wall.
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 0.5, std::sqrt(3.0) / 2}, {0, 0.5, std::sqrt(3.0) / 2},
                {0, 0, 0}, {1, 0, 0}, {1, std::tan(5 * M_PI / 180), 1}, {0, std::tan(5 * M_PI / 180), 1}};
  m.faces = {{0, 1, 2, 3}, {4, 5, 6, 7}};
  const std::vector<FaceClass> c = classify_faces_by_normal(m);
  EXPECT_EQ(c[0], FaceClass::Roof);
  EXPECT_EQ(c[1], FaceClass::Wall);
}

TEST(FaceClass, StoredClassesWinOverTheNormal) {
  PolygonMesh m = unit_cube();
  m.face_class.assign(6, FaceClass::Unknown);
  m.face_class[2] = FaceClass::Closure;
  const std::vector<FaceClass> c = face_classes_or_by_normal(m);
  EXPECT_EQ(c[2], FaceClass::Closure);  // stored
  EXPECT_EQ(c[1], FaceClass::Roof);     // unknown -> by normal
  m.face_class.resize(3);               // wrong size: ignored
  EXPECT_EQ(face_classes_or_by_normal(m)[2], FaceClass::Wall);
}

// Regions: one per connected set of coplanar faces sharing edges, plus one per hole, whatever the polygon split.
TEST(FaceClass, RegionsCountAFaceWithAHoleAsTwoHoweverItIsCut) {
  PolygonMesh m;
  // The square ring [0,3]^2 minus [1,2]^2 at z = 0, cut into four trapezoids.
  m.vertices = {{0, 0, 0}, {3, 0, 0}, {3, 3, 0}, {0, 3, 0}, {1, 1, 0}, {2, 1, 0}, {2, 2, 0}, {1, 2, 0}};
  m.faces = {{0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  const CoplanarGroups ring = coplanar_groups(m);
  EXPECT_EQ(ring.planes.size(), 1u);
  EXPECT_EQ(polygon_regions(m, ring.face_group), 2u);  // one region with one hole
  // Cut into one piece fewer (two trapezoids joined into a non-convex hexagon): still 2.
  PolygonMesh joined = m;
  joined.faces = {{0, 1, 2, 6, 5, 4}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  EXPECT_EQ(polygon_regions(joined, coplanar_groups(joined).face_group), 2u);
  // The hole filled by a square one unit above: another plane, another region: 3.
  m.vertices.insert(m.vertices.end(), {{1, 1, 1}, {2, 1, 1}, {2, 2, 1}, {1, 2, 1}});
  m.faces.push_back({8, 9, 10, 11});
  const CoplanarGroups two = coplanar_groups(m);
  EXPECT_EQ(two.planes.size(), 2u);
  EXPECT_EQ(two.face_group.back(), 1);
  EXPECT_EQ(polygon_regions(m, two.face_group), 3u);
  // A square in two triangles: one region.
  PolygonMesh sq;
  sq.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  sq.faces = {{0, 1, 2}, {0, 2, 3}};
  EXPECT_EQ(polygon_regions(sq, coplanar_groups(sq).face_group), 1u);
}

}  // namespace
}  // namespace hsr
